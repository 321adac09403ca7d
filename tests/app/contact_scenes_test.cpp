// The contact scenes (issue 13) at preview quality, frame by frame: no two particles that are not
// bonded at rest come closer than half the contact thickness, nothing is below the ground, and
// no free particle is inside a collider.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "app/Pipeline.h"
#include "app/Scene.h"
#include "sim/ColliderDistance.h"

using namespace rend;

namespace {

std::filesystem::path sceneFile(const std::string& name) {
    return std::filesystem::path(REND_SOURCE_DIR) / "scenes" / (name + ".toml");
}

/// The closest two particles not bonded at rest (every pair, the sheets are small at preview).
double closestUnbondedPair(const sim::Membrane& m) {
    const auto& x = m.positions();
    const auto& rest = m.restPositions();
    const double reach2 = std::pow(m.horizon() * (1 + 1e-9), 2);
    double closest2 = 1e300;
    for (int i = 0; i < m.particleCount(); ++i)
        for (int j = i + 1; j < m.particleCount(); ++j) {
            const double d2 = (x[i] - x[j]).squaredNorm();
            if (d2 < closest2 && (rest[i] - rest[j]).squaredNorm() > reach2) closest2 = d2;
        }
    return std::sqrt(closest2);
}

/// The deepest a particle the boundaries leave free reaches into a collider, below the offset
/// d / 2 it keeps from their surfaces (0 when none does).
double deepestInCollider(const sim::Membrane& m, const Scene& scene) {
    const sim::Contact& contact = *m.contact();
    const double offset = 0.5 * contact.thickness();
    std::vector<bool> held(std::size_t(m.particleCount()), false);
    for (const sim::BoundaryCondition& bc : scene.sim.boundaries)
        for (int i = 0; i < m.particleCount(); ++i)
            if (bc.region.contains(m.restPositions()[i])) held[std::size_t(i)] = true;
    double deepest = 0.0;
    for (std::size_t c = 0; c < contact.colliders().size(); ++c) {
        const sim::ColliderParams& collider = contact.colliders()[c];
        const sim::ColliderPose& pose = contact.poses()[c];
        for (int i = 0; i < m.particleCount(); ++i) {
            if (held[std::size_t(i)]) continue;
            const auto s = sim::signedDistance(collider, nullptr, pose.toLocal(m.positions()[i]));
            if (s) deepest = std::max(deepest, offset - s->distance);
        }
    }
    return deepest;
}

struct Outcome {
    double closest = 1e300, lowest = 1e300, deepest = 0.0;
    std::size_t broken = 0;
};

Outcome runEveryFrame(const std::string& name) {
    const Scene scene = loadScene(sceneFile(name));
    sim::Membrane m = prepareMembrane(scene);
    EXPECT_TRUE(m.contact()) << name;
    Outcome o;
    for (int frame = 1; frame <= scene.frameCount(); ++frame) {
        m.advanceTo(frame / scene.sim.time.fps);
        o.closest = std::min(o.closest, closestUnbondedPair(m));
        for (const Eigen::Vector3d& x : m.positions()) o.lowest = std::min(o.lowest, x.z());
        o.deepest = std::max(o.deepest, deepestInCollider(m, scene));
    }
    o.broken = m.brokenBondCount();
    return o;
}

}  // namespace

TEST(ContactScenes, NothingPassesThroughAnythingOnAnyFrame) {
    for (const std::string name : {"foil_drape", "film_poke", "towel_pile"}) {
        const Scene scene = loadScene(sceneFile(name));
        ASSERT_TRUE(scene.sim.contact.self.enabled) << name;
        const double d = 0.5 * scene.sim.sheet.dx;  // the default contact thickness
        const Outcome o = runEveryFrame(name);
        EXPECT_GE(o.closest, 0.5 * d) << name;
        if (scene.sim.contact.ground.enabled)
            EXPECT_GE(o.lowest, scene.sim.contact.ground.height) << name;
        EXPECT_LE(o.deepest, 1e-9) << name << ": a particle inside a collider";
        EXPECT_GT(o.broken, 50u) << name << " tears";
    }
}
