#include "render/VdbIo.h"

#include <openvdb/io/Archive.h>

#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>

#include "render/AtomicFile.h"

namespace rend::render::vdb {
namespace {

// io::File writes through an std::ofstream whose state it never checks, so a full disk leaves a
// truncated .vdb. The same archive (seekable, as io::File writes it) goes into memory instead,
// and writeFileAtomic puts it on disk with every write checked.
class MemoryArchive : public openvdb::io::Archive {
public:
    void writeTo(std::ostream& out, const openvdb::GridCPtrVec& grids) const {
        Archive::write(out, grids, /*seekable=*/true);
    }
};

}  // namespace

void initialize() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

void writeGridsAtomic(const std::filesystem::path& path, const openvdb::GridCPtrVec& grids) {
    std::ostringstream bytes(std::ios::binary);
    try {
        MemoryArchive().writeTo(bytes, grids);
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write " + path.string() + ": " + e.what());
    }
    writeFileAtomic(path, bytes.view());
}

}  // namespace rend::render::vdb
