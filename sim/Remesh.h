#pragma once
// Seed 004's remeshing (seeds/004, Sec. 3.2), for the particle solvers: every N steps the
// particles' positions and velocities are redistributed with the M4' kernel onto the regular
// particle set. A membrane's particles are material points that carry bonds and cracks, so the
// regular set is their own rest lattice, and the redistribution runs in material coordinates:
// particle i takes the value at X_i of the moving-least-squares linear fit, weighted by
//     W(X_j - X_i) = M4'(dx_j / h) M4'(dy_j / h),   h = dx,
//     M4'(s) = 1 - 5 s^2 / 2 + 3 |s|^3 / 2 (|s| < 1),  (1 - |s|)(2 - |s|)^2 / 2 (|s| < 2),
// (eq. 28, the tensor product in the rest plane), over itself and the particles joined to it by
// intact bonds. So an affine field (a stretch, a rotation, a rigid spin) is kept exactly, the
// particle-scale part is smoothed away, and nothing is ever carried across a crack. The masses
// stay with their particles; the linear momentum the fit changes is handed back evenly, so it is
// conserved to round-off (the angular momentum is measured: ValidationRemesh).

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "sim/Bonds.h"

namespace rend::sim {

/// The M4' kernel of eq. 28 at s = |x| / h.
double m4Prime(double s);

class Remesher {
public:
    /// rest: flat rest positions (z ignored); bonds: the membrane's; h: the kernel's width [m].
    Remesher(std::span<const Eigen::Vector3d> rest, const BondFamilies& bonds, double h);

    /// Redistributes x and v of the particles with free[i] != 0 over their intact bonds.
    void remesh(std::span<Eigen::Vector3d> x, std::span<Eigen::Vector3d> v,
                std::span<const double> mass, std::span<const std::uint8_t> alive,
                std::span<const std::uint8_t> free) const;

private:
    /// The fit's value at X_i of the field `f` over i's intact neighbours.
    Eigen::Vector3d fitted(int i, std::span<const Eigen::Vector3d> f,
                           std::span<const std::uint8_t> alive) const;

    const BondFamilies& bonds_;
    std::vector<Eigen::Vector2d> rest_;
    std::vector<double> weight_;  ///< per bond, W(X_j - X_i)
};

}  // namespace rend::sim
