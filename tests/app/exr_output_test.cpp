// [output] exr: the path tracer's EXR frame beside the PNG, listed in run.json; refused with the
// osmesa renderer, which has no linear radiance to write.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/Pipeline.h"
#include "app/SceneError.h"
#include "render/ExrWriter.h"

namespace fs = std::filesystem;

namespace {

rend::Scene tinyScene(const std::string& renderer) {
    return rend::loadScene(
        REND_SOURCE_DIR "/scenes/stretch.toml",
        {"sheet.size=[0.6,0.6]", "time.duration=0.125", "render.width=48", "render.height=27",
         "render.spp=2", "render.renderer=\"" + renderer + "\"", "output.exr=true",
         "output.stats=false"});
}

}  // namespace

TEST(ExrOutput, ThePathTracerWritesAnExrBesideEachPngAndListsIt) {
    const fs::path dir = fs::temp_directory_path() / "rend_exr_output_test";
    fs::remove_all(dir);
    rend::RunOptions options;
    options.outDir = dir;
    options.frames = {1};
    rend::runScene(tinyScene("embree"), options);
    const rend::render::ExrChannels exr = rend::render::readExr(dir / "frames/frame_0001.exr");
    EXPECT_EQ(exr.width, 48);
    EXPECT_EQ(exr.height, 27);
    for (const char* channel : {"R", "G", "B", "Z", "N.X", "N.Y", "N.Z"})
        EXPECT_EQ(exr.channels.count(channel), 1u) << channel;
    std::stringstream json;
    json << std::ifstream(dir / "run.json").rdbuf();
    EXPECT_NE(json.str().find("\"frames/frame_0001.exr\""), std::string::npos) << json.str();
    EXPECT_TRUE(fs::exists(dir / "frames/frame_0001.png"));
    fs::remove_all(dir);
}

TEST(ExrOutput, TheOsmesaRendererRefusesExrNamingTheKey) {
    rend::RunOptions options;
    options.outDir = fs::temp_directory_path() / "rend_exr_output_refused";
    try {
        rend::runScene(tinyScene("osmesa"), options);
        FAIL() << "osmesa with exr = true ran";
    } catch (const rend::SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("output.exr: expected the path tracer"),
                  std::string::npos)
            << e.what();
    }
    fs::remove_all(options.outDir);
}
