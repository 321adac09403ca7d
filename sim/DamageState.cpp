#include "sim/DamageState.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "sim/TriangleEdges.h"

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
    // Each mirror from the lower end, the partner's families walked once: j's bonds to i < j
    // come in increasing i, so j's next unmatched lower bond is to i or to a particle without a
    // bond back (bisection of every family took a fifth of a 10^6 sheet's set-up).
    std::vector<int> lower(bonds.offsets.begin(), bonds.offsets.end() - 1);
    for (int i = 0; i < bonds.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            const int j = bonds.partners[b];
            if (j == i) mirror_[b] = bondOf(i, i);  // no family has one, but as bisection
            if (j <= i) continue;
            int& next = lower[j];
            while (next < bonds.offsets[j + 1] && bonds.partners[next] < i) ++next;
            if (next < bonds.offsets[j + 1] && bonds.partners[next] == i)
                mirror_[b] = next, mirror_[next] = b, ++next;
        }
    TriangleEdges numbered = sim::triangleEdges(triangles, 1);  // side s opposite corner s
    edges_ = std::move(numbered.ends);
    triangleEdges_ = std::move(numbered.ofTriangle);
    edgeBonds_.resize(edges_.size());
    for (std::size_t e = 0; e < edges_.size(); ++e) {
        edgeBonds_[e] = {bondOf(edges_[e][0], edges_[e][1]), bondOf(edges_[e][1], edges_[e][0])};
        for (const int bond : edgeBonds_[e])
            if (bond >= 0) bondEdge_[bond] = int(e);
    }
    // The first triangle on each edge, and the last after it.
    edgeTriangles_.assign(edges_.size(), {-1, -1});
    for (int t = 0; t < int(triangles.size()); ++t)
        for (const int e : triangleEdges_[t]) {
            auto& on = edgeTriangles_[e];
            (on[0] < 0 ? on[0] : on[1]) = t;
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
    breaks_.push_back({b, mirror_[b]});
    if (bondEdge_[b] >= 0) killEdge(bondEdge_[b]);
}

std::optional<std::span<const std::array<int, 2>>> DamageState::breaksSince(
    std::uint64_t version) const {
    if (version < logBase_ || version > version_) return std::nullopt;
    return std::span<const std::array<int, 2>>(breaks_).subspan(version - logBase_);
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

// Eight flags at a time where none is set (a byte at a time was 1% of a shipped foil's samples
// at final quality, on every step that broke a bond).
void DamageState::applyProposals() {
    const int n = int(proposed_.size());
    for (int b = 0; b < n; ++b) {
        std::uint64_t eight = 0;
        if (b % 8 == 0 && b + 8 <= n && (std::memcpy(&eight, &proposed_[b], 8), eight == 0)) {
            b += 7;
            continue;
        }
        if (proposed_[b]) {
            proposed_[b] = 0;
            breakBond(b);
        }
    }
}

}  // namespace rend::sim
