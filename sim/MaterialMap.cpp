#include "sim/MaterialMap.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rend::sim {
namespace {

/// A value in [-1, 1] per lattice corner (splitmix64 of the corner and the seed).
double cornerValue(std::int64_t ix, std::int64_t iy, std::uint64_t seed) {
    std::uint64_t z = seed * 0x9e3779b97f4a7c15ULL ^ std::uint64_t(ix) * 0xbf58476d1ce4e5b9ULL ^
                      std::uint64_t(iy) * 0x94d049bb133111ebULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return double(z >> 11) / double(1ULL << 52) - 1.0;
}

double smooth(double t) { return t * t * (3.0 - 2.0 * t); }

double noiseOctave(const Eigen::Vector2d& p, std::uint64_t seed) {
    const double fx = std::floor(p.x()), fy = std::floor(p.y());
    const auto ix = std::int64_t(fx), iy = std::int64_t(fy);
    const double tx = smooth(p.x() - fx), ty = smooth(p.y() - fy);
    const double bottom = std::lerp(cornerValue(ix, iy, seed), cornerValue(ix + 1, iy, seed), tx);
    const double top =
        std::lerp(cornerValue(ix, iy + 1, seed), cornerValue(ix + 1, iy + 1, seed), tx);
    return std::lerp(bottom, top, ty);
}

/// Even-odd rule.
bool insidePolygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
    bool inside = false;
    for (std::size_t a = 0, b = poly.size() - 1; a < poly.size(); b = a++) {
        const Eigen::Vector2d &u = poly[a], &w = poly[b];
        if ((u.y() > p.y()) != (w.y() > p.y()) &&
            p.x() < (w.x() - u.x()) * (p.y() - u.y()) / (w.y() - u.y()) + u.x())
            inside = !inside;
    }
    return inside;
}

struct Bounds {
    Eigen::Vector2d low, size;
};

Bounds restBounds(std::span<const Eigen::Vector3d> rest) {
    Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
    Eigen::Vector2d high = -low;
    for (const Eigen::Vector3d& x : rest) {
        low = low.cwiseMin(x.head<2>());
        high = high.cwiseMax(x.head<2>());
    }
    return {low, (high - low).cwiseMax(Eigen::Vector2d::Constant(1e-300))};
}

double factorAt(const MaterialMap& map, const Eigen::Vector2d& p, const Bounds& bounds) {
    switch (map.shape) {
        case MapShape::Box:
            return (p.array() >= map.min.array()).all() && (p.array() <= map.max.array()).all()
                       ? map.factor
                       : 1.0;
        case MapShape::Disc:
            return (p - map.center).norm() <= map.radius ? map.factor : 1.0;
        case MapShape::Polygon:
            return insidePolygon(map.polygon, p) ? map.factor : 1.0;
        case MapShape::Noise:
            return 1.0 +
                   map.amplitude * valueNoise(p.cwiseQuotient(map.scale), map.octaves, map.seed);
        case MapShape::Image: {
            const Eigen::Vector2d uv = (p - bounds.low).cwiseQuotient(bounds.size);
            return std::lerp(map.low, map.high, map.image.sample(uv.x(), uv.y()));
        }
    }
    return 1.0;
}

}  // namespace

double GreyImage::sample(double u, double v) const {
    if (width <= 0 || height <= 0) return 0.0;
    const double x = std::clamp(u, 0.0, 1.0) * (width - 1);
    const double y = (1.0 - std::clamp(v, 0.0, 1.0)) * (height - 1);  // row 0 at the top
    const int x0 = int(x), y0 = int(y);
    const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
    const auto at = [&](int px, int py) { return double(values[std::size_t(py) * width + px]); };
    const double tx = x - x0, ty = y - y0;
    return std::lerp(std::lerp(at(x0, y0), at(x1, y0), tx), std::lerp(at(x0, y1), at(x1, y1), tx),
                     ty);
}

std::string mappedPropertyName(MappedProperty property) {
    switch (property) {
        case MappedProperty::YoungsModulus:
            return "E";
        case MappedProperty::FractureEnergy:
            return "fracture_energy";
        case MappedProperty::Density:
            return "density";
        case MappedProperty::YieldStrain:
            return "yield_strain";
        case MappedProperty::Softening:
            return "softening";
        case MappedProperty::PowerRatio:
            return "power_ratio";
        case MappedProperty::PowerExponent:
            return "power_exponent";
    }
    return "";
}

double valueNoise(const Eigen::Vector2d& p, int octaves, std::uint64_t seed) {
    double sum = 0.0, amplitude = 1.0, total = 0.0;
    Eigen::Vector2d q = p;
    for (int k = 0; k < std::max(octaves, 1); ++k) {
        sum += amplitude * noiseOctave(q, seed + std::uint64_t(k));
        total += amplitude;
        amplitude *= 0.5;
        q *= 2.0;
    }
    return sum / total;
}

bool mapsProperty(std::span<const MaterialMap> maps, MappedProperty property) {
    return std::any_of(maps.begin(), maps.end(),
                       [&](const MaterialMap& m) { return m.property == property; });
}

bool mapsLaw(std::span<const MaterialMap> maps) {
    return std::any_of(std::begin(kLawProperties), std::end(kLawProperties),
                       [&](MappedProperty p) { return mapsProperty(maps, p); });
}

std::vector<double> materialFactors(MappedProperty property, std::span<const MaterialMap> maps,
                                    std::span<const Eigen::Vector3d> rest) {
    std::vector<double> factors(rest.size(), 1.0);
    if (!mapsProperty(maps, property)) return factors;
    const Bounds bounds = restBounds(rest);
    for (const MaterialMap& map : maps)
        if (map.property == property)
            for (std::size_t i = 0; i < rest.size(); ++i)
                factors[i] *= factorAt(map, rest[i].head<2>(), bounds);
    return factors;
}

}  // namespace rend::sim
