// Every allocation of 4 KiB or more starts on a 64-byte cache line (issue 16). The particle and
// pair arrays are std::vectors, which glibc's malloc starts 16 bytes into a line: every 512-bit
// load of the kernels (sim/PairKernels.h, sim/StepKernels.h) then spans two lines. Aligned,
// the whole step is about 3% faster (10.2 -> 9.9 ns per particle-step at 10^4 particles,
// 16.9 -> 16.6 at 10^6); the arithmetic, and so every bit of the state, is the same.
//
// Allocations of 4 MiB or more (the particle and pair arrays past 10^5 particles) start on a
// 2 MiB boundary and ask for transparent huge pages over their whole 2 MiB pages
// (madvise(MADV_HUGEPAGE): Debian's default THP setting is "madvise"). A step past the caches
// streams every array once; in 4 KiB pages each array crosses a page every 170 particles, each a
// TLB miss and a fresh start for the hardware prefetcher. 1,002,001 particles, interleaved:
// 12.0 -> 11.9 ns on one thread, 6.8 -> 6.5 on two. Where the system refuses, the pages are
// small as before.
//
// A 2 MiB page is given back at most once (below). A shot frees and allocates the same meshes and
// buffers every frame, and each large one had its pages given back and zeroed again by the
// kernel on the next touch: 36 MB a frame on the final foil with its PNGs and cache, in faults
// of fresh huge pages (`clear_page_erms` under the frame's surface, render and cache). Over 20
// frames on one thread (`perf`) the kernel's zeroing fell from 1.68 to 1.39 s; what is left is
// the set-up's first touch of its arrays and the first frames' growth.
//
// The replaceable global operator new, in the rend program and the programs that link
// rend_app (its benchmarks); the library's small allocations are left to malloc as they were.
// operator delete pairs with it through free(), which takes memory from either.

#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <new>
#include <set>

namespace {

constexpr std::size_t kAlignedFrom = 4096;
constexpr std::size_t kLine = 64;
constexpr std::size_t kHugePage = std::size_t(2) << 20, kHugeFrom = std::size_t(4) << 20;

// Asks for huge pages over [p, p + bytes), whole 2 MiB pages. A block malloc carves from memory
// it has used before (the set-up's freed maps and lists: 2.2 of a 10^7 sheet's 11 GB) already
// has small pages, which the hint alone leaves small: they are given back first (a new block's
// contents are undefined, so nothing is lost), and the next touch faults in huge ones
// (crack_path_sources, 10^7 particles, linear, one thread: 19.3 -> 16.1 and 20.0 -> 14.4 ns per
// particle-step; 10^6: 13.6 -> 13.3). Hints only: where the system refuses, the pages stay as
// they were.
//
// Each 2 MiB page is given back once: after that it is huge (or the system had none to give)
// for as long as malloc keeps it. Where malloc unmaps a block, memory mapped there later is fresh,
// untouched, and huge on its first touch with the hint alone. Only memory malloc gives back from
// the heap's top and takes again, then touched by small blocks before a large one reuses it, is
// left in small pages: a slower step, the same results.
void giveHugePages(void* p, std::size_t bytes) {
    madvise(p, bytes, MADV_HUGEPAGE);
    static std::mutex lock;
    static auto* givenBack = new std::set<std::uintptr_t>;  // never destroyed: used until exit
    const std::uintptr_t first = reinterpret_cast<std::uintptr_t>(p) / kHugePage;
    const std::uintptr_t last = first + bytes / kHugePage;
    const std::lock_guard<std::mutex> hold(lock);
    for (std::uintptr_t page = first; page < last;) {
        if (!givenBack->insert(page).second) {
            ++page;
            continue;
        }
        std::uintptr_t end = page + 1;  // the run of pages not given back yet, at once
        while (end < last && givenBack->insert(end).second) ++end;
        madvise(reinterpret_cast<void*>(page * kHugePage), (end - page) * kHugePage, MADV_DONTNEED);
        page = end;  // given back before, or last
    }
}

}  // namespace

void* operator new(std::size_t bytes) {
    void* p = nullptr;
    if (bytes >= kHugeFrom) {
        if (posix_memalign(&p, kHugePage, bytes) != 0) throw std::bad_alloc();
        giveHugePages(p, bytes / kHugePage * kHugePage);
        return p;
    }
    if (bytes >= kAlignedFrom) {
        if (posix_memalign(&p, kLine, bytes) != 0) throw std::bad_alloc();
        return p;
    }
    p = std::malloc(bytes == 0 ? 1 : bytes);
    if (p == nullptr) throw std::bad_alloc();
    return p;
}

void operator delete(void* p) noexcept { std::free(p); }

void operator delete(void* p, std::size_t) noexcept { std::free(p); }
