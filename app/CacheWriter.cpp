#include "app/CacheWriter.h"

#include <stdexcept>
#include <utility>

namespace rend {

CacheWriter::CacheWriter(std::filesystem::path outDir) : outDir_(std::move(outDir)) {}

CacheWriter::~CacheWriter() {
    {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return !job_ && !busy_; });
        stop_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void CacheWriter::start(CacheFrame frame) {
    {
        std::lock_guard lock(mutex_);
        if (job_ || busy_ || done_ || failure_)
            throw std::logic_error("CacheWriter::start: the last write was not waited for");
        job_ = std::move(frame);
    }
    if (!thread_.joinable()) thread_ = std::thread(&CacheWriter::work, this);
    changed_.notify_all();
}

std::optional<CacheWriter::Written> CacheWriter::wait() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !job_ && !busy_; });
    if (std::exception_ptr failure = std::exchange(failure_, nullptr))
        std::rethrow_exception(failure);
    return std::exchange(done_, std::nullopt);
}

// The thread's own buffers (writeCacheFrame's) live as long as the run: one thread writes every
// frame.
void CacheWriter::work() {
    std::unique_lock lock(mutex_);
    for (;;) {
        changed_.wait(lock, [&] { return job_ || stop_; });
        if (!job_) return;
        CacheFrame frame = std::move(*job_);
        job_.reset();
        busy_ = true;
        lock.unlock();
        std::optional<Written> written;
        std::exception_ptr failure;
        try {
            written = Written{frame.frame, writeCacheFrame(outDir_, frame)};
        } catch (...) {
            failure = std::current_exception();
        }
        if (frame.state.capacity() > kCacheBufferKept) frame.state = std::vector<std::byte>();
        lock.lock();
        done_ = written;
        failure_ = failure;
        storage_ = std::move(frame.state);
        busy_ = false;
        changed_.notify_all();
    }
}

}  // namespace rend
