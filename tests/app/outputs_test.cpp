// The output folder's bookkeeping (app/Outputs.h): which names rend may remove, and how a rerun
// replaces the previous run's files.

#include "app/Outputs.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <system_error>

#include "app/Scene.h"

namespace fs = std::filesystem;
using namespace rend;

namespace {

fs::path folderWith(const std::string& name, const std::vector<std::string>& files) {
    const fs::path dir = fs::temp_directory_path() / "rend_outputs_test" / name;
    fs::remove_all(dir);
    for (const std::string& file : files) {
        fs::create_directories((dir / file).parent_path());
        std::ofstream(dir / file) << "x";
    }
    return dir;
}

void writeManifest(const fs::path& dir, const std::vector<std::string>& files) {
    std::ofstream(dir / "run.json")
        << "{\n  \"status\": \"ok\",\n  \"files\": " << jsonStringArray(files, "  ") << "\n}\n";
}

}  // namespace

TEST(RunOutputNames, OnlyTheNamesRendWritesAreAccepted) {
    for (const char* name :
         {"stats.csv", "frames/frame_0001.png", "frames/frame_12345.png", "meshes/frame_0002.obj",
          "meshes/frame_0002.mtl", "vdb/frame_0003.vdb", "frames/frame_0004.exr"})
        EXPECT_TRUE(isRunOutputName(name)) << name;
    for (const char* name :
         {"run.json", "../stats.csv", "/etc/passwd", "frames/../stats.csv", "frames/x.png",
          "frames/frame_0001.png.tmp", "meshes/frame_0001.stl", "notes.txt", ""})
        EXPECT_FALSE(isRunOutputName(name)) << name;
}

TEST(RunFolder, ARerunRemovesOnlyThePreviousRunsFilesItDoesNotRewrite) {
    const fs::path dir = folderWith(
        "rerun", {"frames/frame_0001.png", "frames/frame_0002.png", "frames/frame_0003.png",
                  "frames/mine.png", "stats.csv", "frames/frame_0001.png.tmp"});
    writeManifest(dir, {"frames/frame_0001.png", "frames/frame_0002.png", "frames/frame_0003.png",
                        "stats.csv", "../outside"});
    RunFolder folder(dir, {"frames/frame_0001.png", "frames/frame_0002.png", "stats.csv"});
    EXPECT_EQ(folder.listedWhileRunning(),
              (std::vector<std::string>{"frames/frame_0001.png", "frames/frame_0002.png",
                                        "frames/frame_0003.png", "stats.csv"}));
    EXPECT_EQ(folder.removeStale(), std::vector<std::string>{"frames/frame_0003.png"});
    EXPECT_FALSE(fs::exists(dir / "frames/frame_0003.png"));
    EXPECT_FALSE(fs::exists(dir / "frames/frame_0001.png.tmp"));
    EXPECT_TRUE(fs::exists(dir / "frames/frame_0001.png")) << "kept until overwritten";
    EXPECT_TRUE(fs::exists(dir / "frames/mine.png")) << "rend never wrote it";
    // The run stops after frame 1: frame 2 of the previous run must not pass for this run's.
    folder.wrote({"frames/frame_0001.png", "stats.csv"});
    EXPECT_EQ(folder.finish(), (std::vector<std::string>{"frames/frame_0001.png", "stats.csv"}));
    EXPECT_FALSE(fs::exists(dir / "frames/frame_0002.png"));
    EXPECT_TRUE(fs::exists(dir / "frames/frame_0001.png"));
}

TEST(RunFolder, AFolderWithoutRunJsonHasNoPreviousFiles) {
    const fs::path dir = folderWith("fresh", {"frames/frame_0001.png"});
    EXPECT_TRUE(previousRunFiles(dir).empty());
    RunFolder folder(dir, {"stats.csv"});
    EXPECT_TRUE(folder.removeStale().empty());
    EXPECT_TRUE(fs::exists(dir / "frames/frame_0001.png"));
}

TEST(StatsWriter, AFullDiskFailsNamingTheFileAndLeavesNoStats) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    const fs::path dir = folderWith("stats_full", {});
    fs::create_directories(dir);
    fs::create_symlink("/dev/full", dir / "stats.csv.partial");
    try {
        StatsWriter stats(dir / "stats.csv");
        FAIL() << "writing the header to /dev/full succeeded";
    } catch (const std::system_error& e) {
        EXPECT_EQ(std::string(e.what()), "cannot write " + (dir / "stats.csv.partial").string() +
                                             ": No space left on device");
    }
    EXPECT_TRUE(fs::is_empty(dir));
}

TEST(StatsWriter, FinishRenamesTheRowsIntoPlace) {
    const fs::path dir = folderWith("stats_ok", {});
    fs::create_directories(dir);
    StatsWriter stats(dir / "stats.csv");
    stats.append({1, 0.5, 1.0, 2.0, 3.0, 0.0, 7, 120, 2.5e-4});
    EXPECT_TRUE(stats.finish());
    EXPECT_FALSE(stats.finish());
    std::ifstream in(dir / "stats.csv");
    std::string header, row;
    std::getline(in, header);
    std::getline(in, row);
    EXPECT_EQ(header,
              "frame,time,kinetic_energy,strain_energy,max_speed,max_theta,broken_bonds,steps,dt");
    EXPECT_EQ(row, "1,0.5,1,2,3,0,7,120,0.00025");
    EXPECT_FALSE(fs::exists(dir / "stats.csv.partial"));
}

TEST(RunJson, ShadingIsTheLooksMaterialUnderTheScenesOwnKeys) {
    // The resolved scene has only the keys a file wrote; "shading" is what the renderers use,
    // which scripts/blender_import.py gives Cycles.
    const fs::path foil = fs::path(REND_SOURCE_DIR) / "scenes" / "foil_tear.toml";
    const std::string preset = shadingJson(loadScene(foil).render);
    EXPECT_NE(preset.find("\"look\": \"foil\""), std::string::npos) << preset;
    EXPECT_NE(preset.find("\"material\": \"conductor\""), std::string::npos) << preset;
    EXPECT_NE(preset.find("\"roughness\": 0.22"), std::string::npos) << preset;
    const std::string rough = shadingJson(loadScene(foil, {"render.roughness=0.5"}).render);
    EXPECT_NE(rough.find("\"roughness\": 0.5,"), std::string::npos) << rough;
    EXPECT_NE(rough.find("\"material\": \"conductor\""), std::string::npos) << rough;
}
