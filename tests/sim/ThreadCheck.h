#pragma once
// Shared by the solver tests: a sheet pulled apart by two grips, and the check that 1 and 2
// OpenMP threads give identical bits (each solver sums per particle in a fixed order).

#include <gtest/gtest.h>
#include <omp.h>

#include <cstring>
#include <vector>

#include "sim/Membrane.h"

namespace rend::sim::support {

/// Grips on the left and right 1 cm of a sheet 1 m wide, pulling apart at 0.3 m/s, the left one
/// lifting a little so the sheet leaves its plane.
inline std::vector<BoundaryCondition> pullingGrips() {
    BoundaryCondition left, right;
    left.kind = right.kind = BoundaryKind::Velocity;
    left.region.max.x() = -0.49;
    right.region.min.x() = 0.49;
    left.velocity = {-0.3, 0, 0.02};
    right.velocity = {0.3, 0, 0};
    return {left, right};
}

/// The DamageState agrees with itself: both copies of a bond and its edge break together, the
/// broken count is the bonds seen broken, and a triangle is kept exactly while it is alive and
/// its three edges are intact.
inline void expectConsistentDamage(const Membrane& m) {
    const DamageState& d = m.damageState();
    const std::vector<std::uint8_t>& alive = d.bondAlive();
    std::size_t broken = 0;
    for (std::size_t b = 0; b < alive.size(); ++b) {
        broken += alive[b] == 0;
        ASSERT_EQ(alive[b], alive[d.mirror(int(b))]) << "bond " << b;
        if (const int e = d.bondEdge(int(b)); e >= 0) {
            ASSERT_EQ(d.edgeIntact(e), alive[b] != 0) << "edge " << e;
        }
    }
    EXPECT_EQ(broken, 2 * d.brokenBondCount());
    EXPECT_EQ(d.brokenBondCount(), m.brokenBondCount());
    for (std::size_t t = 0; t < d.keptTriangles().size(); ++t) {
        bool kept = d.triangleAlive()[t] != 0;
        for (int e : d.triangleEdges(int(t))) kept = kept && d.edgeIntact(e);
        ASSERT_EQ(d.keptTriangles()[t] != 0, kept) << "triangle " << t;
    }
    const FrameView v = m.view(1);
    EXPECT_EQ(v.keptTriangles.data(), d.keptTriangles().data()) << "the surfaces read this";
    EXPECT_EQ(v.bondAlive.data(), alive.data());
}

/// Runs `steps` steps with 1 and then 2 threads and expects the same positions, broken bonds,
/// removed triangles and damage, bit for bit, and a consistent DamageState. Returns the broken
/// bond count.
inline std::size_t expectSameBitsWithOneAndTwoThreads(const MembraneParams& p, int steps) {
    struct Result {
        std::vector<Eigen::Vector3d> positions;
        std::size_t broken;
        std::vector<double> damage;
        std::vector<std::uint8_t> bondAlive, kept;
    };
    auto run = [&](int threads) {
        omp_set_num_threads(threads);
        Membrane m(p);
        EXPECT_GT(m.particleCount(), kParallelThreshold) << "must take the parallel path";
        for (int k = 0; k < steps; ++k) m.step();
        m.updateDamage();
        expectConsistentDamage(m);
        return Result{m.positions(), m.brokenBondCount(), m.damage(), m.damageState().bondAlive(),
                      m.damageState().keptTriangles()};
    };
    const Result one = run(1), two = run(2);
    omp_set_num_threads(2);
    EXPECT_EQ(one.positions.size(), two.positions.size());
    if (one.positions.size() == two.positions.size()) {
        const std::size_t bytes = one.positions.size() * sizeof(one.positions[0]);
        EXPECT_EQ(std::memcmp(one.positions.data(), two.positions.data(), bytes), 0);
    }
    EXPECT_EQ(one.broken, two.broken);
    EXPECT_EQ(one.damage, two.damage);
    EXPECT_EQ(one.bondAlive, two.bondAlive);
    EXPECT_EQ(one.kept, two.kept);
    return one.broken;
}

}  // namespace rend::sim::support
