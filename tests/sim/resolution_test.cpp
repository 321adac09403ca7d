// Issue 12: a finer lattice of the same sheet is the same sheet. Seeded draws (the jitter at rest,
// scattered spots) sit on the lattice of the seed spacing, and a source injects the same dose
// (theta x area per second) at every spacing.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <utility>

#include "sim/Lattice.h"
#include "sim/Membrane.h"
#include "sim/Random.h"
#include "tests/sim/Peridynamic.h"

using namespace rend::sim;

namespace {

MembraneParams sheetAt(double dx, double seedSpacing) {
    MembraneParams p;
    p.sheet.size = {1.0, 1.0};
    p.sheet.dx = dx;
    p.sheet.seedSpacing = seedSpacing;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    p.time.dt = 1e-3;
    return p;
}

/// sum_i theta_i A_i: the theta injected into an insulated sheet without diffusion.
double dose(const Membrane& m) {
    double sum = 0.0;
    for (int i = 0; i < m.particleCount(); ++i)
        sum += m.theta()[i] * m.volumes()[i] / m.lattice().particleArea;
    return sum * m.lattice().particleArea;
}

double doseAfterTenSteps(MembraneParams p) {
    Membrane m(p);
    for (int s = 0; s < 10; ++s) m.step();
    return dose(m) / p.sheet.thickness;
}

}  // namespace

TEST(Resolution, ASpotInjectsTheSameDoseAtASixthOfTheSpacing) {
    for (const double radius : {0.05, 0.07, 0.13}) {
        MembraneParams coarse = sheetAt(0.04, 0.04), fine = sheetAt(0.04 / 6, 0.04);
        for (MembraneParams* p : {&coarse, &fine})
            p->diffusion.spots = {DiffusionSpot{{0.013, -0.021}, radius, 1.0, 0.0, 1.0}};
        const double a = doseAfterTenSteps(coarse), b = doseAfterTenSteps(fine);
        EXPECT_NEAR(b / a, 1.0, 0.02) << "radius " << radius;
        // Without the seed lattice the fine one injects about the disc's own area instead.
        MembraneParams own = sheetAt(0.04 / 6, 0.0);
        own.diffusion.spots = fine.diffusion.spots;
        std::printf(
            "[resolution] spot r = %.2f m: dose %.5f (dx 0.04) %.5f (dx 0.04/6, seeded) "
            "%.5f (dx 0.04/6, unseeded), pi r^2 x 0.01 s = %.5f\n",
            radius, a, b, doseAfterTenSteps(own), M_PI * radius * radius * 0.01);
    }
}

TEST(Resolution, ScatteredSpotsLandOnTheSameCentresAtEverySpacing) {
    MembraneParams coarse = sheetAt(0.04, 0.04), fine = sheetAt(0.01, 0.04);
    for (MembraneParams* p : {&coarse, &fine})
        p->diffusion.scatters = {SpotScatter{20, 0.06, 1.0, 0.0, 0.0, 1.0, 11}};
    const double a = doseAfterTenSteps(coarse), b = doseAfterTenSteps(fine);
    EXPECT_NEAR(b / a, 1.0, 0.02);
    // The hottest particle of the fine sheet is where the coarse one's is (overlapping spots).
    Membrane mc(coarse), mf(fine);
    for (int s = 0; s < 10; ++s) mc.step(), mf.step();
    auto hottest = [](const Membrane& m) {
        int best = 0;
        for (int i = 1; i < m.particleCount(); ++i)
            if (m.theta()[i] > m.theta()[best]) best = i;
        return m.restPositions()[best];
    };
    EXPECT_LT((hottest(mc) - hottest(mf)).norm(), 0.1);
}

/// A sheet at dx 0.04 with a jitter of 1 mm (its own seed spacing) and the same sheet at dx 0.01,
/// seeded by it.
static std::pair<SheetParams, SheetParams> jitteredSheets(std::uint64_t seed) {
    SheetParams coarse = sheetAt(0.04, 0.04).sheet;
    coarse.perturbationAmplitude = 1e-3;
    coarse.perturbationSeed = seed;
    SheetParams fine = coarse;
    fine.dx = 0.01;
    return {coarse, fine};
}

