// The scene loader: the canonical scene, every kind of malformed input (each error must name
// its location, key, expectation and finding), --set overrides and material presets.

#include "app/Scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "app/SceneError.h"

using namespace rend;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = REND_SOURCE_DIR;
const fs::path kScenes = kSource / "tests" / "scenes";
const fs::path kStretch = kSource / "scenes" / "stretch.toml";

/// Every test starts with REND_ASSETS unset (the source tree's assets) and gets back whatever
/// the environment had, so tests that point it at tests/scenes/assets cannot leak.
class SceneTest : public ::testing::Test {
protected:
    void SetUp() override {
        if (const char* v = std::getenv("REND_ASSETS")) saved_ = v;
        unsetenv("REND_ASSETS");
    }
    void TearDown() override {
        if (saved_) {
            setenv("REND_ASSETS", saved_->c_str(), 1);
        } else {
            unsetenv("REND_ASSETS");
        }
    }
    static void useTestPresets() { setenv("REND_ASSETS", (kScenes / "assets").c_str(), 1); }

    /// Writes `text` as NAME in a fresh directory of this test.
    fs::path writeScene(const std::string& name, const std::string& text) {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        const fs::path dir = fs::temp_directory_path() / "rend_scene_test" / info->name();
        fs::create_directories(dir);
        std::ofstream(dir / name) << text;
        return dir / name;
    }

private:
    std::optional<std::string> saved_;
};

/// The message of the SceneError that loading throws, or a note that none was thrown.
std::string errorOf(const fs::path& file, const std::vector<std::string>& overrides = {}) {
    try {
        loadScene(file, overrides);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "<no SceneError>";
}

/// "LINE:COL" of the value on the first line that starts with `prefix`, found by reading the
/// file so that retuning the example scene does not break the test.
std::string valueLocation(const fs::path& file, const std::string& prefix) {
    std::ifstream in(file);
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        if (line.rfind(prefix, 0) == 0) {
            return std::to_string(number) + ":" + std::to_string(prefix.size() + 1);
        }
    }
    return "<" + prefix + " not found>";
}

constexpr const char* kMinimal = R"(
[sheet]
size = [1.0, 0.5]
dx = 0.05

[material]
E = 1e5
density = 1000
)";

}  // namespace

// ---- the canonical scene ---------------------------------------------------------------------

TEST_F(SceneTest, StretchSceneLoadsWithPresetAndEdgeBoundaries) {
    const Scene s = loadScene(kStretch);
    EXPECT_EQ(s.file, kStretch);
    EXPECT_EQ(s.sim.sheet.outline, sim::Outline::Rectangle);
    EXPECT_EQ(s.sim.sheet.size, Eigen::Vector2d(2.0, 2.0));
    EXPECT_DOUBLE_EQ(s.sim.sheet.dx, 0.02);
    EXPECT_EQ(s.sim.sheet.lattice, sim::LatticeKind::Hexagonal);
    EXPECT_DOUBLE_EQ(s.sim.sheet.horizonFactor, 1.5);
    EXPECT_DOUBLE_EQ(s.sim.sheet.thickness, 0.001);
    EXPECT_DOUBLE_EQ(s.sim.sheet.perturbationAmplitude, 1e-4);
    EXPECT_EQ(s.sim.sheet.perturbationSeed, 7u);

    EXPECT_EQ(s.sim.material.name, "stretch_sheet");
    EXPECT_DOUBLE_EQ(s.sim.material.youngsModulus, 2e4) << "from the preset";
    EXPECT_DOUBLE_EQ(s.sim.material.density, 5000.0);
    EXPECT_DOUBLE_EQ(s.sim.material.poissonRatio, 0.3);
    EXPECT_EQ(s.sim.material.micromodulus, sim::MicromodulusMode::Calibrated);

    ASSERT_EQ(s.sim.boundaries.size(), 2u);
    const double strip = 0.02 * (1.0 + 1e-9);
    const sim::BoundaryCondition& left = s.sim.boundaries[0];
    EXPECT_EQ(left.kind, sim::BoundaryKind::Velocity);
    EXPECT_EQ(left.velocity, Eigen::Vector3d(-0.15, 0, 0));
    EXPECT_DOUBLE_EQ(left.rampTime, 0.5);
    EXPECT_DOUBLE_EQ(left.region.max.x(), -1.0 + strip);
    EXPECT_TRUE(left.region.contains({-1.0, 0.3, 0}));
    EXPECT_TRUE(left.region.contains({-0.98, -1.0, 0})) << "a full dx deep, corners included";
    EXPECT_FALSE(left.region.contains({-0.97, 0, 0}));
    const sim::BoundaryCondition& right = s.sim.boundaries[1];
    EXPECT_EQ(right.velocity, Eigen::Vector3d(0.15, 0, 0));
    EXPECT_DOUBLE_EQ(right.region.min.x(), 1.0 - strip);
    EXPECT_TRUE(right.region.contains({1.0, 1.0, 0}));
    EXPECT_FALSE(right.region.contains({0.97, 0, 0}));

    ASSERT_TRUE(s.sim.time.dt.has_value());
    EXPECT_DOUBLE_EQ(*s.sim.time.dt, 1e-4);
    EXPECT_EQ(s.frameCount(), 120);
    EXPECT_EQ(s.dtLocation, kStretch.string() + ":" + valueLocation(kStretch, "dt = "));

    EXPECT_EQ(s.renderer, RendererKind::Osmesa);
    EXPECT_EQ(s.render.width, 960);
    EXPECT_EQ(s.render.height, 540);
    EXPECT_EQ(s.render.colorBy, render::ColorBy::Strain);
    ASSERT_TRUE(s.render.colorRange.has_value());
    EXPECT_EQ(*s.render.colorRange, (std::array<double, 2>{0.0, 0.6}));
    EXPECT_DOUBLE_EQ(s.render.groundHeight, -1.0) << "half the sheet's extent below it";
    EXPECT_TRUE(s.writeStats);
}

