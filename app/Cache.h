#pragma once
// The simulation cache: cache/frame_NNNN.rcache in a run's output folder, one file per cached
// frame, each holding the membrane's whole evolving state at the frame's end
// (sim::Membrane::saveState), from which a run resumes (rend run --resume) and a frame is
// rendered or exported again without simulating (rend render).
//
// Format (little-endian), chosen over HDF5 and OpenVDB points because the state is a handful of
// flat arrays read back whole, and zstd is one small, well-kept Debian library:
//   the 64-byte header: "RENDCACH", u32 format version, u32 frame, f64 time,
//     u64 the scene's simulation fingerprint, u64 particles, u64 state bytes, u64 compressed
//     bytes, u64 FNV-1a of the 56 bytes before it;
//   then the state, byte-shuffled by 8 (each double's bytes grouped, so the slowly changing high
//   bytes of neighbours compress together) and compressed by zstd with its content checksum.
// A file is written to NAME.tmp and renamed, so it is complete or absent. Reading checks the
// header's hash, the sizes and zstd's checksum, and names the file and what is wrong.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/SceneError.h"

namespace rend {

/// A cache file that cannot be used: damaged, truncated, or written for another scene. Bad
/// input, as a scene error is (exit status 2).
struct CacheError : SceneError {
    using SceneError::SceneError;
};

struct CacheFrame {
    int frame = 0;
    double time = 0.0;
    std::uint64_t fingerprint = 0;
    std::uint64_t particles = 0;
    std::vector<std::byte> state;
};

/// The scene file and --set values of the run that wrote the cache, for rend render.
inline constexpr const char* kCacheSourceName = "cache/source.toml";

/// "cache/frame_0007.rcache", relative to the output folder.
std::string cacheFileName(int frame);

/// The largest buffer a run keeps from one cached frame to the next (its state, shuffled and
/// compressed), so that it is not allocated, and its pages zeroed, again; larger ones are freed
/// after each write, so a huge sheet holds no copies of its state while it renders.
inline constexpr std::size_t kCacheBufferKept = std::size_t(256) << 20;

/// Writes `frame` atomically under outDir / cacheFileName(frame.frame); returns its size in
/// bytes. Throws std::system_error naming the file (a full disk). zstd's level 1: on the final
/// foil's shuffled state 0.5% larger than level 3 and 1.5 times as fast (1,195 against 812 MB/s,
/// `zstd -b1 -e3`).
std::uintmax_t writeCacheFrame(const std::filesystem::path& outDir, const CacheFrame& frame,
                               int compressionLevel = 1);

/// Reads and checks one cache file. Throws CacheError naming the file and the fault.
CacheFrame readCacheFrame(const std::filesystem::path& file);

/// Reads outDir's cache of `frame` and checks it belongs to the scene of `fingerprint` and
/// `particles`. Throws CacheError naming the file, what it found and the fix.
CacheFrame readCacheFrameFor(const std::filesystem::path& outDir, int frame,
                             std::uint64_t fingerprint, std::uint64_t particles);

/// The highest frame <= `upTo` whose cache file reads back whole for this scene; nullopt when
/// none does. Damaged or foreign files are skipped (a killed run's last file may be either);
/// the newest one's fault goes to `newestRefused` when given (a cache of another format, say).
std::optional<int> lastCompleteCacheFrame(const std::filesystem::path& outDir, int upTo,
                                          std::uint64_t fingerprint, std::uint64_t particles,
                                          std::string* newestRefused = nullptr);

}  // namespace rend
