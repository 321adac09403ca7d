#pragma once
// Constant-strain triangle (CST) membrane: the continuum reference of the seminar report
// (seeds/001) on the rest lattice's triangles. Per triangle, with rest edge matrix Dm (2x2, in
// the rest triangle's own plane, first axis along edge 01) and current edge matrix Ds (3x2):
//     F = Ds Dm^-1 (3x2),  E = (F^T F - I) / 2  (Green strain, report eq. 2.6),
//     S = lambda* tr(E) I + 2 mu E  (Hooke's law on the Green strain: St. Venant-Kirchhoff),
// with the plane-stress constants lambda* = E nu / (1 - nu^2), mu = E / (2 (1 + nu)), so nu is
// free (the bond-based model fixes 1/3). The nodal forces are the exact negative gradient of
// the stored energy A0 h (lambda*/2 tr(E)^2 + mu E:E): H = -A0 h F S Dm^-T gives vertices 1 and
// 2 as its columns, vertex 0 minus their sum.

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <array>
#include <vector>

#include "sim/Lattice.h"
#include "sim/Params.h"
#include "sim/Solver.h"

namespace rend::sim {

class FemCst final : public Solver {
public:
    /// criticalStrain: an element is removed once its largest principal stretch exceeds
    /// 1 + criticalStrain (infinity: never).
    /// The material's thermal strain alpha theta and its stiffness and strength losses apply
    /// per element, with theta averaged over its corners.
    FemCst(const Lattice& lattice, const MaterialParams& material, double thickness,
           double criticalStrain);

    void forces(const std::vector<Eigen::Vector3d>& x,
                std::vector<Eigen::Vector3d>& force) const override;
    std::vector<double> stiffnessRowSums(int particleCount) const override;
    double strainEnergy(const std::vector<Eigen::Vector3d>& x) const override;
    std::vector<std::array<int, 2>> fracture(const std::vector<Eigen::Vector3d>& x) override;
    /// A notch removes every element with a cut side (a gap one element wide).
    bool cut(const std::vector<std::array<int, 2>>& edges) override;
    std::span<const std::uint8_t> triangleAlive() const override { return triangleAlive_; }

    /// Green strain of triangle t at positions x, in its rest frame (first axis along edge 01).
    Eigen::Matrix2d greenStrain(int t, const std::vector<Eigen::Vector3d>& x) const;
    int elementCount() const { return int(elements_.size()); }

private:
    struct Element {
        std::array<int, 3> v;
        Eigen::Matrix2d restInverse;  ///< Dm^-1
        double restArea;              ///< A0
        int triangle;                 ///< index into the lattice's triangles
        std::array<int, 3> across;    ///< element across side s (opposite vertex s), or -1
    };
    void findNeighbours();
    /// Mean theta over the element's corners (0 without diffusion).
    double thetaOf(const Element& e) const;
    /// Removes element t and returns the sides no living element holds any more.
    void erode(int t, std::vector<std::array<int, 2>>& apart);
    Eigen::Matrix<double, 3, 2> deformationGradient(const Element& e,
                                                    const std::vector<Eigen::Vector3d>& x) const;

    std::vector<Element> elements_;
    // Gather layout: the corners each particle belongs to (element * 3 + corner), so each
    // particle sums its own forces and the loop needs no atomics (and no ordering by thread).
    std::vector<int> cornerOffsets_, corners_;
    mutable std::vector<Eigen::Vector3d> cornerForce_;
    double lambda_ = 0.0, mu_ = 0.0, thickness_ = 0.0, criticalStrain_ = 0.0;
    double expansion_ = 0.0, stiffnessLoss_ = 0.0, strengthLoss_ = 0.0;
    std::vector<std::uint8_t> alive_;          ///< per element
    std::vector<std::uint8_t> triangleAlive_;  ///< per lattice triangle, for the FrameView
};

/// Per particle, the corners (element * 3 + corner) of the triangles that contain it, in CSR.
void triangleIncidence(const std::vector<std::array<int, 3>>& triangles, int particleCount,
                       std::vector<int>& offsets, std::vector<int>& corners);

}  // namespace rend::sim
