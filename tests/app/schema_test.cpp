// The scene schema as data: the README's scene-file table is the schema's, every declared key
// is read by the loader, unused keys are errors, and locations survive into the Scene.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "app/Pipeline.h"
#include "app/Scene.h"
#include "app/SceneError.h"
#include "app/SceneReader.h"
#include "tests/ScratchDir.h"

using namespace rend;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = REND_SOURCE_DIR;
const fs::path kReadme = kSource / "README.md";
constexpr std::string_view kBegin = "<!-- scene schema: begin (generated) -->\n";
constexpr std::string_view kEnd = "<!-- scene schema: end -->\n";

std::string readFile(const fs::path& file) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

}  // namespace

// REND_UPDATE_README=1 rewrites the README's table from the schema instead of comparing.
TEST(SceneSchema, ReadmeTableIsTheSchemas) {
    std::string readme = readFile(kReadme);
    const std::size_t begin = readme.find(kBegin);
    const std::size_t end = readme.find(kEnd);
    ASSERT_NE(begin, std::string::npos) << "README.md lacks the line " << kBegin;
    ASSERT_NE(end, std::string::npos) << "README.md lacks the line " << kEnd;
    const std::size_t first = begin + kBegin.size();
    const std::string table = scene::schemaMarkdown();
    if (std::getenv("REND_UPDATE_README")) {
        readme.replace(first, end - first, table);
        std::ofstream(kReadme) << readme;
    }
    EXPECT_EQ(readme.substr(first, end - first), table)
        << "Regenerate with REND_UPDATE_README=1 rend_app_tests --gtest_filter=SceneSchema.*";
}

TEST(SceneSchema, EveryTableKeyNamesADeclaredSection) {
    for (const scene::Section& section : scene::sceneSchema()) {
        for (const scene::Param& p : section.keys) {
            const bool nested =
                p.type == scene::ValueType::Table || p.type == scene::ValueType::Tables;
            if (nested) {
                EXPECT_NO_THROW(scene::sectionAt(p.section)) << p.key;
            }
            EXPECT_FALSE(p.meaning.empty()) << section.path << "." << p.key;
            if (!nested) {
                EXPECT_FALSE(p.example.empty()) << section.path << "." << p.key;
            }
        }
    }
}

TEST(SceneSchema, EveryNumberHasAFiniteRange) {
    using scene::ValueType;
    for (const scene::Section& section : scene::sceneSchema()) {
        for (const scene::Param& p : section.keys) {
            const bool numeric = p.type == ValueType::Number || p.type == ValueType::Integer ||
                                 p.type == ValueType::NumberOrWord || p.type == ValueType::Vec2 ||
                                 p.type == ValueType::Vec3 || p.type == ValueType::Points;
            if (!numeric) continue;
            EXPECT_TRUE(std::isfinite(p.range.lo) && std::isfinite(p.range.hi))
                << section.path << "." << p.key << " " << p.range.describe();
        }
    }
}

namespace {

constexpr const char* kSmall = R"([sheet]
size = [0.2, 0.2]
dx = 0.02

[material]
E = 2e4
density = 5000

[[boundary]]
type = "pinned"
edge = "left"

[[boundary]]
type = "velocity"
box = { min = [0.03, 0.03], max = [0.031, 0.031] }
velocity = [0.1, 0.0, 0.0]

[time]
duration = 0.0834

[render]
renderer = "none"
)";

fs::path writeScene(const std::string& name, const std::string& text) {
    const fs::path dir = test::scratchDir();
    fs::create_directories(dir);
    std::ofstream(dir / name) << text;
    return dir / name;
}

std::string setUpError(const fs::path& file, const std::vector<std::string>& sets = {}) {
    try {
        prepareMembrane(loadScene(file, sets));
    } catch (const SceneError& e) {
        return e.what();
    }
    return "<no SceneError>";
}

}  // namespace

TEST(SceneSchema, TheSceneKeepsTheLocationOfEveryValue) {
    const fs::path file = writeScene("small.toml", kSmall);
    const Scene s = loadScene(file, {"time.fps=12"});
    EXPECT_EQ(s.locationOf("sheet.dx"), file.string() + ":3:6");
    EXPECT_EQ(s.locationOf("boundary.1.velocity"), file.string() + ":16:12");
    EXPECT_EQ(s.locationOf("boundary.1.box"), file.string() + ":15:7");
    EXPECT_EQ(s.locationOf("time.fps"), "--set 'time.fps=12'");
    EXPECT_EQ(s.locationOf("time.dt"), file.string() + ":18:1") << "absent: its table";
    EXPECT_EQ(s.locationOf("forces.gravity"), file.string() + ":1:1") << "no table: the file";
}

