#pragma once
// Plain parameter structs of the membrane simulator, filled and range-checked by the scene
// loader (app/). Units are SI throughout.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace rend::sim {

enum class LatticeKind { Hexagonal, Square };
enum class Outline { Rectangle, Disc };

struct SheetParams {
    Outline outline = Outline::Rectangle;
    Eigen::Vector2d size{2.0, 2.0};   ///< rectangle extent in x and y [m]
    double radius = 1.0;              ///< disc radius [m]
    Eigen::Vector3d center{0, 0, 0};  ///< the sheet lies in the plane z = center.z at rest
    LatticeKind lattice = LatticeKind::Hexagonal;
    double dx = 0.02;                    ///< particle spacing [m]
    double horizonFactor = 1.5;          ///< cutoff R in units of dx (paper Section 6)
    double thickness = 1e-3;             ///< membrane thickness h [m]
    double perturbationAmplitude = 0.0;  ///< seeded out-of-plane jitter at rest [m]
    std::uint64_t perturbationSeed = 1;
};

/// How the micromodulus c of eq. 18 is chosen.
enum class MicromodulusMode {
    Calibrated,  ///< uniform small strain reproduces E in the interior (see BondLaw.h)
    Paper,       ///< the paper's literal c = 18K/(pi R^4) (eq. 24), kept for comparison
};

struct MaterialParams {
    std::string name = "custom";
    double youngsModulus = 2e4;  ///< E [Pa]
    double poissonRatio = 0.3;  ///< used only by the paper's literal constant; bond-based fixes 1/3
    double density = 5000.0;    ///< rho [kg/m^3]
    MicromodulusMode micromodulus = MicromodulusMode::Calibrated;
};

/// Axis-aligned box in rest coordinates (x, y); particles whose rest position lies inside
/// belong to the region. Unbounded sides are +-infinity.
struct Region {
    Eigen::Vector2d min{-std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity()};
    Eigen::Vector2d max{std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity()};
    bool contains(const Eigen::Vector3d& x0) const {
        return x0.x() >= min.x() && x0.x() <= max.x() && x0.y() >= min.y() && x0.y() <= max.y();
    }
};

enum class BoundaryKind { Velocity, Pinned };

struct BoundaryCondition {
    BoundaryKind kind = BoundaryKind::Pinned;
    Region region;
    Eigen::Vector3d velocity{0, 0, 0};  ///< prescribed velocity (Velocity only) [m/s]
    double rampTime = 0.0;              ///< seconds to reach full speed, linear ramp from rest
};

struct TimeParams {
    std::optional<double> dt;  ///< nullopt: "auto", safety * the Silling-Askari bound
    double safety = 0.8;       ///< Peridigm uses 0.8-0.85
    double duration = 5.0;     ///< simulated seconds
    double fps = 24.0;
    bool allowUnstable = false;  ///< expert: accept dt above the bound (the guard still runs)
};

struct MembraneParams {
    SheetParams sheet;
    MaterialParams material;
    std::vector<BoundaryCondition> boundaries;
    Eigen::Vector3d gravity{0, 0, 0};
    double damping = 0.0;  ///< mass-proportional velocity damping [1/s]
    TimeParams time;
};

}  // namespace rend::sim
