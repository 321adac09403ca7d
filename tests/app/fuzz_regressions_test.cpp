// Replays the fuzz target's seeds and every input it ever crashed on (tests/fuzz/regressions/,
// split as fuzz/FuzzInput.h says): each must load or be refused with a SceneError, never crash
// or throw anything else.

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "app/Scene.h"
#include "app/SceneError.h"
#include "fuzz/FuzzInput.h"
#include "tests/ScratchDir.h"

using namespace rend;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = REND_SOURCE_DIR;

std::vector<fs::path> inputsIn(const fs::path& directory) {
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(directory)) {
        if (entry.is_regular_file() && entry.path().filename() != "README.md")
            files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

std::string readBytes(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Loads one fuzz input the way the harness does; returns "loaded" or "refused".
std::string replay(const fs::path& input) {
    const fuzz::FuzzInput split = fuzz::splitFuzzInput(readBytes(input));
    const fs::path scene = test::scratchDir() / "replay.toml";
    std::ofstream(scene, std::ios::binary | std::ios::trunc) << split.scene;
    try {
        loadScene(scene, split.sets);
    } catch (const SceneError&) {
        return "refused";
    }
    return "loaded";
}

}  // namespace

TEST(FuzzInput, SplitsTheSceneFromOneSetPerLine) {
    const fuzz::FuzzInput input = fuzz::splitFuzzInput("[sheet]\ndx = 1\n--set\na=1\n\nb.c=[2]");
    EXPECT_EQ(input.scene, "[sheet]\ndx = 1");
    EXPECT_EQ(input.sets, (std::vector<std::string>{"a=1", "", "b.c=[2]"}));
    EXPECT_TRUE(fuzz::splitFuzzInput("x = 1\n").sets.empty());
}

TEST(FuzzRegressions, EverySeedLoadsOrIsRefused) {
    const std::vector<fs::path> seeds = inputsIn(kSource / "fuzz" / "seeds");
    ASSERT_FALSE(seeds.empty());
    for (const fs::path& seed : seeds) {
        EXPECT_NO_THROW(replay(seed)) << seed;
    }
    EXPECT_EQ(replay(kSource / "fuzz" / "seeds" / "stretch_sets.toml"), "loaded")
        << "the --set lines of a seed are applied";
}

TEST(FuzzRegressions, EveryInputThatOnceCrashedLoadsOrIsRefused) {
    const std::vector<fs::path> inputs = inputsIn(kSource / "tests" / "fuzz" / "regressions");
    ASSERT_FALSE(inputs.empty());
    for (const fs::path& input : inputs) {
        EXPECT_NO_THROW(replay(input)) << input;
    }
}
