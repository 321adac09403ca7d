#include "sim/Mpm.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_set>

#include "sim/Contact.h"
#include "sim/FemCst.h"
#include "sim/SolverRegistry.h"

namespace rend::sim {
namespace {

/// A grid cell's integer coordinates packed into one key; false when x is not finite or lies
/// beyond the packing's reach (such a particle stays off the grid anyway).
bool cellKey(const Eigen::Vector3d& x, double h, long long& key) {
    const Eigen::Vector3d scaled = (x / h).array().floor();
    if (!scaled.allFinite() || scaled.cwiseAbs().maxCoeff() > double(1 << 19)) return false;
    const Eigen::Vector3i c = scaled.cast<int>();
    key = ((long long)(c.x() + (1 << 20)) << 42) | ((long long)(c.y() + (1 << 20)) << 21) |
          (long long)(c.z() + (1 << 20));
    return true;
}

std::vector<std::array<int, 2>> latticeSides(std::span<const std::array<int, 3>> triangles) {
    std::vector<std::array<int, 2>> sides;
    for (const auto& t : triangles)
        for (int s = 0; s < 3; ++s)
            sides.push_back({std::min(t[(s + 1) % 3], t[(s + 2) % 3]),
                             std::max(t[(s + 1) % 3], t[(s + 2) % 3])});
    std::sort(sides.begin(), sides.end());
    sides.erase(std::unique(sides.begin(), sides.end()), sides.end());
    return sides;
}

}  // namespace

Mpm::Mpm(std::unique_ptr<Solver> domainForces, const Lattice& lattice, double gridSpacing,
         std::span<const MaterialMap> maps, bool enrich)
    : domain_(std::move(domainForces)),
      triangles_(lattice.triangles),
      edges_(latticeSides(lattice.triangles)),
      enrich_(enrich),
      grid_(gridSpacing) {
    const int n = int(lattice.positions.size());
    materialBoundary_.assign(n, 0);
    affine_.assign(n, Eigen::Matrix3d::Zero());
    onGrid_.assign(n, 1);
    restPositions_ = lattice.positions;
    if (enrich_) findMaterialBoundaries(maps);
    boundary_ = materialBoundary_;
    bindOwn({}, n, lattice.triangles);
}

std::unique_ptr<Solver> Mpm::make(const SolverSetUp& s) {
    return std::make_unique<Mpm>(FemCst::make(s), s.lattice, s.params.mpm.grid * s.params.sheet.dx,
                                 s.params.materialMaps, s.params.mpm.enrich);
}

// Algorithm 1: the ends of a lattice edge whose properties differ are boundary particles.
void Mpm::findMaterialBoundaries(std::span<const MaterialMap> maps) {
    for (const MappedProperty property :
         {MappedProperty::YoungsModulus, MappedProperty::FractureEnergy, MappedProperty::Density,
          MappedProperty::YieldStrain, MappedProperty::Softening, MappedProperty::PowerRatio,
          MappedProperty::PowerExponent}) {
        if (!mapsProperty(maps, property)) continue;
        const std::vector<double> f = materialFactors(property, maps, restPositions_);
        for (const auto& [i, j] : edges_)
            if (std::abs(f[i] - f[j]) > kMaterialJump * std::max(f[i], f[j]))
                materialBoundary_[i] = materialBoundary_[j] = 1;
    }
}

void Mpm::updateCrackBoundaries() {
    if (!enrich_) return;
    const std::size_t seen = damage_->brokenBondCount() + damage_->removedTriangleCount();
    if (seen == damageSeen_) return;
    damageSeen_ = seen;
    boundary_ = materialBoundary_;
    const std::vector<std::uint8_t>& kept = damage_->keptTriangles();
    for (std::size_t t = 0; t < triangles_.size(); ++t)
        if (!kept[t])
            for (const int corner : triangles_[t]) boundary_[corner] = 1;
}

// Algorithm 2: boundary cells are those within one cell of a boundary particle's; a free
// particle in one is enriched, any other free particle is ordinary.
void Mpm::classify(const TransferState& s) {
    const int n = int(s.x.size());
    const double h = grid_.spacing();
    updateCrackBoundaries();
    std::unordered_set<long long> boundaryCells;
    long long key = 0;
    for (int p = 0; p < n; ++p) {
        if (!boundary_[p] || !cellKey(s.x[p], h, key)) continue;
        for (int a = -1; a <= 1; ++a)
            for (int b = -1; b <= 1; ++b)
                for (int c = -1; c <= 1; ++c)
                    boundaryCells.insert(key + ((long long)a << 42) + ((long long)b << 21) + c);
    }
    enriched_ = 0;
    for (int p = 0; p < n; ++p) {
        const bool inBoundaryCell =
            !boundaryCells.empty() && cellKey(s.x[p], h, key) && boundaryCells.count(key) > 0;
        onGrid_[p] = s.free[p] && !inBoundaryCell;
        if (!onGrid_[p]) {
            ++enriched_;
            affine_[p].setZero();  // solved on its own domain: no affine part to carry
        }
    }
}

void Mpm::transferMomentum(const TransferState& s, std::span<Eigen::Vector3d> v) {
    classify(s);
    if (!s.contact || !s.contact->hasColliders()) {
        grid_.transfer(s.x, s.mass, onGrid_, v, affine_);
        return;
    }
    // Nodes within one cell of a surface's contact offset collide: the particles whose
    // stencils reach them take the surface's velocity along its normal.
    const double reach = grid_.spacing();
    grid_.transfer(s.x, s.mass, onGrid_, v, affine_,
                   [&](const Eigen::Vector3d& at, Eigen::Vector3d& velocity) {
                       s.contact->resolveNodeVelocity(at, velocity, reach);
                   });
}

void Mpm::saveState(StateWriter& out) const {
    domain_->saveState(out);
    out(affine_);
}

void Mpm::loadState(StateReader& in) {
    domain_->loadState(in);
    in(affine_);
    if (affine_.size() != onGrid_.size())
        throw StateMismatch("the checkpoint's MPM particles do not match the scene's");
    damageSeen_ = std::size_t(-1);  // the crack's boundary particles are found again
}

}  // namespace rend::sim
