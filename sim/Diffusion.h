#pragma once
// Peridynamic diffusion of the membrane paper (eq. 25, after Bobaru & Duangpanya 2010) over the
// same bonds as the mechanics; a broken bond carries nothing. Boundaries are insulated: no flux
// leaves a particle's family.
//
// Dimensionally consistent form: rho C V_i dtheta_i/dt = K sum_j W0 V_i V_j (theta_j -
// theta_i)/|xi|^2
// + sources. Expanding theta_j - theta_i to second order on an isotropic lattice gives
// K/4 * sum_j W0 V_j * laplacian(theta), so K = 4k / sum_j W0 V_j (interior particle) makes the
// interior reproduce Fourier's rho C dtheta/dt = k laplacian(theta) (eq. 8). Every pair flux is
// antisymmetric, so the insulated total sum_i V_i theta_i is conserved.
//
// Forward Euler is stable for dt <= min_i rho C / (K sum_j W0 V_j / |xi|^2) (Gershgorin); the
// mechanics' step is split into as many diffusion sub-steps as that bound needs.

#include <Eigen/Core>
#include <span>
#include <vector>

#include "sim/Bonds.h"
#include "sim/DiffusionKernels.h"
#include "sim/Domain.h"
#include "sim/Lattice.h"
#include "sim/Params.h"
#include "sim/StepKernels.h"

namespace rend::sim {

/// The indices of `points` in increasing x (ties in increasing index): what pointsInDisc()
/// searches.
std::vector<int> orderByX(std::span<const Eigen::Vector3d> points);

/// The points whose x y lie within `radius` of `center` (|p - c| <= radius, as a loop over every
/// point tests it), in increasing index, through their order by x: only the points whose x lies
/// within `radius` of the centre's are tested.
std::vector<int> pointsInDisc(std::span<const Eigen::Vector3d> points, std::span<const int> byX,
                              const Eigen::Vector2d& center, double radius);

class Diffusion {
public:
    Diffusion(const MembraneParams& params, std::span<const Eigen::Vector3d> rest,
              const BondFamilies& bonds, std::span<const double> volumes);

    /// Whether the scene has anything to diffuse: sources, edges or a non-zero initial value.
    /// When not, theta stays 0 whatever the conductivity, and the membrane keeps no theta.
    static bool needed(const MembraneParams& params);

    double stableTimeStep() const { return stableDt_; }
    double coefficient() const { return K_; }  ///< calibrated K of eq. 25

    /// theta at t = 0 (initial value, edges applied).
    std::vector<double> initialTheta() const;

    /// Advances theta from t to t + dt, sub-stepping as the stability bound requires, through
    /// the bonds `damage` (of the bonds it was built on) keeps alive.
    void advance(std::vector<double>& theta, const DamageState& damage, double t, double dt);

    /// At least every |theta change| of the last advance() (0 before the first), where
    /// measureChanges() asked for it; else -1.
    double lastChange() const { return measure_ ? lastChange_ : -1.0; }
    /// From now on, advance() measures lastChange() (about 1% of a step at 10^4 particles: the
    /// power law's look-ahead reads it, PeridynamicBonds::lookAheadClear).
    void measureChanges() { measure_ = true; }

    /// The blow-up guard's theta half (sim/StepKernels.h's guardThetaSums: the largest |theta|
    /// and the lowest index whose theta is not finite) of the theta the last advance() left,
    /// over the particles it advanced, taken as it wrote them; null before the first.
    const GuardSums* thetaSums() const { return thetaSumsTaken_ ? &thetaSums_ : nullptr; }

    std::size_t spotCount() const { return spots_.size(); }
    /// The bonds' rates in tiles (sim/DiffusionKernels.h).
    const DiffusionTiles& tiles() const { return tiles_; }

    /// Decomposed runs (sim/Domain.h): advances only its slab's theta, and refreshes the
    /// ghosts through `domain` after every sub-step.
    void restrictTo(Domain& domain) { domain_ = &domain; }

private:
    struct Spot {
        double start, end, rate;
        std::vector<int> particles;
    };
    /// Where sources are placed and measured: the rest positions and per-particle areas, and
    /// the seed lattice's (sheet.seedSpacing; null at the seed spacing itself).
    struct SourceFrame {
        std::span<const Eigen::Vector3d> rest;
        std::vector<double> areas;
        const Lattice* seeds = nullptr;
        std::vector<int> restByX, seedsByX;  ///< orderByX() of each
    };
    void addSpot(const DiffusionSpot& spot, const SourceFrame& frame);
    void expandScatter(const SpotScatter& scatter, const SourceFrame& frame);
    /// One sub-step; returns at least every |theta change| in it where measure_, else 0. With
    /// `takeSums` (the last sub-step), takes thetaSums() of the theta it leaves.
    double step(std::vector<double>& theta, const DamageState& damage, double t, double dt,
                bool takeSums);
    /// thetaSums() from each chunk's sums of the values step() wrote, the `touched` ones (whose
    /// particles a source set or moved since) summed again from `theta`, and the particles
    /// [first, headEnd) and [tailBegin, last) outside the chunks.
    void takeThetaSums(const std::vector<double>& theta, const std::vector<std::uint8_t>& touched,
                       int firstTile, int lastTile, int first, int headEnd, int tailBegin,
                       int last);

    double K_ = 0.0;
    double stableDt_ = 0.0;
    double initial_ = 0.0;
    int particles_ = 0;
    /// Per bond, K W0 V_j / (rho C |xi|^2) [1/s], in tiles of eight particles; a lattice's bond
    /// at its exact length (sim/Diffusion.cpp's LatticeLength).
    DiffusionTiles tiles_;
    std::vector<Spot> spots_;
    std::vector<std::pair<int, double>> held_;  ///< edge sources: particle, value
    std::vector<double> scratch_;
    static constexpr int kChunk = 64;   ///< tiles per chunk of step()'s loop
    std::vector<double> chunkChange_;   ///< step()'s largest change per chunk of tiles
    std::vector<GuardSums> chunkSums_;  ///< step()'s thetaSums() per chunk of tiles
    GuardSums thetaSums_;
    bool thetaSumsTaken_ = false;
    double lastChange_ = 0.0;
    bool measure_ = false;
    Domain* domain_ = nullptr;
};

}  // namespace rend::sim