TEST_F(SceneTest, EveryExampleSceneLoads) {
    int count = 0;
    for (const auto& entry : fs::directory_iterator(kSource / "scenes")) {
        if (entry.path().extension() != ".toml") continue;
        EXPECT_EQ(errorOf(entry.path()), "<no SceneError>") << entry.path();
        ++count;
    }
    EXPECT_GE(count, 1);
}

TEST_F(SceneTest, ResolvedJsonHasThePresetMergedIn) {
    const Scene s = loadScene(kStretch, {"material.E=3e4"});
    EXPECT_NE(s.resolvedJson.find("\"density\" : 5000"), std::string::npos) << s.resolvedJson;
    EXPECT_NE(s.resolvedJson.find("\"E\" : 30000"), std::string::npos) << s.resolvedJson;
    EXPECT_NE(s.resolvedJson.find("\"preset\" : \"stretch_sheet\""), std::string::npos);
    EXPECT_NE(s.resolvedJson.find("\"boundary\" : ["), std::string::npos);
}

TEST_F(SceneTest, DefaultsFrameTheSheetAndUseAutoDt) {
    const Scene s = loadScene(writeScene("minimal.toml", kMinimal));
    EXPECT_FALSE(s.sim.time.dt.has_value());
    EXPECT_EQ(s.dtLocation, writeScene("minimal.toml", kMinimal).string() + ":1:1");
    EXPECT_EQ(s.frameCount(), 120) << "5 s at 24 fps";
    EXPECT_EQ(s.sim.material.name, "custom");
    EXPECT_TRUE(s.sim.boundaries.empty());
    const double extent = 1.0;  // the larger side
    EXPECT_EQ(s.render.camera.lookAt, Eigen::Vector3d::Zero());
    EXPECT_TRUE(s.render.camera.position.isApprox(extent * Eigen::Vector3d(0, -1.6, 1.25)));
    EXPECT_EQ(s.render.camera.up, Eigen::Vector3d(0, 0, 1));
    EXPECT_DOUBLE_EQ(s.render.camera.fovYDegrees, 40.0);
    EXPECT_DOUBLE_EQ(s.render.groundHeight, -0.5);
}

