#pragma once
// The only thing that crosses from sim/ to render/: read-only views of one frame's state.
// Like OpenVDB's ParticleList contract (tools/ParticlesToLevelSet.h), it is small and
// documented; render/ never sees the solver.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "sim/Collider.h"

namespace rend::sim {

struct FrameView {
    int frame = 0;      ///< frame index, 1-based as in frame_0001.png
    double time = 0.0;  ///< simulated seconds

    std::span<const Eigen::Vector3d> positions;      ///< current x_i
    std::span<const Eigen::Vector3d> velocities;     ///< current v_i
    std::span<const Eigen::Vector3d> restPositions;  ///< x0_i (the rest lattice)
    std::span<const double> theta;   ///< diffusive quantity; empty when the scene has none
    std::span<const double> damage;  ///< per-particle damage in [0,1]; empty if nothing breaks

    /// Rest-lattice triangles (particle indices, counter-clockwise seen from +z at rest).
    std::span<const std::array<int, 3>> restTriangles;

    /// Bond families in CSR form: bonds of particle i are [bondOffsets[i], bondOffsets[i+1]).
    /// Every bond is stored from both ends.
    std::span<const int> bondOffsets;
    std::span<const int> bondPartners;
    std::span<const double> bondRestLength;
    /// 1 intact, 0 broken. The two copies of a bond (i->j and j->i) always agree: the
    /// DamageState breaks a bond from both ends, so a reader may look at either.
    std::span<const std::uint8_t> bondAlive;
    /// Per rest triangle, 1 while it is kept: not removed (the FEM's element erosion) and none
    /// of its edges broken. Every surface and the pressure load read this one flag; empty
    /// means every triangle is kept.
    std::span<const std::uint8_t> keptTriangles;

    /// Per rest triangle, 0 once removed (the FEM's element erosion), whatever its edges; empty
    /// means none is. It tells a removed triangle from one whose edges broke, which the lattice
    /// surface cuts rather than drops.
    std::span<const std::uint8_t> triangleAlive;

    /// Seed 004's particle level set of the outline (sim/ParticleLevelSet.h): Phi, the signed
    /// distance along the sheet to its outline or a crack, negative inside, per particle
    /// (-3 dx beyond the narrow band); the ghost particles outside the outline, their rest
    /// sites, Phi and anchors (each ghost's particle); and the band's triangles, whose corners
    /// are particles (< particleCount) and ghosts (particleCount + ghost), kept while bandKept.
    /// All empty where the sheet has no outline (a sphere has no ghosts, only Phi).
    std::span<const double> levelSet;
    std::span<const Eigen::Vector3d> ghostPositions;
    std::span<const Eigen::Vector3d> ghostRestPositions;
    std::span<const double> ghostLevelSet;
    std::span<const int> ghostAnchors;
    std::span<const std::array<int, 3>> bandTriangles;
    std::span<const std::uint8_t> bandKept;

    /// The scene's colliders (sim/Collider.h) and, index for index, their poses at `time`; empty
    /// without colliders. The ground plane is the render settings' own.
    std::span<const ColliderParams> colliders;
    std::span<const ColliderPose> colliderPoses;

    bool triangleKept(std::size_t t) const { return keptTriangles.empty() || keptTriangles[t]; }

    std::size_t particleCount() const { return positions.size(); }

    /// Index of the bond i->j in the CSR arrays, or -1 when i and j are not bonded.
    int findBond(int i, int j) const {
        for (int b = bondOffsets[i]; b < bondOffsets[i + 1]; ++b)
            if (bondPartners[b] == j) return b;
        return -1;
    }
};

}  // namespace rend::sim
