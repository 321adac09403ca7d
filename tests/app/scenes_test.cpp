// The paper's scenes: every shipped scene runs (shortened) without a non-finite value, and the
// crack path is mirror-symmetric without diffusion and not with two unequal sources (Fig. 2).

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "app/Pipeline.h"
#include "app/Scene.h"

using namespace rend;

namespace {

std::filesystem::path sceneFile(const std::string& name) {
    return std::filesystem::path(REND_SOURCE_DIR) / "scenes" / (name + ".toml");
}

std::vector<std::string> shippedScenes() {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(sceneFile("x").parent_path()))
        if (entry.path().extension() == ".toml") names.push_back(entry.path().stem().string());
    std::sort(names.begin(), names.end());
    return names;
}

bool allFinite(const sim::Membrane& m) {
    for (int i = 0; i < m.particleCount(); ++i)
        if (!m.positions()[i].allFinite() || !m.velocities()[i].allFinite()) return false;
    for (double t : m.theta())
        if (!std::isfinite(t)) return false;
    return true;
}

// Rest-position midpoints of the broken bonds, each bond once.
std::vector<Eigen::Vector2d> brokenBondMidpoints(const sim::Membrane& m) {
    std::vector<Eigen::Vector2d> points;
    const sim::BondFamilies& b = m.bonds();
    for (int i = 0; i < m.particleCount(); ++i)
        for (int k = b.offsets[i]; k < b.offsets[i + 1]; ++k)
            if (!m.damageState().bondAlive()[k] && i < b.partners[k])
                points.push_back(
                    0.5 * (m.restPositions()[i] + m.restPositions()[b.partners[k]]).head<2>());
    return points;
}

// Mean distance from each broken bond to the nearest broken bond mirrored about y = 0.
double mirrorMismatch(const std::vector<Eigen::Vector2d>& points) {
    double sum = 0.0;
    for (const auto& p : points) {
        double nearest = 1e9;
        for (const auto& q : points)
            nearest = std::min(nearest, (p - Eigen::Vector2d(q.x(), -q.y())).norm());
        sum += nearest;
    }
    return sum / double(points.size());
}

sim::Membrane runCrackPath(const std::string& name) {
    // The first 4 s: the crack has grown most of the way across. At Table 1's dt, the step the
    // symmetry was measured at (the adaptive default's mismatch is 0.032 m, still under 2 dx).
    const Scene scene = loadScene(sceneFile(name), {"time.duration=4.0", "time.dt=1e-4"});
    sim::Membrane m = prepareMembrane(scene);
    const long steps = std::lround(scene.sim.time.duration / m.timeStep());
    for (long s = 0; s < steps; ++s) m.step();
    return m;
}

}  // namespace

TEST(Scenes, EveryShippedSceneRunsShortenedWithoutNonFiniteValues) {
    const std::vector<std::string> names = shippedScenes();
    ASSERT_GE(names.size(), 13u);
    for (const std::string& name : names) {
        const Scene scene = loadScene(sceneFile(name));
        sim::Membrane m = prepareMembrane(scene);
        // A fifth of a second of each: enough for sources, ramps and notches to act.
        const int steps = std::min(2000, int(0.2 / m.timeStep()) + 1);
        for (int s = 0; s < steps; ++s) ASSERT_NO_THROW(m.step()) << name;
        EXPECT_TRUE(allFinite(m)) << name;
        EXPECT_GT(m.kineticEnergy(), 0.0) << name << " moved";
    }
}

TEST(Scenes, EveryShippedSceneSetsUpAndStepsAtFinalQuality) {
    // quality = "final": at least a quarter of a million particles per sheet, every boundary
    // region, notch and source found at the fine spacing, and the first steps finite.
    for (const std::string& name : shippedScenes()) {
        const Scene scene = loadScene(sceneFile(name), {"sheet.quality=\"final\""});
        ASSERT_EQ(scene.quality, Quality::Final) << name;
        sim::Membrane m = prepareMembrane(scene);
        EXPECT_GE(std::size_t(m.particleCount()), kFinalParticles) << name;
        for (int s = 0; s < 3; ++s) ASSERT_NO_THROW(m.step()) << name;
        EXPECT_TRUE(allFinite(m)) << name;
    }
}

TEST(Scenes, CrackPathIsMirrorSymmetricWithoutDiffusionAndNotWithTwoUnequalSources) {
    const sim::Membrane plain = runCrackPath("crack_path");
    const sim::Membrane sources = runCrackPath("crack_path_sources");
    const auto plainCrack = brokenBondMidpoints(plain);
    const auto sourcesCrack = brokenBondMidpoints(sources);
    ASSERT_GT(plainCrack.size(), 2 * plain.notchedBondCount()) << "the crack grew";
    ASSERT_GT(sourcesCrack.size(), 2 * sources.notchedBondCount());
    const double symmetric = mirrorMismatch(plainCrack);
    const double asymmetric = mirrorMismatch(sourcesCrack);
    std::printf("crack path mirror mismatch: %.4f m without diffusion, %.4f m with sources\n",
                symmetric, asymmetric);
    // The hexagonal lattice is mirror-symmetric about the notch only up to a dx/2 glide, so the
    // straight crack matches its mirror image to about a spacing (0.02 m).
    EXPECT_LT(symmetric, 0.03);
    EXPECT_GT(asymmetric, 3.0 * symmetric);
}
