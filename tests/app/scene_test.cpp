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
#include "render/Look.h"

using namespace rend;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = REND_SOURCE_DIR;
const fs::path kScenes = kSource / "tests" / "scenes";
const fs::path kStretch = kSource / "scenes" / "stretch.toml";
const fs::path kSphere = kSource / "scenes" / "pressurised_sphere.toml";

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

    EXPECT_FALSE(s.sim.time.dt.has_value()) << "shipped scenes take the adaptive step";
    EXPECT_TRUE(s.sim.time.adaptive());
    EXPECT_EQ(s.frameCount(), 120);
    const std::string table = valueLocation(kStretch, "[time]");
    EXPECT_EQ(s.locationOf("time.dt"),
              kStretch.string() + ":" + table.substr(0, table.find(':')) + ":1")
        << "absent: its table";

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

TEST_F(SceneTest, DefaultsFrameTheSheetAndUseTheAdaptiveDt) {
    const Scene s = loadScene(writeScene("minimal.toml", kMinimal));
    EXPECT_FALSE(s.sim.time.dt.has_value());
    EXPECT_TRUE(s.sim.time.adaptive());
    EXPECT_EQ(s.locationOf("time.dt"), writeScene("minimal.toml", kMinimal).string() + ":1:1");
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
depth = 0.1
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
                 {"unknown key 'materal' in the top-level table; expected one of: solver, sheet, "
                  "material, boundary, notch, diffusion, forces, mpm, remesh, contact, collider, "
                  "time, camera, "
                  "light, render, output. Did "
                  "you mean 'material'?"}},
        BadScene{"bad_sub_key.toml",
                 "13:1",
                 {"unknown key 'velocty' in [[boundary]] entry 0", "Did you mean 'velocity'?"}},
        BadScene{"bad_wrong_type.toml",
                 "7:5",
                 {"material.E: expected a number in [0.001, 1e+13] (Young's modulus in Pa)",
                  "found a string \"abc\""}},
        BadScene{"bad_out_of_range.toml",
                 "8:5",
                 {"material.E: expected a number in [0.001, 1e+13] (Young's modulus in Pa), found "
                  "-20000. Use e.g. E = 2e4."}},
        BadScene{"bad_missing_dx.toml",
                 "2:1",
                 {"sheet.dx is missing: expected the particle spacing in metres at quality = "
                  "\"preview\" (in [1e-06, 1000]). Add e.g. dx = 0.02 under [sheet]."}},
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
                 {"sheet.dx: expected a spacing that fits the memory limit of 8 GB",
                  "dx >= 0.0032 m at horizon = 1.5", "about 1.2e+08 particles", "about 79 GB"}},
        BadScene{"bad_export.toml",
                 "11:10",
                 {"output.export: expected an array of format names, one of \"ply\", \"obj\", "
                  "\"glb\", \"vdb\"",
                  "found a string \"stl\""}},
        BadScene{"bad_surface.toml",
                 "11:11",
                 {"render.surface: expected one of \"lattice\", \"splat\", \"vdb\", "
                  "\"particle_level_set\", found \"splats\"",
                  "Did you mean \"splat\"?"}},
        BadScene{"bad_law.toml",
                 "9:7",
                 {"material.law: expected one of \"linear\", \"power_law\", \"elastoplastic\", "
                  "found \"power-law\". Did you mean \"power_law\"?"}},
        BadScene{"bad_law_constant_without_law.toml",
                 "9:15",
                 {"material.power_ratio: expected no power_ratio without law (it belongs to law = "
                  "\"power_law\"), found the number -0.1. Add law = \"power_law\", or remove "
                  "power_ratio."}},
        BadScene{"bad_fracture_energy.toml",
                 "9:19",
                 {"material.fracture_energy: expected a number in (0, 1e+09] (the fracture energy "
                  "G_f in J/m^2), found -11.3. Use e.g. fracture_energy = 11.3."}},
        BadScene{"bad_notch_one_point.toml",
                 "14:10",
                 {"notch.1.points: expected an array of at least 2 points [x, y] (the notch "
                  "polyline in rest coordinates, metres; bonds crossing it break at set-up), found "
                  "an array of 1 element. Use e.g. "
                  "points = [[-1.0, 0.0], [-0.6, 0.0]]."}},
        BadScene{"bad_notch_point_3d.toml",
                 "11:24",
                 {"notch.0.points.1: expected a point [x, y] of 2 numbers",
                  "found an array of 3 "
                  "elements"}},
        BadScene{"bad_scatter_count.toml",
                 "15:9",
                 {"diffusion.scatter.0.count: expected an integer in [1, 10000] (how many spots "
                  "or droplets), found 2.5. Use e.g. count = 20."}},
        BadScene{"bad_spot_missing_radius.toml",
                 "10:1",
                 {"diffusion.spot.0.radius is missing: expected the source's radius in metres (in "
                  "(0, 10000]). Add e.g. radius = 0.05 under [[diffusion.spot]] entry 0."}},
        BadScene{"bad_spot_off_sheet.toml",
                 "11:20",
                 {"diffusion.spot.0.center: expected a centre within radius = 0.5 m of the sheet",
                  "found [2, 0], 1.5 m away"}},
        BadScene{"bad_diffusion_edge.toml",
                 "16:7",
                 {"diffusion.edge.1.box: expected either edge or box, not both"}}));

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