TEST_F(SceneTest, DiscWithPinnedBoxAndTopEdge) {
    const fs::path file = writeScene("disc.toml", R"(
[sheet]
shape = "disc"
radius = 0.5
center = [1.0, 2.0, 0.3]
lattice = "square"
dx = 0.05

[material]
E = 1e5
density = 1000
micromodulus = "paper"

[[boundary]]
type = "pinned"
box = { min = [0.9, 1.9], max = [1.1, 2.1] }

[[boundary]]
type = "velocity"
edge = "top"
depth = 2
velocity = [0, 0, 1]

[time]
dt = "auto"
duration = 1
fps = 30

[render]
renderer = "none"
supersample = 1
)");
    const Scene s = loadScene(file);
    EXPECT_EQ(s.sim.sheet.outline, sim::Outline::Disc);
    EXPECT_EQ(s.sim.sheet.lattice, sim::LatticeKind::Square);
    EXPECT_EQ(s.sim.material.micromodulus, sim::MicromodulusMode::Paper);
    ASSERT_EQ(s.sim.boundaries.size(), 2u);
    EXPECT_EQ(s.sim.boundaries[0].kind, sim::BoundaryKind::Pinned);
    EXPECT_EQ(s.sim.boundaries[0].region.min, Eigen::Vector2d(0.9, 1.9));
    EXPECT_EQ(s.sim.boundaries[0].region.max, Eigen::Vector2d(1.1, 2.1));
    EXPECT_NEAR(s.sim.boundaries[1].region.min.y(), 2.5 - 0.1, 1e-9);
    EXPECT_TRUE(std::isinf(s.sim.boundaries[1].region.max.y()));
    EXPECT_FALSE(s.sim.time.dt.has_value());
    EXPECT_EQ(s.frameCount(), 30);
    EXPECT_EQ(s.renderer, RendererKind::None);
    EXPECT_EQ(s.render.camera.lookAt, Eigen::Vector3d(1.0, 2.0, 0.3));
    EXPECT_DOUBLE_EQ(s.render.groundHeight, 0.3 - 0.5);
}

// ---- malformed scenes ------------------------------------------------------------------------

struct BadScene {
    const char* file;
    const char* location;  ///< "LINE:COL"
    std::vector<const char*> fragments;
};

void PrintTo(const BadScene& bad, std::ostream* os) { *os << bad.file; }

class BadSceneTest : public SceneTest, public ::testing::WithParamInterface<BadScene> {};

TEST_P(BadSceneTest, NamesLocationKeyExpectationAndFinding) {
    const BadScene& bad = GetParam();
    const fs::path file = kScenes / bad.file;
    ASSERT_TRUE(fs::exists(file)) << file;
    const std::string message = errorOf(file);
    const std::string prefix = file.string() + ":" + bad.location + ": error: ";
    EXPECT_EQ(message.rfind(prefix, 0), 0u) << message;
    for (const char* fragment : bad.fragments) {
        EXPECT_NE(message.find(fragment), std::string::npos) << fragment << "\n in: " << message;
    }
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line";
}

INSTANTIATE_TEST_SUITE_P(
    Files, BadSceneTest,
    ::testing::Values(
        BadScene{"bad_unknown_key.toml",
                 "6:2",
                 {"unknown key 'materal' in the top-level table; expected one of: sheet, material, "
                  "boundary, forces, time, camera, light, render, output. Did you mean "
                  "'material'?"}},
        BadScene{"bad_sub_key.toml",
                 "13:1",
                 {"unknown key 'velocty' in [[boundary]] entry 0", "Did you mean 'velocity'?"}},
        BadScene{"bad_wrong_type.toml",
                 "7:5",
                 {"material.E: expected a number > 0 (Young's modulus in Pa)",
                  "found a string \"abc\""}},
        BadScene{"bad_out_of_range.toml",
                 "8:5",
                 {"material.E: expected a number > 0 (Young's modulus in Pa), found -20000. Use "
                  "e.g. E = 2e4."}},
        BadScene{"bad_missing_dx.toml",
                 "2:1",
                 {"sheet.dx is missing: expected the particle spacing in metres (> 0). Add e.g. "
                  "dx = 0.02 under [sheet]."}},
        BadScene{"bad_missing_sheet.toml", "1:1", {"sheet.dx is missing"}},
        BadScene{"bad_enum.toml",
                 "5:11",
                 {"sheet.lattice: expected one of \"hexagonal\", \"square\", found \"hex\""}},
        BadScene{"bad_syntax.toml", "4:1", {"TOML syntax: ", "array"}},
        BadScene{"bad_preset.toml",
                 "7:10",
                 {"material.preset: expected one of ", "\"stretch_sheet\"",
                  "found \"stretch_shet\". Did you mean \"stretch_sheet\"?"}},
        BadScene{"bad_edge_and_box.toml",
                 "13:7",
                 {"boundary.0.box: expected either edge or box, not both"}},
        BadScene{"bad_vec3_length.toml",
                 "5:10",
                 {"sheet.center: expected an array of 3 numbers", "found an array of 2 elements"}},
        BadScene{"bad_float_for_int.toml",
                 "11:9",
                 {"render.width: expected an integer in [16, 8192]", "found 960.5"}},
        BadScene{"bad_pinned_velocity.toml",
                 "17:12",
                 {"boundary.1.velocity: expected no velocity for type = \"pinned\""}},
        BadScene{"bad_too_many_particles.toml",
                 "4:6",
                 {"sheet.dx: expected a spacing of at least 0.0045 m", "at most 5e6 particles"}}));

