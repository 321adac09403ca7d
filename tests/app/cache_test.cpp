// Issue 14: the simulation cache's files read back whole, and anything else is refused by name.

#include "app/Cache.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <system_error>

#include "app/CacheWriter.h"
#include "tests/ScratchDir.h"

namespace fs = std::filesystem;
using namespace rend;

namespace {

fs::path freshDir(const char* name) {
    const fs::path dir = test::scratchDir() / name;
    fs::remove_all(dir);
    return dir;
}

/// A state with the texture of a real one: smooth doubles, runs of equal flags, and a tail
/// shorter than a word.
CacheFrame sampleFrame(int frame) {
    CacheFrame f{frame, 0.25 * frame, 0x1234abcdULL, 1000, {}};
    std::mt19937 random(7);
    for (int i = 0; i < 1000; ++i) {
        const double x = 0.001 * i + (random() % 2 ? 0.0 : 1e-6);
        const auto* p = reinterpret_cast<const std::byte*>(&x);
        f.state.insert(f.state.end(), p, p + sizeof x);
    }
    f.state.insert(f.state.end(), 3000, std::byte{1});
    f.state.insert(f.state.end(), {std::byte{9}, std::byte{8}, std::byte{7}});
    return f;
}

std::string slurp(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

void overwrite(const fs::path& file, const std::string& bytes) {
    std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

/// The message of the CacheError that reading `file` throws; empty when none.
std::string errorReading(const fs::path& dir, int frame) {
    try {
        readCacheFrameFor(dir, frame, 0x1234abcdULL, 1000);
    } catch (const CacheError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(Cache, AFrameReadsBackBitForBitAndCompressed) {
    const fs::path dir = freshDir("rend_cache_roundtrip");
    const CacheFrame written = sampleFrame(7);
    const std::uintmax_t bytes = writeCacheFrame(dir, written);
    EXPECT_EQ(fs::file_size(dir / cacheFileName(7)), bytes);
    EXPECT_LT(double(bytes), 0.6 * double(written.state.size())) << "the flags compress";
    EXPECT_FALSE(fs::exists(dir / "cache/frame_0007.rcache.tmp")) << "renamed into place";
    const CacheFrame read = readCacheFrameFor(dir, 7, 0x1234abcdULL, 1000);
    EXPECT_EQ(read.frame, 7);
    EXPECT_EQ(read.time, 1.75);
    EXPECT_EQ(read.state, written.state);
    EXPECT_EQ(cacheFileName(7), "cache/frame_0007.rcache");
}

// The buffers a run keeps between frames (kCacheBufferKept): a smaller state after a larger one,
// then a larger again, each reads back as written, with the bytes a first write of it gives.
TEST(Cache, FramesWrittenOneAfterAnotherReadBackAsWrittenAlone) {
    const fs::path dir = freshDir("rend_cache_sequence"), alone = freshDir("rend_cache_alone");
    CacheFrame large = sampleFrame(1), small = sampleFrame(2), larger = sampleFrame(3);
    small.state.resize(small.state.size() / 3);
    larger.state.insert(larger.state.end(), large.state.begin(), large.state.end());
    for (const CacheFrame* f : {&large, &small, &larger}) writeCacheFrame(dir, *f);
    for (const CacheFrame* f : {&large, &small, &larger}) {
        EXPECT_EQ(readCacheFrameFor(dir, f->frame, 0x1234abcdULL, 1000).state, f->state)
            << "frame " << f->frame;
        writeCacheFrame(alone, *f);
        EXPECT_EQ(slurp(dir / cacheFileName(f->frame)), slurp(alone / cacheFileName(f->frame)))
            << "frame " << f->frame << ": the same file as written alone";
    }
}

// The run's writes on a thread of their own (app/CacheWriter.h): the files of writeCacheFrame,
// one write in flight at a time, and the state's storage handed back for the next frame.
TEST(CacheWriter, WritesTheFilesOfTheRunsOwnWriteOneAtATime) {
    const fs::path dir = freshDir("rend_cache_writer"), alone = freshDir("rend_cache_writer1");
    CacheWriter writer(dir);
    EXPECT_FALSE(writer.wait()) << "nothing in flight";
    for (int frame = 1; frame <= 3; ++frame) {
        const CacheFrame f = sampleFrame(frame);
        writer.start(f);
        if (frame == 2) {
            EXPECT_THROW(writer.start(f), std::logic_error) << "one at a time";
        }
        const auto written = writer.wait();
        ASSERT_TRUE(written);
        EXPECT_EQ(written->frame, frame);
        EXPECT_EQ(written->bytes, writeCacheFrame(alone, f));
        EXPECT_EQ(slurp(dir / cacheFileName(frame)), slurp(alone / cacheFileName(frame)));
        const std::vector<std::byte> storage = writer.takeStorage();
        EXPECT_EQ(storage, f.state) << "the written state's storage comes back";
        EXPECT_TRUE(writer.takeStorage().empty()) << "once";
    }
    EXPECT_FALSE(writer.wait());
}

// A write that fails (here its temporary name is taken by a folder) is rethrown by the wait
// after it, naming the file; the writer goes on with the next frame, and a write nobody waits
// for is finished before the writer is gone.
TEST(CacheWriter, AFailedWriteIsRethrownByTheWaitAfterIt) {
    const fs::path dir = freshDir("rend_cache_writer_fail");
    fs::create_directories(dir / "cache/frame_0002.rcache.tmp/blocked");
    {
        CacheWriter writer(dir);
        writer.start(sampleFrame(2));
        try {
            writer.wait();
            FAIL() << "the write into a folder's name succeeded";
        } catch (const std::system_error& e) {
            EXPECT_NE(std::string(e.what()).find("frame_0002.rcache"), std::string::npos)
                << e.what();
        }
        EXPECT_FALSE(fs::exists(dir / cacheFileName(2)));
        EXPECT_FALSE(writer.wait()) << "the failure is reported once";
        writer.start(sampleFrame(3));
        ASSERT_TRUE(writer.wait());
        writer.start(sampleFrame(4));
    }
    EXPECT_EQ(readCacheFrameFor(dir, 4, 0x1234abcdULL, 1000).state, sampleFrame(4).state);
}

TEST(Cache, DamagedTruncatedAndForeignFilesAreRefusedByName) {
    const fs::path dir = freshDir("rend_cache_damage");
    writeCacheFrame(dir, sampleFrame(3));
    const fs::path file = dir / cacheFileName(3);
    const std::string good = slurp(file);
    const std::string name = file.string() + ": error: ";

    std::string flipped = good;
    flipped[good.size() / 2] = char(flipped[good.size() / 2] ^ 0x10);  // in the compressed state
    overwrite(file, flipped);
    EXPECT_NE(errorReading(dir, 3).find(name + "damaged"), std::string::npos)
        << errorReading(dir, 3);

    flipped = good;
    flipped[20] = char(flipped[20] ^ 1);  // in the header (the time)
    overwrite(file, flipped);
    EXPECT_NE(errorReading(dir, 3).find(name + "damaged: its header"), std::string::npos);

    for (const std::size_t length : {std::size_t(0), std::size_t(30), good.size() - 1}) {
        overwrite(file, good.substr(0, length));
        EXPECT_NE(errorReading(dir, 3).find(name + "truncated"), std::string::npos)
            << length << ": " << errorReading(dir, 3);
    }
    overwrite(file, "not a cache at all, but long enough to hold a header of sixty-four bytes");
    EXPECT_NE(errorReading(dir, 3).find("not a rend cache file"), std::string::npos);

    overwrite(file, good);
    EXPECT_EQ(errorReading(dir, 3), "");
    EXPECT_THROW(readCacheFrameFor(dir, 3, 0x999ULL, 1000), CacheError) << "another scene";
    EXPECT_THROW(readCacheFrameFor(dir, 3, 0x1234abcdULL, 999), CacheError) << "other particles";
    EXPECT_NE(errorReading(dir, 4).find("frame 4 is not in the cache"), std::string::npos);
}

TEST(Cache, TheLastCompleteFrameSkipsAKilledRunsDamagedTail) {
    const fs::path dir = freshDir("rend_cache_last");
    for (int frame = 1; frame <= 4; ++frame) writeCacheFrame(dir, sampleFrame(frame));
    const fs::path fourth = dir / cacheFileName(4);
    overwrite(fourth, slurp(fourth).substr(0, 100));
    EXPECT_EQ(lastCompleteCacheFrame(dir, 10, 0x1234abcdULL, 1000), 3);
    EXPECT_EQ(lastCompleteCacheFrame(dir, 2, 0x1234abcdULL, 1000), 2) << "within the run's frames";
    EXPECT_EQ(lastCompleteCacheFrame(dir, 10, 0x999ULL, 1000), std::nullopt) << "another scene's";
    std::string refused;
    EXPECT_EQ(lastCompleteCacheFrame(dir, 10, 0x1234abcdULL, 1000, &refused), 3);
    EXPECT_NE(refused.find(fourth.string() + ": error: "), std::string::npos) << refused;
    refused.clear();
    lastCompleteCacheFrame(dir, 10, 0x999ULL, 1000, &refused);
    EXPECT_NE(refused.find(fourth.string() + ": error: "), std::string::npos)
        << "the newest file's fault: " << refused;
}