// The finer sheet's heights are the coarse lattice's values interpolated linearly in the
// coarse triangle holding each particle, found by a search over every triangle (and, just
// outside the coarse rim, extended from the least-outside triangle).
TEST(Resolution, TheJitterIsInterpolatedInTheCoarseTriangleHoldingEachParticle) {
    const auto [coarse, fine] = jitteredSheets(5);
    const Lattice lc = generateLattice(coarse), lf = generateLattice(fine);
    const std::vector<double> values = perturbationHeights(coarse, lc.positions);
    std::vector<Eigen::Vector3d> at = lf.positions;
    for (int k = 0; k < 300; ++k)  // and points off the lattice, some beyond the rim
        at.emplace_back(1.2 * uniformFromHash(9, 2 * k) - 0.6,
                        1.2 * uniformFromHash(9, 2 * k + 1) - 0.6, 0.0);
    const std::vector<double> z = perturbationHeights(fine, at);
    // Each triangle's weights at p; its smallest; its value there, weights clamped.
    const auto weightsAt = [&](int t, const Eigen::Vector3d& p) {
        const auto& [a, b, c] = lc.triangles[t];
        Eigen::Matrix2d m;
        m << (lc.positions[b] - lc.positions[a]).head<2>(),
            (lc.positions[c] - lc.positions[a]).head<2>();
        const Eigen::Vector2d uv = m.inverse() * (p - lc.positions[a]).head<2>();
        return Eigen::Vector3d(1.0 - uv.sum(), uv.x(), uv.y());
    };
    const auto valueIn = [&](int t, const Eigen::Vector3d& p) {
        const Eigen::Vector3d w = weightsAt(t, p).cwiseMax(0.0);
        const auto& [a, b, c] = lc.triangles[t];
        return (w[0] * values[a] + w[1] * values[b] + w[2] * values[c]) / w.sum();
    };
    int inside = 0, rim = 0;
    for (std::size_t i = 0; i < at.size(); ++i) {
        double most = -std::numeric_limits<double>::infinity();
        for (int t = 0; t < int(lc.triangles.size()); ++t)
            most = std::max(most, weightsAt(t, at[i]).minCoeff());
        if (most < -0.5) continue;
        inside += most >= 0.0, rim += most < 0.0;
        // The value of a triangle holding p (of any, where p is on an edge), or just outside the
        // rim of one whose smallest weight is the largest (the least outside), extended.
        bool matched = false;
        for (int t = 0; t < int(lc.triangles.size()) && !matched; ++t)
            matched = weightsAt(t, at[i]).minCoeff() >= most - 1e-12 &&
                      std::abs(z[i] - valueIn(t, at[i])) <= 1e-12 * coarse.perturbationAmplitude;
        ASSERT_TRUE(matched) << "point " << i << " at " << at[i].transpose() << ": " << z[i];
    }
    EXPECT_GT(inside, int(lf.positions.size()) / 2);
    EXPECT_GT(rim, 20);
}

TEST(Resolution, TheJitterIsTheSameSurfaceSampledFiner) {
    const auto [coarse, fine] = jitteredSheets(3);
    const Lattice lc = generateLattice(coarse), lf = generateLattice(fine);
    const std::vector<double> zc = perturbationHeights(coarse, lc.positions);
    const std::vector<double> zf = perturbationHeights(fine, lf.positions);
    auto steepest = [](const Lattice& l, const std::vector<double>& z, double dx) {
        double slope = 0.0;
        // Inside the coarse lattice's rim, where the heights are interpolated, not extended.
        auto inner = [&](int v) {
            return l.positions[v].head<2>().lpNorm<Eigen::Infinity>() < 0.44;
        };
        for (const auto& [a, b, c] : l.triangles)
            if (inner(a) && inner(b) && inner(c))
                slope = std::max({slope, std::abs(z[a] - z[b]), std::abs(z[b] - z[c])});
        return slope / dx;
    };
    SheetParams unseeded = fine;
    unseeded.seedSpacing = 0.0;
    const double seeded = steepest(lf, zf, fine.dx), own = steepest(lc, zc, coarse.dx);
    const double rough = steepest(lf, perturbationHeights(unseeded, lf.positions), fine.dx);
    std::printf(
        "[resolution] jitter's steepest slope: %.4f (dx 0.04), %.4f (dx 0.01, seeded), "
        "%.4f (dx 0.01, one value per particle)\n",
        own, seeded, rough);
    // Interpolated within the coarse triangles the slopes stay the coarse ones' (a triangle's
    // gradient exceeds its edges' by at most 2 / sqrt(3)), where one value per fine particle
    // would make them four times as steep and strain the bonds at rest.
    EXPECT_LT(seeded, 2.0 * own);
    EXPECT_GT(rough, 3.0 * own);
    for (const double z : zf) EXPECT_LE(std::abs(z), coarse.perturbationAmplitude);
}

