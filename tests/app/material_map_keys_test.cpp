// [[material.map]] as a hostile user writes it: every mistake refused at its file:line:column
// with what was expected; good maps load into the simulation's parameters.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/Scene.h"
#include "app/SceneError.h"
#include "render/Image.h"
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
fracture_energy = 1.0

)";  // the map text starts on line 10

fs::path writeScene(const std::string& text) {
    const fs::path file = test::scratchDir() / "scene.toml";
    std::ofstream(file) << kSheet << text;
    return file;
}

std::string refusal(const std::string& text, const std::vector<std::string>& sets = {}) {
    return test::refusalOf(writeScene(text), sets);
}

void expectRefused(const std::string& text, int line, const std::string& fragment) {
    test::expectRefusedAt(refusal(text), line, fragment);
}

}  // namespace

TEST(MaterialMapKeys, EveryShapeLoads) {
    render::Image grey{2, 1, {0, 0, 0, 255, 255, 255}};
    render::writePngAtomic(grey, test::scratchDir() / "fibres.png");
    const Scene s = loadScene(writeScene(R"([[material.map]]
property = "E"
shape = "box"
min = [-0.2, -0.2]
max = [0.0, 0.2]
factor = 0.5

[[material.map]]
property = "density"
shape = "disc"
center = [0.1, 0.1]
radius = 0.05
factor = 2.0

[[material.map]]
property = "fracture_energy"
shape = "noise"
scale = [0.2, 0.02]
amplitude = 0.6
octaves = 3
seed = 9

[[material.map]]
property = "E"
shape = "image"
file = "fibres.png"
low = 0.8
high = 1.2
)"));
    const auto& maps = s.sim.materialMaps;
    ASSERT_EQ(maps.size(), 4u);
    EXPECT_EQ(maps[0].shape, sim::MapShape::Box);
    EXPECT_EQ(maps[0].factor, 0.5);
    EXPECT_EQ(maps[1].property, sim::MappedProperty::Density);
    EXPECT_EQ(maps[1].radius, 0.05);
    EXPECT_EQ(maps[2].property, sim::MappedProperty::FractureEnergy);
    EXPECT_EQ(maps[2].scale, Eigen::Vector2d(0.2, 0.02));
    EXPECT_EQ(maps[2].octaves, 3);
    EXPECT_EQ(maps[2].seed, 9u);
    EXPECT_EQ(maps[3].image.width, 2);
    EXPECT_FLOAT_EQ(maps[3].image.values[1], 1.0f);
    EXPECT_EQ(maps[3].high, 1.2);
}

TEST(MaterialMapKeys, EveryMistakeIsRefusedAtItsLocation) {
    expectRefused("[[material.map]]\nshape = \"box\"\n", 10, "property is missing");
    expectRefused("[[material.map]]\nproperty = \"stiffness\"\nshape = \"box\"\n", 11,
                  "expected one of \"E\", \"fracture_energy\", \"density\", \"yield_strain\", "
                  "\"softening\", \"power_ratio\", \"power_exponent\", found \"stiffness\"");
    expectRefused(
        "[[material.map]]\nproperty = \"E\"\nshape = \"disc\"\ncenter = [0.0, 0.0]\n"
        "factor = 2.0\n",
        10, "radius is missing");
    expectRefused(
        "[[material.map]]\nproperty = \"E\"\nshape = \"box\"\nmin = [0.0, 0.0]\n"
        "max = [0.1, 0.1]\nfactor = 2.0\nradius = 0.1\n",
        16, "no radius for shape = \"box\"");
    expectRefused("[[material.map]]\nproperty = \"E\"\nshape = \"noise\"\namplitude = 1.5\n", 13,
                  "amplitude");
    expectRefused("[[material.map]]\nproperty = \"E\"\nshape = \"noise\"\nscale = [1e-300, 0.1]\n",
                  13, "in [1e-06, 10000]");  // the noise's lattice index must stay an integer
    expectRefused("[[material.map]]\nproperty = \"E\"\nshape = \"image\"\nfile = \"none.png\"\n",
                  13, "a PNG file of at most 256 MiB");
    expectRefused("[[material.map]]\nproperty = \"E\"\nshape = \"image\"\nfile = \".\"\n", 13,
                  "a PNG file of at most 256 MiB");  // a folder, never read
    std::ofstream(test::scratchDir() / "text.png") << "not a png";
    expectRefused("[[material.map]]\nproperty = \"E\"\nshape = \"image\"\nfile = \"text.png\"\n",
                  13, "expected a PNG image");
    expectRefused(
        "[[material.map]]\nproperty = \"E\"\nshape = \"box\"\nmin = [0.0, 0.0]\n"
        "max = [0.1, 0.1]\nfactor = 0.0\n",
        15, "factor");
}

TEST(MaterialMapKeys, AFractureEnergyMapNeedsABreakingMaterialAndEverySolverTakesMaps) {
    const std::string message = refusal(
        "[[material.map]]\nproperty = \"fracture_energy\"\nshape = \"disc\"\n"
        "center = [0.0, 0.0]\nradius = 0.1\nfactor = 2.0\n",
        {"material.fracture_energy=\"none\""});
    EXPECT_NE(message.find("a material that breaks"), std::string::npos) << message;
    for (const char* solver : {"peridynamic", "fem_cst", "mass_spring_vg", "mass_spring_tp", "sph"})
        EXPECT_EQ(refusal("[[material.map]]\nproperty = \"E\"\nshape = \"disc\"\n"
                          "center = [0.0, 0.0]\nradius = 0.1\nfactor = 2.0\n",
                          {std::string("solver=") + solver}),
                  "")
            << "every solver takes an E map: " << solver;
    const std::string yield =
        "[[material.map]]\nproperty = \"yield_strain\"\nshape = \"disc\"\n"
        "center = [0.0, 0.0]\nradius = 0.1\nfactor = 0.5\n";
    const std::string linear = refusal(yield);
    EXPECT_NE(linear.find("law = \"elastoplastic\""), std::string::npos) << linear;
    EXPECT_EQ(refusal(yield, {"material.law=elastoplastic"}), "");
    const std::string sph = refusal(yield, {"material.law=elastoplastic", "solver=sph"});
    EXPECT_NE(sph.find("a material map of the bond law (yield_strain, softening, power_ratio, "
                       "power_exponent)"),
              std::string::npos)
        << sph;
    EXPECT_EQ(refusal(yield, {"material.law=elastoplastic", "solver=mass_spring_vg"}), "");
}

// The power law's maps: they need the power law, a c*/c to scale, and an exponent kept in the
// schema's (1, 100] by all the exponent maps together (their factors multiply).
TEST(MaterialMapKeys, APowerLawMapNeedsThePowerLawAndKeepsItsExponentInRange) {
    auto map = [](const char* property, const char* factor) {
        return std::string("[[material.map]]\nproperty = \"") + property +
               "\"\nshape = \"disc\"\ncenter = [0.0, 0.0]\nradius = 0.1\nfactor = " + factor + "\n";
    };
    const std::string ratio = map("power_ratio", "2.0");
    expectRefused(ratio, 11, "expected a material with law = \"power_law\"");
    const std::string zero = refusal(ratio, {"material.law=power_law"});
    EXPECT_NE(zero.find("power_ratio below 0"), std::string::npos) << zero;
    EXPECT_EQ(refusal(ratio, {"material.law=power_law", "material.power_ratio=-0.1"}), "");
    const std::vector<std::string> power = {"material.law=power_law"};
    EXPECT_EQ(refusal(map("power_exponent", "1.5"), power), "");
    // n = 4 by default: 0.2 gives 0.8, and two maps of 6 give 144.
    const std::string low = refusal(map("power_exponent", "0.2"), power);
    EXPECT_NE(low.find("scene.toml:15:10: error: material.map.0.factor: expected factors that "
                       "keep power_exponent in (1, 100], found n from 0.8 to 4"),
              std::string::npos)
        << low;
    const std::string twice =
        refusal(map("power_exponent", "6.0") + "\n" + map("power_exponent", "6.0"), power);
    EXPECT_NE(twice.find("scene.toml:22:10: error: material.map.1.factor"), std::string::npos)
        << twice;
    EXPECT_NE(twice.find("found n from 4 to 144"), std::string::npos) << twice;
    const std::string sph =
        refusal(map("power_exponent", "1.5"), {"material.law=power_law", "solver=sph"});
    EXPECT_NE(sph.find("a material map of the bond law"), std::string::npos) << sph;
}