TEST_F(SceneTest, MissingFileIsReportedWithItsPath) {
    const fs::path file = kScenes / "no_such_scene.toml";
    EXPECT_EQ(errorOf(file),
              file.string() + ": error: cannot open scene file (No such file or directory)");
}

TEST_F(SceneTest, ShapeSpecificKeysAreRejectedForTheOtherShape) {
    const fs::path file = writeScene("radius.toml", kMinimal);
    EXPECT_NE(errorOf(file, {"sheet.radius=1"})
                  .find("sheet.radius: expected no radius for shape = "
                        "\"rectangle\""),
              std::string::npos);
    EXPECT_NE(errorOf(file, {"sheet.shape=disc"}).find("sheet.radius is missing"),
              std::string::npos);
}

TEST_F(SceneTest, SpacingMustLeaveAtLeastFourParticlesAcross) {
    const std::string message = errorOf(kStretch, {"sheet.dx=0.9"});
    EXPECT_NE(message.find("sheet.dx: expected a spacing of at most 0.66 m"), std::string::npos)
        << message;
}

// ---- --set -----------------------------------------------------------------------------------

TEST_F(SceneTest, SetOverridesValues) {
    const Scene s = loadScene(kStretch, {"material.E=3e4", "camera.fov=55", "sheet.lattice=square",
                                         "render.color_by=\"speed\"", "output.stats=false"});
    EXPECT_DOUBLE_EQ(s.sim.material.youngsModulus, 3e4);
    EXPECT_DOUBLE_EQ(s.sim.material.density, 5000.0) << "the rest of the preset stays";
    EXPECT_DOUBLE_EQ(s.render.camera.fovYDegrees, 55.0);
    EXPECT_EQ(s.sim.sheet.lattice, sim::LatticeKind::Square) << "bare words become strings";
    EXPECT_EQ(s.render.colorBy, render::ColorBy::Speed);
    EXPECT_FALSE(s.writeStats);
}

TEST_F(SceneTest, SetAutoDtClearsTheStepAndPointsAtTheOverride) {
    const Scene s = loadScene(kStretch, {"time.dt=auto"});
    EXPECT_FALSE(s.sim.time.dt.has_value());
    EXPECT_EQ(s.dtLocation, "--set 'time.dt=auto'");
}

TEST_F(SceneTest, SetCreatesMissingTables) {
    const Scene s = loadScene(writeScene("minimal.toml", kMinimal), {"forces.gravity=[0,0,-9.81]"});
    EXPECT_EQ(s.sim.gravity, Eigen::Vector3d(0, 0, -9.81));
}

TEST_F(SceneTest, SetIndexesArraysOfTablesFromZero) {
    const Scene s = loadScene(kStretch, {"boundary.1.velocity=[0,0,1]", "boundary.0.ramp=2"});
    EXPECT_EQ(s.sim.boundaries[1].velocity, Eigen::Vector3d(0, 0, 1));
    EXPECT_DOUBLE_EQ(s.sim.boundaries[1].rampTime, 0.5);
    EXPECT_DOUBLE_EQ(s.sim.boundaries[0].rampTime, 2.0);
    EXPECT_EQ(s.sim.boundaries[0].velocity, Eigen::Vector3d(-0.15, 0, 0));
}

