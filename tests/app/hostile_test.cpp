// Hostile input, class by class: every value is refused at load (or at set-up) with its
// location, or the run ends finite. Values from --set are located by the --set text.

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "app/Pipeline.h"
#include "app/Scene.h"
#include "app/SceneError.h"
#include "app/SceneReader.h"
#include "tests/ScratchDir.h"

using namespace rend;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = REND_SOURCE_DIR;
const fs::path kStretch = kSource / "scenes" / "stretch.toml";

/// A scene with a table for every section, so that every schema key has a place to go.
constexpr const char* kEverything = R"([sheet]
size = [0.2, 0.2]
dx = 0.02
perturbation = 1e-4

[material]
E = 2e4
density = 5000
law = "linear"
fracture_energy = 11.3
conductivity = 0.01

[[boundary]]
type = "velocity"
edge = "left"
velocity = [-0.1, 0.0, 0.0]

[[boundary]]
type = "pinned"
box = { min = [0.05, -0.1], max = [0.1, 0.1] }

[[notch]]
points = [[-0.1, 0.0], [-0.05, 0.0]]

[[diffusion.spot]]
center = [0.0, 0.0]
radius = 0.05
rate = 1.0

[[diffusion.scatter]]
count = 3
radius = 0.02
rate = 1.0

[[diffusion.edge]]
edge = "top"
value = 1.0

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

/// The message of the SceneError thrown by loading and preparing, or "" when none is.
std::string errorOf(const fs::path& file, const std::vector<std::string>& sets) {
    try {
        const Scene scene = loadScene(file, sets);
        prepareMembrane(scene);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

/// Dotted --set paths of every numeric key, with array-of-tables entries at index 0, and how
/// many numbers each holds (0: a scalar).
std::vector<std::pair<std::string, int>> numericKeys(const scene::Section& section,
                                                     const std::string& prefix) {
    using scene::ValueType;
    std::vector<std::pair<std::string, int>> keys;
    for (const scene::Param& p : section.keys) {
        const std::string key = prefix + std::string(p.key);
        switch (p.type) {
            case ValueType::Table:
            case ValueType::Tables: {
                const std::string child = key + (p.type == ValueType::Tables ? ".0." : ".");
                for (auto& k : numericKeys(scene::sectionAt(p.section), child))
                    keys.push_back(std::move(k));
                break;
            }
            case ValueType::Number:
            case ValueType::Integer:
            case ValueType::NumberOrWord:
                keys.emplace_back(key, 0);
                break;
            case ValueType::Vec2:
                keys.emplace_back(key, 2);
                break;
            case ValueType::Vec3:
                keys.emplace_back(key, 3);
                break;
            default:
                break;
        }
    }
    return keys;
}

/// VALUE, or [VALUE, VALUE(, VALUE)] for a vector.
std::string valueText(const std::string& value, int arity) {
    if (arity == 0) return value;
    std::string text = "[";
    for (int k = 0; k < arity; ++k) text += (k ? ", " : "") + value;
    return text + "]";
}

}  // namespace

TEST(HostileInput, EveryNumberRefusesNonFiniteAndAbsurdValuesWithItsLocation) {
    const fs::path file = writeScene("everything.toml", kEverything);
    ASSERT_EQ(errorOf(file, {}), "") << "the base scene is valid";
    const auto keys = numericKeys(scene::sectionAt(""), "");
    EXPECT_GE(keys.size(), 75u);
    for (const auto& [key, arity] : keys) {
        for (const char* value : {"nan", "inf", "-inf", "1e308", "-1e308", "9223372036854775807",
                                  "-9223372036854775808"}) {
            const std::string set = key + "=" + valueText(value, arity);
            const std::string message = errorOf(file, {set});
            // Located at the --set text (shortened past 80 characters).
            EXPECT_EQ(message.rfind("--set '" + set.substr(0, 60), 0), 0u)
                << set << ": " << message;
            // The finding may quote the value; the advice after it never does.
            const std::size_t found = message.find(", found ");
            ASSERT_NE(found, std::string::npos) << message;
            const std::string advice = message.substr(message.find(". ", found) + 1);
            EXPECT_EQ(advice.find("nan"), std::string::npos) << message;
            EXPECT_EQ(advice.find("inf"), std::string::npos) << message;
        }
    }
}

TEST(HostileInput, ATinyFrameRateIsRefusedInsteadOfRunningPastTheDuration) {
    const std::string message = errorOf(kStretch, {"time.fps=1e-300"});
    EXPECT_EQ(message.rfind("--set 'time.fps=1e-300': error: time.fps: expected a number in", 0),
              0u)
        << message;
    EXPECT_NE(errorOf(kStretch, {"time.fps=0.01"}).find("at least one frame"), std::string::npos);
}

TEST(HostileInput, HugeSpeedsAndAccelerationsAreRefused) {
    EXPECT_NE(errorOf(kStretch, {"boundary.1.velocity=[1e300, 0, 0]"})
                  .find("boundary.1.velocity: expected an array of 3 numbers in [-1000, 1000]"),
              std::string::npos);
    EXPECT_NE(errorOf(kStretch, {"forces.gravity=[0, 0, -1e300]"})
                  .find("forces.gravity: expected an array of 3 numbers in [-10000, 10000]"),
              std::string::npos);
}

TEST(HostileInput, AHugeSheetQuotesAFiniteSpacing) {
    const std::string message = errorOf(kStretch, {"sheet.size=[1e4, 1e4]"});
    EXPECT_NE(message.find("sheet.dx: expected a spacing that fits the memory limit of 8 GB"),
              std::string::npos)
        << message;
    EXPECT_EQ(message.find("nan"), std::string::npos) << message;
    EXPECT_EQ(message.find("inf"), std::string::npos) << message;
}

TEST(HostileInput, MemoryIsCappedByTheHorizonsBonds) {
    // 2 m x 2 m at dx = 1.5 mm: 2e6 particles. With 6 bonds each they fit in 1.4 GB; with the
    // 130 of horizon = 6 they need about 11 GB.
    const std::vector<std::string> fine = {"sheet.dx=0.0015"};
    EXPECT_NO_THROW(loadScene(kStretch, fine));
    std::vector<std::string> wide = fine;
    wide.push_back("sheet.horizon=6");
    try {
        loadScene(kStretch, wide);
        FAIL() << "no SceneError";
    } catch (const SceneError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.rfind("--set 'sheet.dx=0.0015': error: sheet.dx: ", 0), 0u) << message;
        EXPECT_NE(message.find("130 bonds each, about 11 GB"), std::string::npos) << message;
        EXPECT_NE(message.find("or a smaller horizon"), std::string::npos) << message;
    }
    const SheetEstimate e = estimateSheet(loadScene(kStretch).sim.sheet);
    EXPECT_NEAR(e.particles, 11658, 0.02 * 11658) << "the hexagonal lattice's count";
}

