#include "sim/DamageState.h"

#include <algorithm>
#include <map>

namespace rend::sim {

DamageState::DamageState(const BondFamilies& bonds, std::span<const std::array<int, 3>> triangles)
    : bondEdge_(bonds.directedCount(), -1),
      mirror_(bonds.directedCount(), -1),
      bondAlive_(bonds.directedCount(), 1),
      proposed_(bonds.directedCount(), 0),
      triangleAlive_(triangles.size(), 1),
      kept_(triangles.size(), 1),
      strength_(bonds.directedCount(), 1.0) {
    // Partners are sorted, so each family finds its mirror by bisection.
    const auto bondOf = [&](int i, int j) {
        const auto first = bonds.partners.begin() + bonds.offsets[i];
        const auto last = bonds.partners.begin() + bonds.offsets[i + 1];
        const auto it = std::lower_bound(first, last, j);
        return it != last && *it == j ? int(it - bonds.partners.begin()) : -1;
    };
    for (int i = 0; i < bonds.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b)
            mirror_[b] = bondOf(bonds.partners[b], i);
    std::map<std::array<int, 2>, int> index;  // set-up only
    triangleEdges_.resize(triangles.size());
    for (int t = 0; t < int(triangles.size()); ++t)
        for (int s = 0; s < 3; ++s) {
            const int a = triangles[t][(s + 1) % 3], b = triangles[t][(s + 2) % 3];
            const std::array<int, 2> key{std::min(a, b), std::max(a, b)};
            const auto [it, added] = index.try_emplace(key, int(edges_.size()));
            if (added) {
                edges_.push_back(key);
                edgeBonds_.push_back({bondOf(key[0], key[1]), bondOf(key[1], key[0])});
                edgeTriangles_.push_back({t, -1});
                for (int bond : edgeBonds_.back())
                    if (bond >= 0) bondEdge_[bond] = it->second;
            } else {
                edgeTriangles_[it->second][1] = t;
            }
            triangleEdges_[t][s] = it->second;
        }
    edgeAlive_.assign(edges_.size(), 1);
}

void DamageState::killEdge(int e) {
    if (!edgeAlive_[e]) return;
    edgeAlive_[e] = 0;
    for (int t : edgeTriangles_[e])
        if (t >= 0) kept_[t] = 0;
}

void DamageState::breakBond(int b) {
    if (!bondAlive_[b]) return;
    bondAlive_[b] = 0;
    if (mirror_[b] >= 0) bondAlive_[mirror_[b]] = 0;
    ++brokenBonds_, ++version_;
    if (bondEdge_[b] >= 0) killEdge(bondEdge_[b]);
}

void DamageState::breakEdge(int e) {
    for (int b : edgeBonds_[e])
        if (b >= 0) breakBond(b);
    killEdge(e);
}

void DamageState::removeTriangle(int t) {
    if (!triangleAlive_[t]) return;
    triangleAlive_[t] = 0;
    kept_[t] = 0;
    ++removedTriangles_;
}

void DamageState::weaken(int b, double gamma) { strength_[b] = gamma; }

void DamageState::applyProposals() {
    for (int b = 0; b < int(proposed_.size()); ++b)
        if (proposed_[b]) {
            proposed_[b] = 0;
            breakBond(b);
        }
}

}  // namespace rend::sim
