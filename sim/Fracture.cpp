#include "sim/Fracture.h"

#include <cmath>
#include <numbers>

namespace rend::sim {

double calibratedCriticalStretch(double fractureEnergy, double micromodulus,
                                 double interiorWeightedMoment) {
    return std::sqrt(2.0 * std::numbers::pi * fractureEnergy /
                     (micromodulus * interiorWeightedMoment));
}

double paperCriticalStretch(double fractureEnergy, double youngsModulus, double horizon) {
    return std::sqrt(4.0 * std::numbers::pi * fractureEnergy / (9.0 * youngsModulus * horizon));
}

namespace {

double orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

bool onSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
    return p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) &&
           p.y() >= std::min(a.y(), b.y()) && p.y() <= std::max(a.y(), b.y());
}

}  // namespace

bool segmentsCross(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& a,
                   const Eigen::Vector2d& b) {
    const double d1 = orientation(a, b, p), d2 = orientation(a, b, q);
    const double d3 = orientation(p, q, a), d4 = orientation(p, q, b);
    if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
        return true;
    return (d1 == 0 && onSegment(a, b, p)) || (d2 == 0 && onSegment(a, b, q)) ||
           (d3 == 0 && onSegment(p, q, a)) || (d4 == 0 && onSegment(p, q, b));
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

std::size_t applyNotches(std::span<const Notch> notches, std::span<const Eigen::Vector3d> rest,
                         BondFamilies& bonds) {
    std::size_t broken = 0;
    for (int i = 0; i < bonds.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b)
            if (bonds.alive[b] &&
                crossesAnyNotch(rest[i].head<2>(), rest[bonds.partners[b]].head<2>(), notches)) {
                bonds.alive[b] = 0;
                ++broken;
            }
    return broken / 2;  // each bond is stored from both ends, and both ends cross alike
}

}  // namespace rend::sim
