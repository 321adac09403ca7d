#include "sim/Fracture.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace rend::sim {

double calibratedCriticalStretch(double fractureEnergy, double micromodulus,
                                 double interiorWeightedMoment) {
    return std::sqrt(2.0 * std::numbers::pi * fractureEnergy /
                     (micromodulus * interiorWeightedMoment));
}

double springCriticalStrain(const MembraneParams& params) {
    const MaterialParams& m = params.material;
    if (!m.fractureEnergy) return std::numeric_limits<double>::infinity();
    // The springs crossing a unit length of crack along a hexagonal row (2 / dx of them, each
    // sqrt(3)/2 E h at nu = 1/3) store G_f h at this strain: k eps^2 dx^2 / 2 * 2 / dx = G_f h.
    return std::sqrt(2.0 * *m.fractureEnergy /
                     (std::sqrt(3.0) * m.youngsModulus * params.sheet.dx));
}

double bandCriticalStrain(const MembraneParams& params) {
    // An eroded element (or a two-parameter triangle with a broken side) releases only its own
    // energy: the band the crack takes out, sqrt(3)/2 dx high, at E eps^2 / (2 (1 - nu^2)),
    // holds G_f h per unit length at sqrt(2 (1 - nu^2)) times the springs' strain.
    const double nu = params.material.poissonRatio;
    return std::sqrt(2.0 * (1.0 - nu * nu)) * springCriticalStrain(params);
}

double paperCriticalStretch(double fractureEnergy, double youngsModulus, double horizon) {
    return std::sqrt(4.0 * std::numbers::pi * fractureEnergy / (9.0 * youngsModulus * horizon));
}

MembraneParams withPreviewStrength(MembraneParams params) {
    MaterialParams& m = params.material;
    const double preview = params.sheet.seedSpacing;
    if (!m.fractureEnergy || preview <= 0.0) return params;
    const double finer = params.sheet.dx / preview;
    if (m.criticalStretch == CriticalStretchMode::Preview) *m.fractureEnergy *= finer;
    if (m.criticalStretch == CriticalStretchMode::Midway) *m.fractureEnergy *= std::sqrt(finer);
    return params;
}

MembraneParams withCrackBandSoftening(MembraneParams params) {
    const double preview = params.sheet.seedSpacing;
    if (params.material.law == BondLawKind::Elastoplastic && preview > 0.0)
        params.material.softening *= params.sheet.dx / preview;
    return params;
}

namespace {

double orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

}  // namespace

bool segmentsCross(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& a,
                   const Eigen::Vector2d& b) {
    // A point exactly on the other segment's line counts as lying on its left (>= 0): a notch
    // drawn along a lattice row then cuts that row off from the row below, once, instead of
    // cutting every bond that touches it and leaving the row's particles loose.
    const bool pLeft = orientation(a, b, p) >= 0, qLeft = orientation(a, b, q) >= 0;
    const bool aLeft = orientation(p, q, a) >= 0, bLeft = orientation(p, q, b) >= 0;
    return pLeft != qLeft && aLeft != bLeft;
}

namespace {

bool crossesAnyNotch(const Eigen::Vector2d& p, const Eigen::Vector2d& q,
                     std::span<const Notch> notches) {
    for (const Notch& notch : notches)
        for (std::size_t k = 0; k + 1 < notch.points.size(); ++k)
            if (segmentsCross(p, q, notch.points[k], notch.points[k + 1])) return true;
    return false;
}

}  // namespace

std::vector<int> notchedBonds(std::span<const Notch> notches, std::span<const Eigen::Vector3d> rest,
                              const BondFamilies& bonds) {
    std::vector<int> crossing;
    for (int i = 0; i < bonds.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b)
            // Both copies of a bond are tested with the lower index first, so they agree even
            // where the tie-break of segmentsCross decides.
            if (const int lo = std::min(i, bonds.partners[b]), hi = std::max(i, bonds.partners[b]);
                crossesAnyNotch(rest[lo].head<2>(), rest[hi].head<2>(), notches))
                crossing.push_back(b);
    return crossing;
}

}  // namespace rend::sim
