#pragma once
// The cache's writes on a thread of their own (issue 16): a cached frame is shuffled, compressed
// and written (writeCacheFrame) while the membrane simulates the next frame. The kernel's copy
// into its page cache and zstd were a fifth of a final-quality shot on one core, all of it while
// every simulation thread waited.
//
// One write is in flight at a time, and the run waits for it (wait) before it writes anything of
// the next frame, its stats.csv row included: the files appear in the order they did when the
// write was the run's own, and a failed write (a full disk) stops the run at the same frame, with
// the same files written. A run killed mid-write loses that frame's cache file as it did: the
// file is written under a temporary name and renamed (render::writeFileAtomic).

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "app/Cache.h"

namespace rend {

class CacheWriter {
public:
    struct Written {
        int frame = 0;
        std::uintmax_t bytes = 0;
    };

    explicit CacheWriter(std::filesystem::path outDir);
    /// Waits for the write in flight; a failure nobody waited for is dropped (the run is already
    /// failing).
    ~CacheWriter();
    CacheWriter(const CacheWriter&) = delete;
    CacheWriter& operator=(const CacheWriter&) = delete;

    /// Starts writing `frame`. Call wait() first: one write is in flight at a time.
    void start(CacheFrame frame);
    /// Waits for the write in flight: the frame and bytes written, or nothing when none was in
    /// flight. Rethrows the write's failure (std::system_error naming the file).
    std::optional<Written> wait();
    /// After wait(): the last written frame's state storage, for Membrane::saveState's `reuse`:
    /// kept when it is at most kCacheBufferKept, so a huge sheet holds no copy of its state while
    /// it renders.
    std::vector<std::byte> takeStorage() { return std::move(storage_); }

private:
    void work();

    std::filesystem::path outDir_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::optional<CacheFrame> job_;  // the frame in flight, set by start
    bool busy_ = false;              // job_ taken and not yet written
    bool stop_ = false;
    std::optional<Written> done_;
    std::exception_ptr failure_;
    std::vector<std::byte> storage_;
    std::thread thread_;  // started by the first start(), so a run without a cache has none
};

}  // namespace rend