TEST_F(SceneTest, SetValuesAreCheckedLikeFileValues) {
    EXPECT_EQ(errorOf(kStretch, {"material.E=-5"}),
              "--set 'material.E=-5': error: material.E: expected a number > 0 (Young's modulus "
              "in Pa), found -5. Use e.g. E = 2e4.");
    EXPECT_EQ(errorOf(kStretch, {"material.E=abc"})
                  .rfind("--set 'material.E=abc': error: "
                         "material.E: expected a number > 0",
                         0),
              0u);
    const std::string pinned =
        errorOf(kStretch, {"boundary.0.type=pinned", "boundary.0.velocity=[0,0,0]"});
    EXPECT_EQ(pinned.rfind("--set 'boundary.0.velocity=[0,0,0]': error: boundary.0.velocity", 0),
              0u)
        << pinned;
}

TEST_F(SceneTest, SetOfAnUnknownKeyIsRejected) {
    EXPECT_EQ(errorOf(kStretch, {"time.dtt=1e-4"}),
              "--set 'time.dtt=1e-4': error: unknown key 'dtt' in [time]; expected one of: dt, "
              "safety, duration, fps, allow_unstable. Did you mean 'dt'?");
    EXPECT_NE(errorOf(kStretch, {"rendr.width=5"}).find("unknown key 'rendr'"), std::string::npos);
}

TEST_F(SceneTest, MalformedSetIsRejected) {
    EXPECT_EQ(errorOf(kStretch, {"material.E"}),
              "--set 'material.E': error: expected KEY=VALUE, e.g. --set material.E=3e4, found no "
              "'='.");
    EXPECT_NE(errorOf(kStretch, {"=3"}).find("found an empty key"), std::string::npos);
    EXPECT_NE(errorOf(kStretch, {"a..b=3"}).find("--set 'a..b=3': error: expected a dotted key"),
              std::string::npos);
    EXPECT_EQ(errorOf(kStretch, {"boundary.2.type=pinned"}),
              "--set 'boundary.2.type=pinned': error: boundary: expected an index in 0..1 "
              "(boundary has 2 entries), found '2'.");
    EXPECT_EQ(errorOf(kStretch, {"sheet.dx.x=1"})
                  .rfind("--set 'sheet.dx.x=1': error: sheet.dx: "
                         "expected a table",
                         0),
              0u);
    EXPECT_NE(errorOf(kStretch, {"sheet.size.0=1"}).find("arrays are set whole"),
              std::string::npos);
}

// ---- presets ---------------------------------------------------------------------------------

TEST_F(SceneTest, PresetValuesKeepThePresetFilesLocation) {
    useTestPresets();
    const fs::path preset = kScenes / "assets" / "materials" / "negative_modulus.toml";
    const std::string message = errorOf(kScenes / "preset_bad_modulus.toml");
    EXPECT_EQ(message, preset.string() +
                           ":3:5: error: material.E: expected a number > 0 (Young's modulus in "
                           "Pa), found -5. Use e.g. E = 2e4.");
}

TEST_F(SceneTest, SceneKeysOverrideThePreset) {
    useTestPresets();
    const fs::path file = kScenes / "preset_override.toml";
    const Scene s = loadScene(file);
    EXPECT_DOUBLE_EQ(s.sim.material.youngsModulus, 3e4);
    EXPECT_DOUBLE_EQ(s.sim.material.density, 1200.0) << "from the preset";
    EXPECT_EQ(s.sim.material.name, "negative_modulus");
    // The overriding key reports the scene's location, --set its own.
    EXPECT_EQ(errorOf(file, {"material.poisson=0.7"}).rfind("--set 'material.poisson=0.7'", 0), 0u);
    const std::string message = errorOf(writeScene("override.toml", R"(
[sheet]
size = [1.0, 1.0]
dx = 0.05

[material]
preset = "negative_modulus"
E = 0
)"));
    EXPECT_NE(message.find("override.toml:8:5: error: material.E:"), std::string::npos) << message;
}

TEST_F(SceneTest, UnknownPresetViaSetListsTheAvailableOnes) {
    const std::string message = errorOf(kStretch, {"material.preset=rubber"});
    EXPECT_EQ(message.rfind("--set 'material.preset=rubber': error: material.preset: expected "
                            "one of ",
                            0),
              0u)
        << message;
    EXPECT_NE(message.find("\"stretch_sheet\""), std::string::npos) << message;
    EXPECT_NE(message.find("(the presets in " + (kSource / "assets" / "materials").string() +
                           "), found \"rubber\"."),
              std::string::npos)
        << message;
}
