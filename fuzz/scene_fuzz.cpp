// libFuzzer target over the scene loader and --set (README "Tests and benchmarks"; run by
// scripts/fuzz.sh). A SceneError is the loader doing its job; any other exception, a crash, a
// leak, undefined behaviour or a hang is a finding.

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>

#include "app/Scene.h"
#include "app/SceneError.h"
#include "fuzz/FuzzInput.h"

namespace {

/// The loader reads a path, as `rend` does, so the scene goes through a file of this process.
class SceneFile {
public:
    SceneFile()
        : path_(std::filesystem::temp_directory_path() /
                ("rend_fuzz_" + std::to_string(::getpid()) + ".toml")) {}
    ~SceneFile() {
        std::error_code ignored;
        std::filesystem::remove(path_, ignored);
    }
    const std::filesystem::path& write(const std::string& text) {
        std::ofstream(path_, std::ios::binary | std::ios::trunc) << text;
        return path_;
    }

private:
    std::filesystem::path path_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static SceneFile file;
    const rend::fuzz::FuzzInput input =
        rend::fuzz::splitFuzzInput({reinterpret_cast<const char*>(data), size});
    try {
        rend::loadScene(file.write(input.scene), input.sets);
    } catch (const rend::SceneError&) {
    }
    return 0;
}
