#pragma once
// Plain parameter structs of the membrane simulator, filled and range-checked by the scene
// loader (app/). Units are SI throughout.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "sim/Collider.h"
#include "sim/MaterialMap.h"

namespace rend::sim {

enum class LatticeKind { Hexagonal, Square };
/// Sphere: a closed geodesic sphere (a subdivided icosahedron, edges about dx) of `radius`
/// around `center`, for inflation tests; its triangles face outwards, so a positive pressure
/// inflates it.
enum class Outline { Rectangle, Disc, Sphere };

struct SheetParams {
    Outline outline = Outline::Rectangle;
    Eigen::Vector2d size{2.0, 2.0};   ///< rectangle extent in x and y [m]
    double radius = 1.0;              ///< disc or sphere radius [m]
    Eigen::Vector3d center{0, 0, 0};  ///< the sheet lies in the plane z = center.z at rest
    LatticeKind lattice = LatticeKind::Hexagonal;
    double dx = 0.02;                    ///< particle spacing [m]
    double horizonFactor = 1.5;          ///< cutoff R in units of dx (paper Section 6)
    double thickness = 1e-3;             ///< membrane thickness h [m]
    double perturbationAmplitude = 0.0;  ///< seeded out-of-plane jitter at rest [m]
    std::uint64_t perturbationSeed = 1;
    /// The spacing of the lattice that seeded random draws refer to (the jitter's values, the
    /// scattered spots' centres) [m]; 0: dx. The loader sets the preview spacing, so a scene
    /// keeps its jitter and its spots at every quality.
    double seedSpacing = 0.0;
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

/// How the micromodulus c of eq. 18 is chosen.
enum class MicromodulusMode {
    Calibrated,  ///< uniform small strain reproduces E in the interior (see BondLaw.h)
    Paper,       ///< the paper's literal c = 18K/(pi R^4) (eq. 24), kept for comparison
};

/// The three bond laws of the membrane paper (eqs. 18-20).
enum class BondLawKind {
    Linear,         ///< eq. 18: f = c eta
    PowerLaw,       ///< eq. 19: rubber, c (s^2 + 1/s^2) + c* s^n energy
    Elastoplastic,  ///< eq. 20: linear up to eta0, exponential softening beyond
};

/// How the critical stretch is derived from the fracture energy G_f.
enum class CriticalStretchMode {
    Calibrated,  ///< the energy of the bonds crossing a unit crack equals G_f (see Fracture.h)
    Paper,       ///< eq. 28 as printed: eta_c = sqrt(4 pi G_f / (9 E R))
    /// The calibrated eta_c of the preview spacing (SheetParams::seedSpacing) at every spacing:
    /// the sheet breaks at the same stretch at final quality as in its preview, where the
    /// calibrated one grows as 1 / sqrt(dx) (withPreviewStrength).
    Preview,
    /// The geometric mean of Calibrated and Preview: eta_c grows as dx^(-1/4) where the
    /// calibrated one grows as dx^(-1/2). Tears that start where a sheet lands keep to a
    /// strength (Preview); tears that run from a cut keep to an energy (Calibrated).
    Midway,
};

struct MaterialParams {
    std::string name = "custom";
    double youngsModulus = 2e4;  ///< E [Pa]
    /// nu of the FEM and mass-spring solvers and of the paper's literal constant; the
    /// peridynamic bonds fix 1/3.
    double poissonRatio = 0.3;
    double density = 5000.0;  ///< rho [kg/m^3]
    MicromodulusMode micromodulus = MicromodulusMode::Calibrated;

    BondLawKind law = BondLawKind::Linear;
    double powerLawRatio = 0.0;     ///< c* / c of eq. 19, <= 0
    double powerLawExponent = 4.0;  ///< n of eq. 19, > 1
    double yieldStrain = 1e-4;      ///< eta0 of eqs. 20 and 27
    double softening = 1.0;         ///< beta of eqs. 20 and 27, > 0

    std::optional<double> fractureEnergy;  ///< G_f [J/m^2]; nullopt: bonds never break
    CriticalStretchMode criticalStretch = CriticalStretchMode::Calibrated;

