#include "render/AtomicFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace rend::render {

OutputFile::OutputFile(const std::filesystem::path& path) : path_(path) {
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) fail(errno);
}

OutputFile::~OutputFile() {
    if (fd_ >= 0) ::close(fd_);
}

void OutputFile::fail(int error) const {
    throw std::system_error(error, std::generic_category(), "cannot write " + path_.string());
}

void OutputFile::write(std::string_view bytes) {
    while (!bytes.empty()) {
        const ssize_t done = ::write(fd_, bytes.data(), bytes.size());
        if (done < 0 && errno == EINTR) continue;
        // write() returns 0 only for a zero-byte request; treat it as "no space" rather than spin.
        if (done <= 0) fail(done < 0 ? errno : ENOSPC);
        bytes.remove_prefix(std::size_t(done));
    }
}

void OutputFile::close() {
    const int fd = fd_;
    fd_ = -1;
    // A network file system may report a failed write only here.
    if (::close(fd) != 0 && errno != EINTR) fail(errno);
}

std::filesystem::path temporaryName(const std::filesystem::path& path) {
    std::filesystem::path tmp = path;
    tmp += ".tmp";
    return tmp;
}

void writeFileAtomic(const std::filesystem::path& path, std::string_view bytes) {
    const std::filesystem::path tmp = temporaryName(path);
    std::error_code ec;
    try {
        OutputFile file(tmp);
        file.write(bytes);
        file.close();
        std::filesystem::rename(tmp, path, ec);
    } catch (const std::system_error& e) {
        ec = e.code();
    }
    if (!ec) return;
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::system_error(ec, "cannot write " + path.string());
}

}  // namespace rend::render
