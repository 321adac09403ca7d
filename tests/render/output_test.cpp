// Checked output files (render/AtomicFile.h): a write that fails names the file and the reason
// and leaves nothing under the final name.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <system_error>

#include "render/AtomicFile.h"
#include "render/Image.h"
#include "render/MeshExport.h"

namespace fs = std::filesystem;
using rend::render::OutputFile;
using rend::render::writeFileAtomic;

namespace {

fs::path freshDir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / "rend_output_test" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string errorOf(const std::function<void()>& write) {
    try {
        write();
    } catch (const std::system_error& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(OutputFile, AFullDeviceFailsNamingTheFileAndTheReason) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    const std::string message = errorOf([] {
        OutputFile file("/dev/full");
        file.write(std::string(1 << 16, 'x'));
        file.close();
    });
    EXPECT_EQ(message, "cannot write /dev/full: No space left on device");
}

TEST(OutputFile, WritesEveryByte) {
    const fs::path path = freshDir("bytes") / "data.bin";
    std::string bytes(3'000'000, '\0');
    for (std::size_t k = 0; k < bytes.size(); ++k) bytes[k] = char(k * 7);
    OutputFile file(path);
    file.write(bytes);
    file.close();
    std::ifstream in(path, std::ios::binary);
    const std::string back((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(back, bytes);
}

TEST(WriteFileAtomic, AFailedWriteLeavesTheOldFileAndNoTemporary) {
    const fs::path dir = freshDir("atomic");
    writeFileAtomic(dir / "run.json", "old");
    // A folder where the temporary file should go makes the open fail.
    fs::create_directories(dir / "run.json.tmp");
    const std::string message = errorOf([&] { writeFileAtomic(dir / "run.json", "new"); });
    EXPECT_EQ(message.rfind("cannot write " + (dir / "run.json").string() + ": ", 0), 0u)
        << message;
    std::ifstream in(dir / "run.json");
    std::string text;
    in >> text;
    EXPECT_EQ(text, "old");
}

TEST(WriteFileAtomic, AMissingFolderFailsAndCreatesNothing) {
    const fs::path dir = freshDir("missing");
    EXPECT_NE(errorOf([&] {
                  writeFileAtomic(dir / "nope" / "a.png", "x");
              }).find("No such file or directory"),
              std::string::npos);
    EXPECT_TRUE(fs::is_empty(dir));
}

TEST(MeshExport, ObjReturnsItsMaterialLibraryFirstAndItselfLast) {
    const fs::path dir = freshDir("obj");
    rend::render::Mesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.triangles = {{0, 1, 2}};
    const auto written =
        rend::render::exportMesh(mesh, dir / "frame_0001.obj", rend::render::MeshFormat::Obj);
    ASSERT_EQ(written.size(), 2u);
    EXPECT_EQ(written[0], dir / "frame_0001.mtl");
    EXPECT_EQ(written[1], dir / "frame_0001.obj");
    for (const auto& file : written) EXPECT_GT(fs::file_size(file), 0u) << file;
}
