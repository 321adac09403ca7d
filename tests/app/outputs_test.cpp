// The output folder's bookkeeping (app/Outputs.h): which names rend may remove, and how a rerun
// replaces the previous run's files.

#include "app/Outputs.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

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
          "meshes/frame_0002.mtl", "vdb/frame_0003.vdb"})
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
