#include "app/Cache.h"

#include <zstd.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>

#include "render/AtomicFile.h"

namespace rend {

namespace {

constexpr char kMagic[8] = {'R', 'E', 'N', 'D', 'C', 'A', 'C', 'H'};
constexpr std::uint32_t kFormatVersion = 3;  // 2: the particle level set (issue 15); 3: the
// elastoplastic history once per bond (sim/PeridynamicBonds.cpp)
constexpr std::size_t kHeaderBytes = 64;
constexpr std::size_t kShuffle = 8;

struct Header {
    std::uint32_t version = kFormatVersion;
    std::uint32_t frame = 0;
    double time = 0.0;
    std::uint64_t fingerprint = 0, particles = 0, stateBytes = 0, compressedBytes = 0;
};

std::uint64_t fnv1a(const unsigned char* p, std::size_t n) {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    for (std::size_t k = 0; k < n; ++k) h = (h ^ p[k]) * 0x100000001b3ULL;
    return h;
}

template <class T>
void put(std::array<unsigned char, kHeaderBytes>& out, std::size_t& at, const T& value) {
    std::memcpy(out.data() + at, &value, sizeof value);
    at += sizeof value;
}

template <class T>
void get(const unsigned char* in, std::size_t& at, T& value) {
    std::memcpy(&value, in + at, sizeof value);
    at += sizeof value;
}

std::array<unsigned char, kHeaderBytes> encode(const Header& h) {
    std::array<unsigned char, kHeaderBytes> out{};
    std::size_t at = 0;
    std::memcpy(out.data(), kMagic, sizeof kMagic);
    at += sizeof kMagic;
    put(out, at, h.version), put(out, at, h.frame), put(out, at, h.time);
    put(out, at, h.fingerprint), put(out, at, h.particles), put(out, at, h.stateBytes);
    put(out, at, h.compressedBytes);
    put(out, at, fnv1a(out.data(), at));
    return out;
}

/// Groups byte k of every 8-byte word together (the tail, shorter than a word, stays as it is),
/// into out[0, in.size()).
void shuffle(std::span<const std::byte> in, std::byte* out) {
    const std::size_t words = in.size() / kShuffle;
    for (std::size_t w = 0; w < words; ++w)
        for (std::size_t k = 0; k < kShuffle; ++k) out[k * words + w] = in[w * kShuffle + k];
    std::copy(in.begin() + std::ptrdiff_t(words * kShuffle), in.end(), out + words * kShuffle);
}

/// A buffer kept between frames, grown but never filled: a frame's tens of megabytes allocated
/// afresh were zeroed page by page by the kernel, and the compressor's bound zeroed again by
/// std::string (the shipped foil at final quality: 8% of a run's samples).
struct Scratch {
    std::unique_ptr<std::byte[]> data;
    std::size_t size = 0;
    std::byte* atLeast(std::size_t n) {
        if (n > size) data = std::make_unique_for_overwrite<std::byte[]>(n), size = n;
        return data.get();
    }
    /// After a write: kept up to kCacheBufferKept.
    void settle() {
        if (size > kCacheBufferKept) data.reset(), size = 0;
    }
};

struct ContextFree {
    void operator()(ZSTD_CCtx* context) const { ZSTD_freeCCtx(context); }
};

std::vector<std::byte> unshuffled(std::span<const std::byte> in) {
    std::vector<std::byte> out(in.size());
    const std::size_t words = in.size() / kShuffle;
    for (std::size_t w = 0; w < words; ++w)
        for (std::size_t k = 0; k < kShuffle; ++k) out[w * kShuffle + k] = in[k * words + w];
    std::copy(in.begin() + std::ptrdiff_t(words * kShuffle), in.end(),
              out.begin() + std::ptrdiff_t(words * kShuffle));
    return out;
}

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
    throw CacheError(file.string() + ": error: " + what +
                     ". Delete it and rerun rend run into this folder (with --resume it "
                     "continues from the last whole frame before it).");
}

}  // namespace

std::string cacheFileName(int frame) {
    char name[40];
    std::snprintf(name, sizeof name, "cache/frame_%04d.rcache", frame);
    return name;
}