TEST(HostileInput, ASlowRunIsRefusedAtTheKeyThatDrivesItUnlessAllowed) {
    const fs::path sources = kSource / "scenes" / "crack_path_sources.toml";
    const std::vector<std::string> slow = {"material.conductivity=1e8"};
    const std::string message = errorOf(sources, slow);
    EXPECT_NE(message.find(": error: material.conductivity: expected a run estimated within 6 h "
                           "on one core, found "),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("diffusion sub-steps per step"), std::string::npos) << message;
    EXPECT_NE(message.find("--set time.allow_slow=true"), std::string::npos) << message;
    std::vector<std::string> allowed = slow;
    allowed.push_back("time.allow_slow=true");
    EXPECT_EQ(errorOf(sources, allowed), "");
}

TEST(HostileInput, ATinyDensityWithAutoDtIsRefusedAtTheDensity) {
    const std::string message =
        errorOf(kStretch, {"time.dt=auto", "material.E=1e9", "material.density=1e-3"});
    EXPECT_EQ(message.rfind("--set 'material.density=1e-3': error: material.density: expected a "
                            "run estimated within 6 h",
                            0),
              0u)
        << message;
}

TEST(HostileInput, StepCountsBeyondTheCountersAreRefusedEvenWhenSlowRunsAreAllowed) {
    const std::string message = errorOf(kStretch, {"time.dt=1e-300", "time.allow_slow=true"});
    EXPECT_EQ(message.rfind("--set 'time.dt=1e-300': error: time.dt: expected at most 1e9 steps "
                            "per frame",
                            0),
              0u)
        << message;
    EXPECT_EQ(message.find("inf"), std::string::npos) << message;
}

TEST(HostileInput, TheEstimateCountsStepsAndDiffusionSubsteps) {
    // Table 1's fixed dt: the adaptive default's estimate counts the bound's steps.
    const Scene scene = loadScene(kSource / "scenes" / "crack_path_sources.toml", {"time.dt=1e-4"});
    const sim::Membrane membrane = prepareMembrane(scene);
    const RunEstimate e = estimateRun(scene, membrane);
    EXPECT_EQ(e.frames, 120);
    EXPECT_EQ(e.stepsPerFrame, 417);
    EXPECT_GE(e.diffusionSubsteps, 1);
    EXPECT_DOUBLE_EQ(e.particleSteps, 417.0 * 120 * membrane.particleCount());
    EXPECT_GT(e.seconds, 0);
    EXPECT_NE(describeEstimate(e).find("417 per frame x 120 frames"), std::string::npos);
}

TEST(HostileInput, RendCheckPrintsTheEstimates) {
    const std::string command =
        std::string(REND_BINARY) + " check " + kStretch.string() + " --set time.dt=1e-4";
    std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
    ASSERT_TRUE(pipe);
    std::string output;
    std::array<char, 256> buffer{};
    while (fgets(buffer.data(), buffer.size(), pipe.get())) output += buffer.data();
    EXPECT_NE(output.find("estimated memory 0.00793 GB (1.15e+04 particles x (400 B + 7.16 "
                          "bonds x 40 B))"),
              std::string::npos)
        << output;
    EXPECT_NE(output.find("estimated cost: 5e+04 steps (417 per frame x 120 frames)"),
              std::string::npos)
        << output;
}