    double capacity = 1.0;      ///< diffusive capacity C (eq. 25)
    double conductivity = 0.0;  ///< coefficient of diffusion k (eq. 25); 0: no diffusion
    double expansion = 0.0;     ///< alpha: strain per unit theta (eqs. 18-20)
    /// Degradation by the diffusive quantity (acid, moisture): stiffness and critical stretch
    /// scale by max(0, 1 - loss * theta_bar).
    double stiffnessLoss = 0.0;
    double strengthLoss = 0.0;
    /// Surface correction: scale each bond by the mean of its ends' factors S_interior / S_i
    /// (S = sum_j W0 V_j), so particles that miss part of their family near a free edge are as
    /// stiff as interior ones (the "energy method" of peridynamic surface corrections).
    bool surfaceCorrection = false;
};

/// A pre-notch: a polyline in rest coordinates (x, y); every bond crossing it is broken at set-up.
struct Notch {
    std::vector<Eigen::Vector2d> points;
};

/// Source of the diffusive quantity, adding `rate` [theta units per second] to every particle
/// within `radius` of its centre while start <= t < start + duration.
struct DiffusionSpot {
    Eigen::Vector2d center{0, 0};
    double radius = 0.05;
    double rate = 1.0;
    double start = 0.0;
    double duration = std::numeric_limits<double>::infinity();
};

/// Seeded generators of spots: `count` spots placed uniformly over the sheet at t = start
/// (heat spots), or a spray emitting `count` droplets uniformly over [start, start + spread).
struct SpotScatter {
    int count = 0;
    double radius = 0.05;
    double rate = 1.0;
    double start = 0.0;
    double spread = 0.0;  ///< 0: all at once; > 0: a spray over this many seconds
    double duration = std::numeric_limits<double>::infinity();  ///< each spot's lifetime
    std::uint64_t seed = 1;
};

/// Dirichlet edge source: theta is held at `value` on the particles of the region.
struct DiffusionEdge {
    Region region;
    double value = 1.0;
};

struct DiffusionParams {
    double initial = 0.0;               ///< theta everywhere at t = 0
    std::vector<DiffusionSpot> spots;   ///< explicit sources (negative rate: sinks)
    std::vector<SpotScatter> scatters;  ///< random spots and sprays, expanded at set-up
    std::vector<DiffusionEdge> edges;   ///< edge sources: theta held fixed there
};

enum class BoundaryKind { Velocity, Pinned };

struct BoundaryCondition {
    BoundaryKind kind = BoundaryKind::Pinned;
    Region region;
    Eigen::Vector3d velocity{0, 0, 0};  ///< prescribed velocity (Velocity only) [m/s]
    double rampTime = 0.0;              ///< seconds to reach full speed, linear ramp from rest
};

/// Explicit schemes: eq. 26's symplectic Euler (velocity, then position), or velocity Verlet
/// (half kick, drift, new forces, half kick), second order and better at conserving energy.
enum class Integrator { SymplecticEuler, VelocityVerlet };

/// Without a numeric dt: "auto" (a fixed step, safety x the stable bound at rest) or "adaptive"
/// (sim/TimeStep.h: safety x the current bound, cut further where accuracy needs it).
enum class StepControl { Auto, Adaptive };

struct TimeParams {
    Integrator integrator = Integrator::SymplecticEuler;
    std::optional<double> dt;  ///< a number: a fixed step; nullopt: `control` says which
    StepControl control = StepControl::Adaptive;  ///< Auto or Adaptive when dt is nullopt
    double safety = 0.8;                          ///< Peridigm uses 0.8-0.85
    /// Adaptive: the most a loaded bond's stretch may change in one step, as a fraction of the
    /// critical stretch (sim/TimeStep.h).
    double maxStretchIncrement = 0.02;
    /// Adaptive: a step that breaks more bonds than this shrinks the next ones (a burst).
    int burstBonds = 8;
    double duration = 5.0;  ///< simulated seconds
    double fps = 24.0;
    bool allowUnstable = false;  ///< expert: accept dt above the bound (the guard still runs)

    bool adaptive() const { return !dt && control == StepControl::Adaptive; }
};

/// The MPM solver's grid (solver = "mpm", sim/Mpm.h).
struct MpmParams {
    double grid = 0.5;   ///< the background grid's spacing over sheet.dx
    bool enrich = true;  ///< seed 002's enrichment at material boundaries and cracks
};

/// Seed 004's remeshing (sim/Remesh.h) for the particle solvers.
struct RemeshParams {
    int every = 0;  ///< steps between remeshes; 0: never
};

struct MembraneParams {
    /// Which discretisation turns positions into internal forces, by its name in the solver
    /// registry (sim/SolverRegistry.h): "peridynamic" is the membrane paper's bonds.
    std::string solver = "peridynamic";
    SheetParams sheet;
    MaterialParams material;
    std::vector<BoundaryCondition> boundaries;
    Eigen::Vector3d gravity{0, 0, 0};
    double damping = 0.0;   ///< mass-proportional velocity damping [1/s]
    double pressure = 0.0;  ///< uniform follower pressure on the intact surface, +z side [Pa]
    TimeParams time;
    std::vector<Notch> notches;
    DiffusionParams diffusion;
    ContactParams contact;                  ///< ground, colliders, self-contact (sim/Contact.h)
    std::vector<MaterialMap> materialMaps;  ///< E, G_f and density over the sheet
    MpmParams mpm;
    RemeshParams remesh;
    /// Carry seed 004's particle level set of the outline (sim/ParticleLevelSet.h): set where the
    /// surface draws it (render.surface = "particle_level_set"); it never changes the motion.
    bool particleLevelSet = false;
};

}  // namespace rend::sim
