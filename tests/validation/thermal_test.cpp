// VALIDATION.md, "free thermal expansion: strain = alpha dT, 1e-6" and "clamped thermal stress:
// sigma = -E alpha dT / (1 - nu), 3%", with the bond-based nu = 1/3 (so sigma = -1.5 E alpha dT).
// Every bond law sees the mechanical strain eta - alpha theta_bar (README, "Diffusion-driven
// strain"); theta is uniform here (DiffusionParams::initial) and conductivity is 0.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sim/Membrane.h"
#include "tests/sim/Peridynamic.h"

using namespace rend::sim;

namespace {

constexpr double kE = 2e4, kAlpha = 1e-3, kDeltaT = 2.0;

MembraneParams heatedSheet(double size) {
    MembraneParams p;
    p.sheet.size = {size, size};
    p.sheet.dx = 0.02;
    p.material.youngsModulus = kE;
    p.material.density = 5000;
    p.material.expansion = kAlpha;
    p.diffusion.initial = kDeltaT;  // uniform theta = dT from t = 0
    p.time.integrator = Integrator::VelocityVerlet;
    p.time.duration = 1e9;
    return p;
}

}  // namespace

TEST(ValidationThermal, FreeSheetSettlesAtStrainAlphaDeltaTWithinOneMillionthUnderVerlet) {
    // Target: |strain - alpha dT| <= 1e-6 (VALIDATION.md, free thermal expansion).
    MembraneParams p = heatedSheet(0.2);
    // About twice the lowest in-plane frequency pi c / L (c ~ sqrt(E / rho)) so the sheet,
    // released from its cold rest shape, settles in a few periods.
    p.damping = 2.0 * 3.14159 * std::sqrt(kE / 5000) / 0.2;
    Membrane m(p);
    for (int s = 0; s < 4000; ++s) m.step();
    const auto& b = m.bonds();
    double sum = 0.0, worst = 0.0;
    long count = 0;
    for (int i = 0; i < m.particleCount(); ++i)
        for (int k = b.offsets[i]; k < b.offsets[i + 1]; ++k, ++count) {
            const double eta =
                (m.positions()[b.partners[k]] - m.positions()[i]).norm() / b.restLength[k] - 1.0;
            sum += eta;
            worst = std::max(worst, std::abs(eta - kAlpha * kDeltaT));
        }
    std::printf(
        "free expansion (Verlet, %d particles, t = %.2f s): mean bond strain %.9f,"
        " alpha dT = %.9f, max |eta - alpha dT| = %.2e  (target 1e-6)\n",
        m.particleCount(), m.time(), sum / count, kAlpha * kDeltaT, worst);
    EXPECT_LE(std::abs(sum / count - kAlpha * kDeltaT), 1e-6);
    EXPECT_LE(worst, 1e-6);
}

TEST(ValidationThermal,
     ClampedHeatedSheetCarriesMinusEAlphaDeltaTOverOneMinusNuWithinThreePercent) {
    // Target: interior sigma_xx = sigma_yy = -E alpha dT / (1 - nu) within 3% (VALIDATION.md).
    MembraneParams p = heatedSheet(0.4);
    BoundaryCondition all;  // the default Region is unbounded: every particle is held at rest
    all.kind = BoundaryKind::Pinned;
    p.boundaries = {all};
    Membrane m(p);
    for (int s = 0; s < 100; ++s) m.step();
    const double reference = -kE * kAlpha * kDeltaT / (1.0 - 1.0 / 3.0);
    const double delta = m.horizon();
    double worst = 0.0, meanXX = 0.0, meanYY = 0.0, maxShear = 0.0;
    int interior = 0;
    for (int i = 0; i < m.particleCount(); ++i) {
        const Eigen::Vector3d& x = m.restPositions()[i];
        ASSERT_EQ(x, m.positions()[i]) << "held at rest";
        if (std::abs(x.x()) > 0.2 - delta || std::abs(x.y()) > 0.2 - delta) continue;
        const Eigen::Matrix3d s = rend::test::particleStress(m, i);
        worst =
            std::max({worst, std::abs(s(0, 0) / reference - 1), std::abs(s(1, 1) / reference - 1)});
        maxShear = std::max(maxShear, std::abs(s(0, 1) / reference));
        meanXX += s(0, 0);
        meanYY += s(1, 1);
        ++interior;
    }
    meanXX /= interior;
    meanYY /= interior;
    std::printf(
        "clamped thermal stress, %d interior particles: mean sigma_xx = %.6f Pa,"
        " sigma_yy = %.6f Pa, reference -E alpha dT/(1-nu) = %.6f Pa; worst particle"
        " error %.2e, max |sigma_xy / ref| = %.1e  (target 3%%)\n",
        interior, meanXX, meanYY, reference, worst, maxShear);
    const Eigen::Matrix3d corner = rend::test::particleStress(m, 0);
    std::printf(
        "  (reported only) corner particle: sigma_xx / ref = %.4f, sigma_yy / ref = %.4f"
        " (skin effect)\n",
        corner(0, 0) / reference, corner(1, 1) / reference);
    EXPECT_LE(worst, 0.03);
    EXPECT_LE(maxShear, 0.03);
}