TEST(SceneSchema, EveryUnknownKeyIsReportedWithItsLocationAndASuggestion) {
    const fs::path file = writeScene("unknown.toml", std::string(kSmall) + R"(widht = 64
colour_by = "strain"
)");
    try {
        loadScene(file);
        FAIL() << "no SceneError";
    } catch (const SceneError& e) {
        EXPECT_EQ(
            std::string(e.what()),
            file.string() +
                ":23:1: error: unknown key 'widht' in [render]; expected one of: "
                "renderer, width, height, supersample, look, color_by, theta_style, tone_map, "
                "exposure, color_range, albedo, "
                "background, ground_color, ground, ground_height, spp, max_depth, denoise, "
                "material, roughness, transmission, sky, sun_radius, sky_zenith, "
                "sky_horizon, surface, thickness, vdb_voxel_size, vdb_particle_radius, "
                "vdb_smoothing, vdb_adaptivity. Did you mean 'width'?\n" +
                file.string() +
                ":24:1: error: unknown key 'colour_by' in [render]; expected one of: "
                "renderer, width, height, supersample, look, color_by, theta_style, tone_map, "
                "exposure, color_range, albedo, "
                "background, ground_color, ground, ground_height, spp, max_depth, denoise, "
                "material, roughness, transmission, sky, sun_radius, sky_zenith, "
                "sky_horizon, surface, thickness, vdb_voxel_size, vdb_particle_radius, "
                "vdb_smoothing, vdb_adaptivity. Did you mean 'color_by'?");
    }
}

TEST(SceneSchema, ABoundaryRegionWithoutParticlesIsLocatedAtItsBox) {
    const fs::path file = writeScene("small.toml", kSmall);
    EXPECT_EQ(setUpError(file),
              file.string() +
                  ":15:7: error: boundary.1: expected a region that holds particles, found none "
                  "inside it. Widen its depth or box, or check it against the sheet's size.");
}

TEST(SceneSchema, ANotchThatCutsNothingIsLocatedAtItsPoints) {
    const fs::path file = writeScene("notch.toml", std::string(kSmall) + R"(
[[notch]]
points = [[-0.1, 0.0], [-0.05, 0.0]]
)");
    const std::vector<std::string> wide = {"boundary.1.box.max=[0.1, 0.1]"};
    ASSERT_EQ(setUpError(file, wide), "<no SceneError>");
    std::vector<std::string> between = wide;
    between.push_back("notch.0.points=[[0.001, 0.0005], [0.002, 0.0005]]");
    EXPECT_EQ(setUpError(file, between),
              "--set 'notch.0.points=[[0.001, 0.0005], [0.002, 0.0005]]': error: notch.0.points: "
              "expected notches that cross at least one bond, found none crossed. Extend the "
              "polyline across the sheet's particles.");
    std::vector<std::string> off = wide;
    off.push_back("notch.0.points=[[5, 5], [6, 5]]");
    EXPECT_NE(setUpError(file, off).find("--set 'notch.0.points=[[5, 5], [6, 5]]': error: "
                                         "notch.0.points: expected a polyline that meets the "
                                         "sheet, whose rest extent is x in [-0.1, 0.1]"),
              std::string::npos);
}

TEST(SceneSchema, TheStableStepBoundIsLocatedAtDt) {
    const fs::path file = writeScene("small.toml", kSmall);
    const std::string message = setUpError(file, {"boundary.1.box.max=[0.1, 0.1]", "time.dt=0.05"});
    EXPECT_EQ(message.rfind("--set 'time.dt=0.05': error: time.dt: expected at most the stable "
                            "limit",
                            0),
              0u)
        << message;
}

TEST(SceneSchema, StatsFalseWritesNoStatsFile) {
    const fs::path file = writeScene("small.toml", kSmall);
    const fs::path out = test::scratchDir() / "no_stats";
    fs::remove_all(out);
    RunOptions options;
    options.outDir = out;
    runScene(loadScene(file, {"boundary.1.box.max=[0.1, 0.1]", "output.stats=false"}), options);
    EXPECT_TRUE(fs::exists(out / "run.json"));
    EXPECT_FALSE(fs::exists(out / "stats.csv"));
    runScene(loadScene(file, {"boundary.1.box.max=[0.1, 0.1]"}), options);
    EXPECT_TRUE(fs::exists(out / "stats.csv"));
}