// critical_stretch = "preview": a sheet breaks at the same stretch at every spacing (a strength),
// where the calibrated eta_c grows as 1 / sqrt(dx) at a fixed horizon factor. The bonds of a
// finer lattice, and the continuum's reference value, break at the preview's stretch.
TEST(Resolution, APreviewStrengthBreaksAtThePreviewsStretchAtEverySpacing) {
    const auto etaAt = [](double dx, CriticalStretchMode mode) {
        MembraneParams p = sheetAt(dx, 0.05);
        p.material.fractureEnergy = 5.0;
        p.material.criticalStretch = mode;
        const Membrane m(p);
        return std::pair{rend::test::criticalStretch(m), m.referenceCriticalStretch()};
    };
    const auto [calibrated, calibratedReference] = etaAt(0.05, CriticalStretchMode::Calibrated);
    const auto [finer, finerReference] = etaAt(0.025, CriticalStretchMode::Calibrated);
    EXPECT_NEAR(finer / calibrated, std::sqrt(2.0), 1e-9);
    EXPECT_NEAR(finerReference / calibratedReference, std::sqrt(2.0), 1e-9);
    for (const double dx : {0.05, 0.025, 0.0125 * 1.6}) {
        const auto [preview, reference] = etaAt(dx, CriticalStretchMode::Preview);
        EXPECT_NEAR(preview / calibrated, 1.0, 1e-9) << "dx " << dx;
        EXPECT_NEAR(reference / calibratedReference, 1.0, 1e-9) << "dx " << dx;
    }
}

TEST(Resolution, AMidwayStrengthIsTheGeometricMeanOfTheCalibratedAndThePreviews) {
    const auto etaAt = [](double dx, CriticalStretchMode mode) {
        MembraneParams p = sheetAt(dx, 0.05);
        p.material.fractureEnergy = 5.0;
        p.material.criticalStretch = mode;
        return rend::test::criticalStretch(Membrane(p));
    };
    const double preview = etaAt(0.05, CriticalStretchMode::Calibrated);
    EXPECT_NEAR(etaAt(0.05, CriticalStretchMode::Midway) / preview, 1.0, 1e-9);
    for (const double dx : {0.025, 0.0125 * 1.6}) {
        const double calibrated = etaAt(dx, CriticalStretchMode::Calibrated);
        EXPECT_NEAR(etaAt(dx, CriticalStretchMode::Midway), std::sqrt(calibrated * preview), 1e-12)
            << "dx " << dx;
        EXPECT_NEAR(etaAt(dx, CriticalStretchMode::Midway) / preview, std::pow(0.05 / dx, 0.25),
                    1e-9)
            << "dx " << dx;
    }
}

// A softening law localises its strain in one row of bonds, so the work past the yield per unit
// crack length must not shrink with the row: each bond's eta0^2 / beta times the bonds crossing a
// unit crack (c S / pi, from the calibrated eta_c^2 = 2 pi G_f / (c S)) holds at every spacing.
TEST(Resolution, TheSofteningTakesTheSameWorkPerUnitCrackAtEverySpacing) {
    const auto softeningWork = [](double dx, double seedSpacing) {
        MembraneParams p = sheetAt(dx, seedSpacing);
        p.material.law = BondLawKind::Elastoplastic;
        p.material.yieldStrain = 0.015;
        p.material.softening = 0.06;
        p.material.fractureEnergy = 5.0;
        const Membrane m(p);
        const double eta = rend::test::criticalStretch(m), eta0 = 0.015;
        const double perBond = eta0 * eta0 / m.params().material.softening;
        return *p.material.fractureEnergy * 2.0 * perBond / (eta * eta);
    };
    const double preview = softeningWork(0.05, 0.05);
    for (const double dx : {0.025, 0.0125 * 1.6})
        EXPECT_NEAR(softeningWork(dx, 0.05) / preview, 1.0, 1e-9) << "dx " << dx;
    EXPECT_NEAR(softeningWork(0.025, 0.0) / preview, 0.5, 1e-9)
        << "without a preview spacing the law is the one given, and a finer row takes less work";
}