TEST_F(SceneTest, ColorByThetaAndDamage) {
    EXPECT_EQ(loadScene(kStretch, {"render.color_by=theta"}).render.colorBy,
              render::ColorBy::Theta);
    EXPECT_EQ(loadScene(kStretch, {"render.color_by=damage"}).render.colorBy,
              render::ColorBy::Damage);
    EXPECT_NE(errorOf(kStretch, {"render.color_by=damag"}).find("Did you mean \"damage\"?"),
              std::string::npos);
}

TEST_F(SceneTest, ALookIsAPresetThatTheScenesOwnKeysOverride) {
    const Scene foil = loadScene(kStretch, {"render.look=foil"});
    EXPECT_EQ(foil.render.look, render::Look::Foil);
    EXPECT_EQ(foil.render.pathTracing.material, render::MaterialKind::Conductor);
    EXPECT_FLOAT_EQ(float(foil.render.pathTracing.roughness),
                    render::lookPreset(render::Look::Foil).roughness);
    const Scene rough = loadScene(kStretch, {"render.look=foil", "render.roughness=0.6"});
    EXPECT_DOUBLE_EQ(rough.render.pathTracing.roughness, 0.6);
    EXPECT_EQ(rough.render.pathTracing.material, render::MaterialKind::Conductor);
    const Scene paper = loadScene(kStretch, {"render.look=paper", "render.theta_style=paper_map",
                                             "render.tone_map=clamp", "render.exposure=-1.5"});
    EXPECT_EQ(paper.render.thetaStyle, render::ThetaStyle::PaperMap);
    EXPECT_EQ(paper.render.tone.curve, render::ToneCurve::Clamp);
    EXPECT_DOUBLE_EQ(paper.render.tone.exposure, -1.5);
    EXPECT_EQ(loadScene(kStretch).render.tone.curve, render::ToneCurve::Filmic);
    EXPECT_NE(errorOf(kStretch, {"render.look=nori"}).find("\"seaweed\""), std::string::npos);
}

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
    EXPECT_EQ(s.sim.time.control, sim::StepControl::Auto);
    EXPECT_TRUE(loadScene(kStretch, {"time.dt=adaptive"}).sim.time.adaptive());
    EXPECT_EQ(s.locationOf("time.dt"), "--set 'time.dt=auto'");
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
              "--set 'material.E=-5': error: material.E: expected a number in [0.001, 1e+13] "
              "(Young's modulus in Pa), found -5. Use e.g. E = 2e4.");
    EXPECT_EQ(errorOf(kStretch, {"material.E=abc"})
                  .rfind("--set 'material.E=abc': error: "
                         "material.E: expected a number in [0.001, 1e+13]",
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
              "safety, max_stretch_increment, burst_bonds, duration, fps, allow_unstable, "
              "allow_slow, integrator. Did you mean 'dt'?");
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
                           ":3:5: error: material.E: expected a number in [0.001, 1e+13] "
                           "(Young's modulus in Pa), found -5. Use e.g. E = 2e4.");
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