std::uintmax_t writeCacheFrame(const std::filesystem::path& outDir, const CacheFrame& frame,
                               int compressionLevel) {
    thread_local Scratch plain, packed;
    thread_local std::unique_ptr<ZSTD_CCtx, ContextFree> context{ZSTD_createCCtx()};
    if (!context) throw std::runtime_error("zstd: cannot create a compression context");
    const std::size_t size = frame.state.size();
    shuffle(frame.state, plain.atLeast(size));
    const std::size_t bound = ZSTD_compressBound(size);
    std::byte* const bytes = packed.atLeast(kHeaderBytes + bound);
    ZSTD_CCtx_reset(context.get(), ZSTD_reset_session_and_parameters);
    ZSTD_CCtx_setParameter(context.get(), ZSTD_c_compressionLevel, compressionLevel);
    ZSTD_CCtx_setParameter(context.get(), ZSTD_c_checksumFlag, 1);
    const std::size_t compressed =
        ZSTD_compress2(context.get(), bytes + kHeaderBytes, bound, plain.data.get(), size);
    if (ZSTD_isError(compressed))
        throw std::runtime_error("zstd: " + std::string(ZSTD_getErrorName(compressed)));
    Header h;
    h.frame = std::uint32_t(frame.frame);
    h.time = frame.time;
    h.fingerprint = frame.fingerprint;
    h.particles = frame.particles;
    h.stateBytes = frame.state.size();
    h.compressedBytes = compressed;
    const auto header = encode(h);
    std::memcpy(bytes, header.data(), kHeaderBytes);
    const std::filesystem::path path = outDir / cacheFileName(frame.frame);
    std::filesystem::create_directories(path.parent_path());
    plain.settle();
    render::writeFileAtomic(path,
                            {reinterpret_cast<const char*>(bytes), kHeaderBytes + compressed});
    packed.settle();
    return kHeaderBytes + compressed;
}

CacheFrame readCacheFrame(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) fail(file, "cannot open the cache file");
    const std::string bytes{std::istreambuf_iterator<char>(in), {}};
    const auto* raw = reinterpret_cast<const unsigned char*>(bytes.data());
    if (bytes.size() < kHeaderBytes)
        fail(file, "truncated: " + std::to_string(bytes.size()) + " bytes, shorter than a header");
    if (std::memcmp(raw, kMagic, sizeof kMagic) != 0) fail(file, "not a rend cache file");
    Header h;
    std::size_t at = sizeof kMagic;
    std::uint64_t stored = 0;
    get(raw, at, h.version), get(raw, at, h.frame), get(raw, at, h.time);
    get(raw, at, h.fingerprint), get(raw, at, h.particles), get(raw, at, h.stateBytes);
    get(raw, at, h.compressedBytes);
    const std::uint64_t expected = fnv1a(raw, at);
    get(raw, at, stored);
    if (stored != expected) fail(file, "damaged: its header's checksum does not match");
    if (h.version != kFormatVersion)
        throw CacheError(file.string() + ": error: written by cache format " +
                         std::to_string(h.version) + ", this rend reads " +
                         std::to_string(kFormatVersion) +
                         ": another version of rend wrote it. Rerun rend run into this folder "
                         "without --resume (it writes the cache again), or finish the shot with "
                         "the rend that wrote it.");
    if (bytes.size() - kHeaderBytes != h.compressedBytes)
        fail(file, "truncated or extended: " + std::to_string(bytes.size() - kHeaderBytes) +
                       " bytes of state, the header says " + std::to_string(h.compressedBytes));
    std::vector<std::byte> plain(h.stateBytes);
    const std::size_t got =
        ZSTD_decompress(plain.data(), plain.size(), raw + kHeaderBytes, h.compressedBytes);
    if (ZSTD_isError(got)) fail(file, "damaged: " + std::string(ZSTD_getErrorName(got)));
    if (got != h.stateBytes) fail(file, "damaged: the state is shorter than its header says");
    return {int(h.frame), h.time, h.fingerprint, h.particles, unshuffled(plain)};
}

CacheFrame readCacheFrameFor(const std::filesystem::path& outDir, int frame,
                             std::uint64_t fingerprint, std::uint64_t particles) {
    const std::filesystem::path file = outDir / cacheFileName(frame);
    if (!std::filesystem::exists(file))
        throw CacheError(file.string() + ": error: frame " + std::to_string(frame) +
                         " is not in the cache. Run rend run (with --cache-every 1 to cache "
                         "every frame) into " +
                         outDir.string() + " first.");
    CacheFrame cached = readCacheFrame(file);
    if (cached.fingerprint != fingerprint || cached.particles != particles)
        throw CacheError(file.string() + ": error: written for another scene or other --set " +
                         "values (" + std::to_string(cached.particles) + " particles; this scene " +
                         std::to_string(particles) +
                         "). Use the scene and --set values of that run, or rerun rend run.");
    if (cached.frame != frame) fail(file, "holds frame " + std::to_string(cached.frame));
    return cached;
}

std::optional<int> lastCompleteCacheFrame(const std::filesystem::path& outDir, int upTo,
                                          std::uint64_t fingerprint, std::uint64_t particles,
                                          std::string* newestRefused) {
    for (int frame = upTo; frame >= 1; --frame) {
        if (!std::filesystem::exists(outDir / cacheFileName(frame))) continue;
        try {
            readCacheFrameFor(outDir, frame, fingerprint, particles);
            return frame;
        } catch (const CacheError& e) {
            if (newestRefused && newestRefused->empty()) *newestRefused = e.what();
        }
    }
    return std::nullopt;
}

}  // namespace rend
