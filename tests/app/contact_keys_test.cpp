// [contact] and [[collider]] as a hostile user writes them: every mistake is refused at its
// file:line:column with what was expected; good ones load into the simulation's parameters.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/Scene.h"
#include "app/SceneError.h"
#include "tests/ScratchDir.h"
#include "tests/app/Refusal.h"

using namespace rend;
namespace fs = std::filesystem;

namespace {

constexpr const char* kSheet = R"([sheet]
size = [0.4, 0.4]
dx = 0.02

[material]
E = 2e4
density = 5000

)";

fs::path writeScene(const std::string& text) {
    const fs::path dir = test::scratchDir();
    fs::create_directories(dir);
    const fs::path file = dir / "scene.toml";
    std::ofstream(file) << kSheet << text;
    return file;
}

std::string refusal(const std::string& text) { return test::refusalOf(writeScene(text)); }

void expectRefused(const std::string& text, int line, const std::string& fragment) {
    test::expectRefusedAt(refusal(text), line, fragment);
}

}  // namespace

TEST(ContactKeys, AGoodColliderAndContactTableLoad) {
    const Scene s = loadScene(writeScene(R"([contact]
self = true
thickness = 0.004
ground_friction = 0.2

[[collider]]
shape = "box"
size = [0.2, 0.1, 0.05]
rotation = [0.0, 0.0, 90.0]
color = [0.9, 0.1, 0.1]

[[collider.keyframe]]
time = 0.0

[[collider.keyframe]]
time = 1.0
position = [0.0, 0.0, 0.3]
)"));
    const sim::ContactParams& c = s.sim.contact;
    EXPECT_TRUE(c.self.enabled);
    EXPECT_DOUBLE_EQ(c.self.thickness, 0.004);
    EXPECT_TRUE(c.ground.enabled) << "the drawn ground stops the sheet";
    EXPECT_DOUBLE_EQ(c.ground.friction.kinetic, 0.2);
    EXPECT_DOUBLE_EQ(c.ground.friction.stiction, 0.2) << "static defaults to kinetic";
    ASSERT_EQ(c.colliders.size(), 1u);
    const sim::ColliderParams& box = c.colliders[0];
    EXPECT_EQ(box.shape, sim::ColliderShape::Box);
    EXPECT_LT((box.rotation * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
    EXPECT_LT((box.poseAt(0.5).position - Eigen::Vector3d(0, 0, 0.15)).norm(), 1e-12);
    ASSERT_EQ(s.render.colliderLooks.size(), 1u);
    EXPECT_DOUBLE_EQ(s.render.colliderLooks[0].color.x(), 0.9);
    EXPECT_FALSE(loadScene(writeScene("[render]\nground = false\n")).sim.contact.ground.enabled);
}

TEST(ContactKeys, EveryMistakeIsRefusedAtItsLocation) {
    // Lines count from the scene's first line; kSheet takes 8.
    expectRefused("[[collider]]\nradius = 0.1\n", 9, "shape");
    expectRefused("[[collider]]\nshape = \"sphere\"\n", 9, "radius");
    expectRefused("[[collider]]\nshape = \"sphere\"\nradius = 0.1\nsize = [1, 1, 1]\n", 12,
                  "no size for shape = \"sphere\"");
    expectRefused("[[collider]]\nshape = \"box\"\nsize = [1, -1, 1]\n", 11, "size");
    expectRefused("[[collider]]\nshape = \"cone\"\n", 10, "\"capsule\"");
    expectRefused("[[collider]]\nshape = \"capsule\"\nradius = 0.1\n", 9, "length");
    expectRefused(
        "[[collider]]\nshape = \"sphere\"\nradius = 0.1\nfriction = 0.5\n"
        "static_friction = 0.2\n",
        13, "at least the kinetic");
    expectRefused("[contact]\nfriction = -1\n", 10, "friction");
    expectRefused("[contact]\nthickness = 0\n", 10, "thickness");
    expectRefused("[contact]\nthickness = 0.03\n", 10, "below the horizon R = 0.03");
    expectRefused(
        "[[collider]]\nshape = \"sphere\"\nradius = 0.1\n[[collider.keyframe]]\n"
        "time = 1.0\n[[collider.keyframe]]\ntime = 0.5\n",
        15, "increase");
    expectRefused(
        "[[collider]]\nshape = \"sphere\"\nradius = 0.1\nvelocity = [0, 0, 1]\n"
        "[[collider.keyframe]]\ntime = 1.0\n",
        12, "keyframed");
    expectRefused("[[collider]]\nshape = \"mesh\"\nfile = \"no_such_mesh.obj\"\n", 11,
                  "no_such_mesh.obj");
    expectRefused("[[collider]]\nshape = \"mesh\"\n", 9, "file");
}

TEST(ContactKeys, AnOpenMeshIsRefusedWithItsOpenEdgeCount) {
    const fs::path dir = test::scratchDir();
    fs::create_directories(dir);
    std::ofstream(dir / "quad.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    expectRefused("[[collider]]\nshape = \"mesh\"\nfile = \"quad.obj\"\n", 11, "4 open edges");
    const Scene s = loadScene(writeScene("[[collider]]\nshape = \"mesh\"\nfile = \"" REND_SOURCE_DIR
                                         "/tests/data/collider_cube.obj\"\nscale = 0.5\n"));
    ASSERT_TRUE(s.sim.contact.colliders[0].mesh);
    EXPECT_EQ(s.sim.contact.colliders[0].mesh->triangles.size(), 12u);
    EXPECT_DOUBLE_EQ(s.sim.contact.colliders[0].mesh->vertices[0].cwiseAbs().maxCoeff(), 0.25);
}