// ---- bond laws, fracture, diffusivity ----------------------------------------------------------

TEST_F(SceneTest, MaterialDefaultsAreLinearUnbreakableAndInert) {
    const sim::MaterialParams m = loadScene(writeScene("minimal.toml", kMinimal)).sim.material;
    EXPECT_EQ(m.law, sim::BondLawKind::Linear);
    EXPECT_DOUBLE_EQ(m.powerLawRatio, 0.0);
    EXPECT_DOUBLE_EQ(m.powerLawExponent, 4.0);
    EXPECT_DOUBLE_EQ(m.yieldStrain, 1e-4);
    EXPECT_DOUBLE_EQ(m.softening, 1.0);
    EXPECT_FALSE(m.fractureEnergy.has_value());
    EXPECT_EQ(m.criticalStretch, sim::CriticalStretchMode::Calibrated);
    EXPECT_DOUBLE_EQ(m.capacity, 1.0);
    EXPECT_DOUBLE_EQ(m.conductivity, 0.0);
    EXPECT_DOUBLE_EQ(m.expansion, 0.0);
    EXPECT_DOUBLE_EQ(m.stiffnessLoss, 0.0);
    EXPECT_DOUBLE_EQ(m.strengthLoss, 0.0);
}

TEST_F(SceneTest, MaterialReadsEveryNewKey) {
    const sim::MaterialParams m = loadScene(writeScene("material.toml", std::string(kMinimal) + R"(
law = "elastoplastic"
yield_strain = 2e-3
softening = 2.5
fracture_energy = 4.0
critical_stretch = "paper"
capacity = 2.0
conductivity = 0.3
expansion = -0.5
stiffness_loss = 0.25
strength_loss = 1.5
)"))
                                      .sim.material;
    EXPECT_EQ(m.law, sim::BondLawKind::Elastoplastic);
    EXPECT_DOUBLE_EQ(m.yieldStrain, 2e-3);
    EXPECT_DOUBLE_EQ(m.softening, 2.5);
    ASSERT_TRUE(m.fractureEnergy.has_value());
    EXPECT_DOUBLE_EQ(*m.fractureEnergy, 4.0);
    EXPECT_EQ(m.criticalStretch, sim::CriticalStretchMode::Paper);
    EXPECT_DOUBLE_EQ(m.capacity, 2.0);
    EXPECT_DOUBLE_EQ(m.conductivity, 0.3);
    EXPECT_DOUBLE_EQ(m.expansion, -0.5) << "alpha may be negative (shrinking)";
    EXPECT_DOUBLE_EQ(m.stiffnessLoss, 0.25);
    EXPECT_DOUBLE_EQ(m.strengthLoss, 1.5);
}

TEST_F(SceneTest, MaterialRangesAreChecked) {
    const fs::path file = writeScene("minimal.toml", kMinimal);
    const auto expectError = [&](std::vector<std::string> sets, const std::string& fragment) {
        const std::string message = errorOf(file, sets);
        EXPECT_NE(message.find(fragment), std::string::npos) << message;
    };
    expectError(
        {"material.law=power_law", "material.power_ratio=0.1"},
        "material.power_ratio: expected a number in [-1e+06, 0] (c*/c of the power law, eq. 19), "
        "found 0.1.");
    expectError({"material.law=power_law", "material.power_exponent=1"},
                "material.power_exponent: expected a number in (1, 100]");
    expectError({"material.yield_strain=0"}, "material.yield_strain: expected a number in (0, 10]");
    expectError({"material.law=elastoplastic", "material.softening=-1"},
                "material.softening: expected a number in (0, 1e+06]");
    expectError({"material.capacity=0"}, "material.capacity: expected a number in [1e-09, 1e+09]");
    expectError({"material.conductivity=-0.1"},
                "material.conductivity: expected a number in [0, 1e+09]");
    expectError({"material.stiffness_loss=-1"},
                "material.stiffness_loss: expected a number in [0, 1e+06]");
    expectError({"material.fracture_energy=1", "material.strength_loss=-1"},
                "material.strength_loss: expected a number in [0, 1e+06]");
    expectError({"material.fracture_energy=1", "material.critical_stretch=printed"},
                "material.critical_stretch: expected one of \"calibrated\", \"paper\"");
    expectError({"material.fracture_energy=true"},
                "material.fracture_energy: expected a number in (0, 1e+09] (the fracture energy "
                "G_f in J/m^2) or \"none\", found a boolean. Use e.g. fracture_energy = 11.3 or "
                "fracture_energy = \"none\".");
    expectError({"material.expansion=nan"}, "material.expansion: expected a number");
}

TEST_F(SceneTest, LawAndFractureConstantsNeedTheirSwitch) {
    const fs::path file = writeScene("minimal.toml", kMinimal);
    EXPECT_NE(errorOf(file, {"material.softening=2"})
                  .find("material.softening: expected no softening without law (it belongs to "
                        "law = \"elastoplastic\")"),
              std::string::npos);
    EXPECT_NE(
        errorOf(file, {"material.power_exponent=3"}).find("expected no power_exponent without law"),
        std::string::npos);
    EXPECT_NE(errorOf(file, {"material.critical_stretch=paper"})
                  .find("material.critical_stretch: expected no critical_stretch without "
                        "fracture_energy (bonds never break without it)"),
              std::string::npos);
    EXPECT_NE(errorOf(file, {"material.strength_loss=0.5"})
                  .find("expected no strength_loss without fracture_energy"),
              std::string::npos);
    // With the switch present, another law's constants are accepted and unused.
    const Scene s = loadScene(
        file, {"material.law=linear", "material.power_ratio=-0.2", "material.softening=3"});
    EXPECT_EQ(s.sim.material.law, sim::BondLawKind::Linear);
    EXPECT_DOUBLE_EQ(s.sim.material.powerLawRatio, -0.2);
}

TEST_F(SceneTest, PresetLawAndFractureCanBeSwitchedWithSet) {
    const fs::path file = writeScene("rubber.toml", R"(
[sheet]
size = [1.0, 1.0]
dx = 0.05

[material]
preset = "rubber_film"
)");
    const Scene s = loadScene(file, {"material.law=linear", "material.fracture_energy=none"});
    EXPECT_EQ(s.sim.material.law, sim::BondLawKind::Linear);
    EXPECT_FALSE(s.sim.material.fractureEnergy.has_value());
    EXPECT_DOUBLE_EQ(s.sim.material.strengthLoss, 15.0) << "kept, unused while unbreakable";
}

// ---- presets from the membrane paper ---------------------------------------------------------

namespace {

/// A tiny scene that uses preset NAME and nothing else in [material].
std::string presetScene(const std::string& name) {
    return "[sheet]\nsize = [1.0, 1.0]\ndx = 0.05\n\n[material]\npreset = \"" + name + "\"\n";
}

struct Table1Column {
    const char* preset;
    double E, poisson, density, capacity, conductivity, expansion, fractureEnergy, yieldStrain;
    sim::BondLawKind law;
};

}  // namespace

TEST_F(SceneTest, EveryShippedPresetLoads) {
    int count = 0;
    for (const auto& entry : fs::directory_iterator(kSource / "assets" / "materials")) {
        if (entry.path().extension() != ".toml") continue;
        const std::string name = entry.path().stem().string();
        const fs::path file = writeScene(name + ".toml", presetScene(name));
        EXPECT_EQ(errorOf(file), "<no SceneError>") << name;
        EXPECT_EQ(errorOf(kStretch, {"material.preset=" + name}), "<no SceneError>") << name;
        if (errorOf(file) == "<no SceneError>") {
            EXPECT_EQ(loadScene(file).sim.material.name, name);
        }
        ++count;
    }
    EXPECT_GE(count, 7);
}

TEST_F(SceneTest, PaperPresetsMatchTable1) {
    using sim::BondLawKind;
    // Membrane paper, Table 1: E, nu, rho, C, k, alpha, G_f, eta0 per column.
    const Table1Column columns[] = {
        {"crack_path", 2e4, 0.3, 5000, 1, 0.01, 1, 11.3, 1e-4, BondLawKind::Linear},
        {"foil", 2e3, 0.3, 5000, 1, 0.3, 0.3, 1.2, 1e-4, BondLawKind::Elastoplastic},
        {"rubber_film", 1e2, 0.3, 100, 1, 1, 10, 11.3, 1e-3, BondLawKind::PowerLaw},
        {"seaweed", 2e4, 0.3, 100, 1, 0.01, 0.3, 2.4, 1e-4, BondLawKind::Linear},
    };
    for (const Table1Column& c : columns) {
        SCOPED_TRACE(c.preset);
        const sim::MaterialParams m =
            loadScene(writeScene(std::string(c.preset) + ".toml", presetScene(c.preset)))
                .sim.material;
        EXPECT_EQ(m.name, c.preset);
        EXPECT_DOUBLE_EQ(m.youngsModulus, c.E);
        EXPECT_DOUBLE_EQ(m.poissonRatio, c.poisson);
        EXPECT_DOUBLE_EQ(m.density, c.density);
        EXPECT_DOUBLE_EQ(m.capacity, c.capacity);
        EXPECT_DOUBLE_EQ(m.conductivity, c.conductivity);
        EXPECT_DOUBLE_EQ(m.expansion, c.expansion);
        ASSERT_TRUE(m.fractureEnergy.has_value());
        EXPECT_DOUBLE_EQ(*m.fractureEnergy, c.fractureEnergy);
        EXPECT_DOUBLE_EQ(m.yieldStrain, c.yieldStrain);
        EXPECT_EQ(m.law, c.law);
        EXPECT_EQ(m.micromodulus, sim::MicromodulusMode::Calibrated);
        EXPECT_EQ(m.criticalStretch, sim::CriticalStretchMode::Calibrated);
    }
}

TEST_F(SceneTest, PresetsCarryTheirChosenLawsAndLosses) {
    const auto material = [&](const std::string& name) {
        return loadScene(writeScene(name + ".toml", presetScene(name))).sim.material;
    };
    const sim::MaterialParams rubber = material("rubber_film");
    EXPECT_DOUBLE_EQ(rubber.powerLawRatio, -0.05);
    EXPECT_DOUBLE_EQ(rubber.powerLawExponent, 2.0);
    EXPECT_DOUBLE_EQ(rubber.stiffnessLoss, 15.0);
    EXPECT_DOUBLE_EQ(rubber.strengthLoss, 15.0);
    EXPECT_DOUBLE_EQ(material("foil").softening, 1.0);
    const sim::MaterialParams seaweed = material("seaweed");
    EXPECT_DOUBLE_EQ(seaweed.stiffnessLoss, 3.0);
    EXPECT_DOUBLE_EQ(seaweed.strengthLoss, 4.0);

    const sim::MaterialParams dry = material("paper_towel_dry");
    const sim::MaterialParams wet = material("paper_towel_wet");
    EXPECT_EQ(dry.law, sim::BondLawKind::Linear);
    ASSERT_TRUE(dry.fractureEnergy && wet.fractureEnergy);
    EXPECT_DOUBLE_EQ(*dry.fractureEnergy, 3.0);
    EXPECT_DOUBLE_EQ(wet.youngsModulus, dry.youngsModulus) << "same base";
    EXPECT_DOUBLE_EQ(wet.density, dry.density);
    EXPECT_DOUBLE_EQ(*wet.fractureEnergy, *dry.fractureEnergy);
    EXPECT_DOUBLE_EQ(dry.conductivity, 0.0);
    EXPECT_DOUBLE_EQ(dry.stiffnessLoss, 0.0);
    EXPECT_DOUBLE_EQ(wet.conductivity, 0.05);
    EXPECT_DOUBLE_EQ(wet.expansion, 0.05);
    EXPECT_DOUBLE_EQ(wet.stiffnessLoss, 0.5);
    EXPECT_DOUBLE_EQ(wet.strengthLoss, 0.5);
}

// ---- [[notch]] and [diffusion] ---------------------------------------------------------------

TEST_F(SceneTest, NotchesAndDiffusionParse) {
    const Scene s = loadScene(writeScene("acid.toml", std::string(kMinimal) + R"(
conductivity = 0.01

[[notch]]
points = [[-0.5, 0.0], [-0.3, 0.0]]

[[notch]]
points = [[0.1, -0.2], [0.2, 0], [0.3, 0.1]]

[diffusion]
initial = 0.25

[[diffusion.spot]]
center = [0.1, -0.1]
radius = 0.08
rate = -2.0

[[diffusion.spot]]
center = [0.0, 0.0]
radius = 0.05
rate = 1.5
start = 0.5
duration = 2.0

[[diffusion.scatter]]
count = 12
radius = 0.03
rate = 4.0
start = 1.0
spread = 3.0
duration = 0.5
seed = 9

[[diffusion.scatter]]
count = 1
radius = 0.1
rate = 1.0

[[diffusion.edge]]
edge = "left"
depth = 0.1
value = 1.0

[[diffusion.edge]]
box = { min = [0.4, -0.25], max = [0.5, 0.25] }
value = -0.5
)"));
    ASSERT_EQ(s.sim.notches.size(), 2u);
    ASSERT_EQ(s.sim.notches[0].points.size(), 2u);
    EXPECT_EQ(s.sim.notches[0].points[0], Eigen::Vector2d(-0.5, 0.0));
    EXPECT_EQ(s.sim.notches[0].points[1], Eigen::Vector2d(-0.3, 0.0));
    ASSERT_EQ(s.sim.notches[1].points.size(), 3u);
    EXPECT_EQ(s.sim.notches[1].points[1], Eigen::Vector2d(0.2, 0.0)) << "integers are numbers";

    const sim::DiffusionParams& d = s.sim.diffusion;
    EXPECT_DOUBLE_EQ(d.initial, 0.25);
    ASSERT_EQ(d.spots.size(), 2u);
    EXPECT_EQ(d.spots[0].center, Eigen::Vector2d(0.1, -0.1));
    EXPECT_DOUBLE_EQ(d.spots[0].radius, 0.08);
    EXPECT_DOUBLE_EQ(d.spots[0].rate, -2.0) << "a sink";
    EXPECT_DOUBLE_EQ(d.spots[0].start, 0.0);
    EXPECT_TRUE(std::isinf(d.spots[0].duration)) << "forever by default";
    EXPECT_DOUBLE_EQ(d.spots[1].start, 0.5);
    EXPECT_DOUBLE_EQ(d.spots[1].duration, 2.0);

    ASSERT_EQ(d.scatters.size(), 2u);
    const sim::SpotScatter& spray = d.scatters[0];
    EXPECT_EQ(spray.count, 12);
    EXPECT_DOUBLE_EQ(spray.radius, 0.03);
    EXPECT_DOUBLE_EQ(spray.rate, 4.0);
    EXPECT_DOUBLE_EQ(spray.start, 1.0);
    EXPECT_DOUBLE_EQ(spray.spread, 3.0);
    EXPECT_DOUBLE_EQ(spray.duration, 0.5);
    EXPECT_EQ(spray.seed, 9u);
    const sim::SpotScatter& heat = d.scatters[1];
    EXPECT_EQ(heat.count, 1);
    EXPECT_DOUBLE_EQ(heat.start, 0.0);
    EXPECT_DOUBLE_EQ(heat.spread, 0.0) << "all at once";
    EXPECT_TRUE(std::isinf(heat.duration));
    EXPECT_EQ(heat.seed, 1u);

    ASSERT_EQ(d.edges.size(), 2u);
    EXPECT_DOUBLE_EQ(d.edges[0].value, 1.0);
    EXPECT_NEAR(d.edges[0].region.max.x(), -0.5 + 0.1, 1e-9)
        << "depth in metres, like [[boundary]]";
    EXPECT_TRUE(std::isinf(d.edges[0].region.min.x()));
    EXPECT_EQ(d.edges[1].region.min, Eigen::Vector2d(0.4, -0.25));
    EXPECT_EQ(d.edges[1].region.max, Eigen::Vector2d(0.5, 0.25));
    EXPECT_DOUBLE_EQ(d.edges[1].value, -0.5);
}

TEST_F(SceneTest, NoNotchOrDiffusionMeansNone) {
    const Scene s = loadScene(kStretch);
    EXPECT_TRUE(s.sim.notches.empty());
    EXPECT_DOUBLE_EQ(s.sim.diffusion.initial, 0.0);
    EXPECT_TRUE(s.sim.diffusion.spots.empty());
    EXPECT_TRUE(s.sim.diffusion.scatters.empty());
    EXPECT_TRUE(s.sim.diffusion.edges.empty());
}

TEST_F(SceneTest, DiffusionSourcesNeedNoConductivity) {
    // Sources then act only where they are; that is a valid (if local) scene.
    const Scene s = loadScene(writeScene("local.toml", std::string(kMinimal) + R"(
[[diffusion.spot]]
center = [0.0, 0.0]
radius = 0.1
rate = 1.0
)"));
    EXPECT_DOUBLE_EQ(s.sim.material.conductivity, 0.0);
    EXPECT_EQ(s.sim.diffusion.spots.size(), 1u);
}

TEST_F(SceneTest, MalformedNotchesAndSourcesAreLocated) {
    const fs::path file = writeScene("sources.toml", std::string(kMinimal) + R"(
[[notch]]
points = [[0.0, 0.0], [0.1, 0.0]]

[[diffusion.scatter]]
count = 3
radius = 0.05
rate = 1.0
)");
    const std::string where = file.string() + ":";
    EXPECT_EQ(errorOf(file, {"diffusion.scatter.0.count=0"}),
              "--set 'diffusion.scatter.0.count=0': error: diffusion.scatter.0.count: expected "
              "an integer in [1, 10000] (how many spots or droplets), found 0. Use e.g. count "
              "= 20.");
    EXPECT_NE(errorOf(file, {"diffusion.scatter.0.seed=-1"})
                  .find("diffusion.scatter.0.seed: expected an integer in [0, 9e+18]"),
              std::string::npos);
    EXPECT_NE(errorOf(file, {"diffusion.scatter.0.spread=-1"})
                  .find("diffusion.scatter.0.spread: expected a number in [0, 1e+06]"),
              std::string::npos);
    EXPECT_NE(errorOf(file, {"diffusion.scatter.0.duration=0"})
                  .find("diffusion.scatter.0.duration: expected a number in (0, 1e+06]"),
              std::string::npos);
    EXPECT_NE(errorOf(file, {"diffusion.scatter.0.rat=1"})
                  .find("unknown key 'rat' in [[diffusion.scatter]] entry 0"),
              std::string::npos);
    EXPECT_EQ(errorOf(file, {"notch.0.points=[[0, 0], [0, 0]]"}),
              "--set 'notch.0.points=[[0, 0], [0, 0]]': error: notch.0.points: expected "
              "consecutive points that differ (the notch polyline in rest coordinates, metres; "
              "bonds crossing it break at set-up), found point 1 repeating [0, 0]. Remove the "
              "repeated point.");
    EXPECT_NE(errorOf(file, {"notch.0.points=[[0, 0], [0, \"a\"]]"})
                  .find("notch.0.points.1: expected a point [x, y] of 2 numbers in [-10000, 10000] "
                        "(the notch polyline in rest coordinates, metres; bonds crossing it "
                        "break at set-up), found an array containing a "
                        "string \"a\"."),
              std::string::npos);
    EXPECT_NE(errorOf(file, {"notch.0.points=3"})
                  .find("notch.0.points: expected an array of at least 2 points [x, y]"),
              std::string::npos);
    EXPECT_NE(errorOf(file, {"notch=5"})
                  .find("notch: expected an array of tables written as [[notch]], found the "
                        "number 5. Give each entry its own [[notch]] header."),
              std::string::npos);
    EXPECT_NE(errorOf(file, {"diffusion.initial=inf"})
                  .find("diffusion.initial: expected a number in [-1e+06, 1e+06] (theta everywhere "
                        "at t = 0), "
                        "found "
                        "inf."),
              std::string::npos);
    const std::string edge = errorOf(writeScene("edge.toml", std::string(kMinimal) + R"(
[[diffusion.edge]]
edge = "right"
)"));
    EXPECT_EQ(edge.rfind(where.substr(0, where.rfind('/')) + "/edge.toml:10:1: error: "
                                                             "diffusion.edge.0.value is missing",
                         0),
              0u)
        << edge;
}

TEST_F(SceneTest, RenderingKeysAndExportsAreRead) {
    const fs::path file = writeScene("render_keys.toml", R"(
[sheet]
size = [1.0, 1.0]
dx = 0.05
[material]
E = 2e4
density = 5000
[render]
renderer = "embree"
surface = "vdb"
thickness = 0.002
spp = 64
max_depth = 6
material = "conductor"
roughness = 0.2
transmission = 0.1
sky = false
sun_radius = 0.5
sky_zenith = [0.1, 0.2, 0.3]
vdb_voxel_size = 0.01
vdb_particle_radius = 0.02
vdb_smoothing = 3
vdb_adaptivity = 0.5
[output]
export = ["glb", "vdb"]
)");
    const Scene s = loadScene(file);
    EXPECT_EQ(s.renderer, RendererKind::Embree);
    EXPECT_EQ(s.render.surface, render::SurfaceKind::Vdb);
    EXPECT_DOUBLE_EQ(s.render.thickness, 0.002);
    const render::PathTracing& p = s.render.pathTracing;
    EXPECT_EQ(p.samplesPerPixel, 64);
    EXPECT_EQ(p.maxDepth, 6);
    EXPECT_EQ(p.material, render::MaterialKind::Conductor);
    EXPECT_DOUBLE_EQ(p.roughness, 0.2);
    EXPECT_DOUBLE_EQ(p.transmission, 0.1);
    EXPECT_FALSE(p.sky);
    EXPECT_DOUBLE_EQ(p.sunAngularRadiusDegrees, 0.5);
    EXPECT_DOUBLE_EQ(p.skyZenith.z(), 0.3);
    EXPECT_DOUBLE_EQ(s.render.vdb.voxelSize, 0.01);
    EXPECT_DOUBLE_EQ(s.render.vdb.particleRadius, 0.02);
    EXPECT_EQ(s.render.vdb.smoothingIterations, 3);
    EXPECT_DOUBLE_EQ(s.render.vdb.adaptivity, 0.5);
    EXPECT_EQ(s.exports, (std::vector<ExportFormat>{ExportFormat::Glb, ExportFormat::Vdb}));
}

TEST_F(SceneTest, SolverIsChosenAtTheTopLevelAndRefusesWhatItCannotDo) {
    EXPECT_EQ(loadScene(kStretch).sim.solver, "peridynamic") << "the default";
    EXPECT_EQ(loadScene(kStretch, {"solver=fem_cst"}).sim.solver, "fem_cst");
    EXPECT_EQ(loadScene(kStretch, {"solver=mass_spring_vg"}).sim.solver, "mass_spring_vg");
    EXPECT_EQ(loadScene(kStretch, {"solver=mass_spring_tp"}).sim.solver, "mass_spring_tp");
    EXPECT_EQ(loadScene(kStretch, {"solver=sph"}).sim.solver, "sph");
    const fs::path file = writeScene("minimal.toml", kMinimal);
    EXPECT_NE(errorOf(file, {"solver=fem"}).find("solver: expected one of"), std::string::npos);
    EXPECT_EQ(loadScene(file, {"solver=fem_cst", "material.fracture_energy=5"})
                  .sim.material.fractureEnergy,
              5.0)
        << "the FEM and spring solvers break by a critical strain";
    const std::string sphere = errorOf(kSphere, {"solver=sph"});
    EXPECT_NE(sphere.find("solver: expected a solver that takes shape = \"sphere\""),
              std::string::npos)
        << sphere;
    EXPECT_EQ(
        loadScene(file, {"solver=sph", "material.fracture_energy=5"}).sim.material.fractureEnergy,
        5.0)
        << "the SPH breaks its pairs";
    for (const char* solver : {"fem_cst", "mass_spring_vg", "mass_spring_tp"})
        EXPECT_EQ(loadScene(file, {std::string("solver=") + solver, "material.law=power_law"})
                      .sim.material.law,
                  sim::BondLawKind::PowerLaw)
            << solver << " takes the bond laws";
    EXPECT_NE(errorOf(file, {"solver=sph", "material.law=elastoplastic"})
                  .find("a bond law other than linear"),
              std::string::npos);
}
