#pragma once
// Output files whose every write and close is checked. A full disk (ENOSPC), a file size limit
// (EFBIG) or an I/O error becomes an exception naming the file and the reason, never a
// truncated file under its final name.
//
// Files are not fsync'ed: the rename makes a file appear complete or not at all to anyone who
// reads the folder while or after rend runs (a killed run included), which is the promise; a
// power cut may still lose the last files, as with Blender's and Houdini's frame writers, and an
// fsync per frame would cost more than the write on a network disk.

#include <filesystem>
#include <string_view>

namespace rend::render {

/// A file written front to back; throws std::system_error ("cannot write PATH: REASON") when
/// opening, a write or the close fails.
class OutputFile {
public:
    explicit OutputFile(const std::filesystem::path& path);
    ~OutputFile();  ///< closes without a check when close() was not called (an error path)
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;

    void write(std::string_view bytes);
    void close();
    const std::filesystem::path& path() const { return path_; }

private:
    [[noreturn]] void fail(int error) const;

    std::filesystem::path path_;
    int fd_ = -1;
};

/// Writes `bytes` to path + ".tmp" and renames it over `path`. On failure the temporary file is
/// removed, `path` is left as it was, and std::system_error names `path` and the reason.
void writeFileAtomic(const std::filesystem::path& path, std::string_view bytes);

/// path + ".tmp", the name a file has until it is complete.
std::filesystem::path temporaryName(const std::filesystem::path& path);

}  // namespace rend::render
