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

/// Runs `steps` steps with 1 and then 2 threads and expects the same positions, broken bonds
/// and damage, bit for bit. Returns the broken bond count.
inline std::size_t expectSameBitsWithOneAndTwoThreads(const MembraneParams& p, int steps) {
    struct Result {
        std::vector<Eigen::Vector3d> positions;
        std::size_t broken;
        std::vector<double> damage;
    };
    auto run = [&](int threads) {
        omp_set_num_threads(threads);
        Membrane m(p);
        EXPECT_GT(m.particleCount(), kParallelThreshold) << "must take the parallel path";
        for (int k = 0; k < steps; ++k) m.step();
        m.updateDamage();
        return Result{m.positions(), m.brokenBondCount(), m.damage()};
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
    return one.broken;
}

}  // namespace rend::sim::support
