#pragma once
// Where a test writes its files: a folder of its own under the system's temporary folder,
// named after the running test and this process, so that tests run side by side (ctest -j,
// two CI jobs on one machine) never read each other's files.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace rend::test {

/// The folder last handed out; removed when the process ends if every test passed, kept for a
/// look when one failed.
struct ScratchRoot {
    std::string path;
    ~ScratchRoot() { dropIfPassed(); }
    void dropIfPassed() const {
        std::error_code ignored;
        if (!path.empty() && ::testing::UnitTest::GetInstance()->Passed())
            std::filesystem::remove_all(path, ignored);
    }
};

/// temp/rend_tests/<Suite>.<Test>.<pid>/<leaf>, created empty on the first call of each test.
inline std::filesystem::path scratchDir(const std::string& leaf = "") {
    namespace fs = std::filesystem;
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const std::string test =
        info ? std::string(info->test_suite_name()) + "." + info->name() : "no_test";
    const fs::path root = fs::temp_directory_path() / "rend_tests" /
                          (test + "." + std::to_string(static_cast<long>(::getpid())));
    static ScratchRoot made;  // the test whose folder was last emptied
    if (made.path != root.string()) {
        made.dropIfPassed();
        fs::remove_all(root);
        made.path = root.string();
    }
    const fs::path dir = leaf.empty() ? root : root / leaf;
    fs::create_directories(dir);
    return dir;
}

}  // namespace rend::test
