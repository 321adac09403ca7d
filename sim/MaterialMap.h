#pragma once
// Material maps (issue 15): E, the fracture energy G_f and the density may vary over the sheet.
// Each map multiplies one property by a factor field over the rest plane (x, y): a constant
// inside a box, disc or polygon (1 outside), a seeded multi-octave value noise (1 + amplitude
// times a noise in [-1, 1], stretched by a scale per axis, so long thin cells read as fibres),
// or a greyscale image spread over the sheet's rest bounds (low where black, high where
// white). Several maps of one property multiply. A particle carries the factors; a bond takes
// the mean of its two ends (the solvers' business: sim/PeridynamicBonds.cpp).

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace rend::sim {

enum class MappedProperty {
    YoungsModulus,
    FractureEnergy,
    Density,
    YieldStrain,
    Softening,
    PowerRatio,
    PowerExponent
};
enum class MapShape { Box, Disc, Polygon, Noise, Image };

/// Grey levels in [0, 1], row 0 at the top (at the sheet's largest rest y), as images are stored.
struct GreyImage {
    int width = 0, height = 0;
    std::vector<float> values;  ///< width * height

    /// Bilinear, with (u, v) in [0, 1]^2, v = 0 at the bottom row; clamped at the borders.
    double sample(double u, double v) const;
};

struct MaterialMap {
    MappedProperty property = MappedProperty::YoungsModulus;
    MapShape shape = MapShape::Box;
    double factor = 1.0;                   ///< box, disc, polygon: the factor inside
    Eigen::Vector2d min{0, 0}, max{0, 0};  ///< box
    Eigen::Vector2d center{0, 0};          ///< disc
    double radius = 0.0;                   ///< disc
    std::vector<Eigen::Vector2d> polygon;  ///< polygon, its corners in order
    Eigen::Vector2d scale{0.1, 0.1};       ///< noise: the cell size along x and y [m]
    double amplitude = 0.5;                ///< noise: the factor spans 1 +- amplitude, < 1
    int octaves = 4;                       ///< noise: each halves the cells and the amplitude
    std::uint64_t seed = 1;                ///< noise
    GreyImage image;                       ///< image
    double low = 0.5, high = 1.5;          ///< image: the factors of black and white
};

/// The property's name as scenes spell it: "E", "fracture_energy", "density", "yield_strain",
/// "softening", "power_ratio", "power_exponent".
std::string mappedPropertyName(MappedProperty property);

/// Each particle's factor for `property`: the product of the maps that name it, 1 where none
/// does. The image and noise maps are spread over the rest positions' bounds.
std::vector<double> materialFactors(MappedProperty property, std::span<const MaterialMap> maps,
                                    std::span<const Eigen::Vector3d> rest);

/// Whether any map names `property`.
bool mapsProperty(std::span<const MaterialMap> maps, MappedProperty property);

/// The maps of the bond law's own parameters (eqs. 19 and 20), which every solver but the SPH
/// applies bond by bond (spring, element): yield_strain, softening, power_ratio, power_exponent.
inline constexpr MappedProperty kLawProperties[] = {
    MappedProperty::YieldStrain, MappedProperty::Softening, MappedProperty::PowerRatio,
    MappedProperty::PowerExponent};

/// Whether any map names one of kLawProperties.
bool mapsLaw(std::span<const MaterialMap> maps);

/// The value noise of the noise maps, in [-1, 1], at p in cells (octave 1).
double valueNoise(const Eigen::Vector2d& p, int octaves, std::uint64_t seed);

}  // namespace rend::sim
