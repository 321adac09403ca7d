// sim/Parallel.h: a loop wakes the OpenMP team only where it is wide enough and more than one
// thread would run it; else it runs on the calling thread, outside any parallel region (libgomp
// ends even a team of one with a system call). Either way every index is visited once and the
// maxima are the same.

#include "sim/Parallel.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <vector>

using namespace rend::sim;

namespace {

/// Sets the OpenMP thread count for one test and puts it back.
class Threads {
public:
    explicit Threads(int n) : before_(omp_get_max_threads()) { omp_set_num_threads(n); }
    ~Threads() { omp_set_num_threads(before_); }

private:
    int before_;
};

/// How many of forEachIndex's calls of body ran inside a parallel region, over [0, n).
int callsInRegion(bool wide, int n, std::vector<int>& visits) {
    std::atomic<int> inside{0};
    visits.assign(std::size_t(n), 0);
    forEachIndex(wide, 0, n, [&](int i) {
        ++visits[std::size_t(i)];
        if (omp_in_parallel()) ++inside;
    });
    return inside.load();
}

}  // namespace

TEST(Parallel, OneThreadNeverEntersAParallelRegion) {
    const Threads one(1);
    std::vector<int> visits;
    EXPECT_FALSE(wakesTeam(true));
    EXPECT_EQ(callsInRegion(true, 5000, visits), 0);
    for (int v : visits) ASSERT_EQ(v, 1);
    int teamSize = 0;
    inTeam(true, [&] { teamSize = omp_get_num_threads() + (omp_in_parallel() ? 100 : 0); });
    EXPECT_EQ(teamSize, 1) << "body ran once, on this thread";
}

TEST(Parallel, TwoThreadsWakeTheTeamOnlyForAWideLoop) {
    const Threads two(2);
    std::vector<int> visits;
    EXPECT_TRUE(wakesTeam(true));
    EXPECT_FALSE(wakesTeam(false));
    EXPECT_EQ(callsInRegion(false, 3000, visits), 0) << "a narrow loop stays on this thread";
    for (int v : visits) ASSERT_EQ(v, 1);
    EXPECT_EQ(callsInRegion(true, 3000, visits), 3000) << "a wide loop runs in the team";
    for (int v : visits) ASSERT_EQ(v, 1);
    std::atomic<int> bodies{0};
    inTeam(true, [&] { ++bodies; });
    EXPECT_EQ(bodies.load(), omp_get_max_threads());
}

TEST(Parallel, MaximaAreTheSameForAnyThreadCount) {
    std::vector<double> values(10007);
    for (std::size_t k = 0; k < values.size(); ++k)
        values[k] = double((k * 7919) % 10007) - 5000.0;  // largest 5006 at one index
    const auto largest = [&](bool wide, double most) {
        return largestOverIndices(wide, 0, int(values.size()), most, [&](int i, double& m) {
            m = std::max(m, values[std::size_t(i)]);
        });
    };
    const auto largestOfTeams = [&](bool wide, double most) {
        return largestInTeam(wide, most, [&](double& m) {
            const int t = omp_get_thread_num(), threads = omp_get_num_threads();
            const int n = int(values.size());
            for (int i = n * t / threads; i < n * (t + 1) / threads; ++i)
                m = std::max(m, values[std::size_t(i)]);
        });
    };
    for (int threads : {1, 2}) {
        const Threads set(threads);
        for (bool wide : {false, true}) {
            EXPECT_EQ(largest(wide, -1e300), 5006.0) << threads << " threads";
            EXPECT_EQ(largest(wide, 7000.0), 7000.0) << "the starting value counts";
            EXPECT_EQ(largestOfTeams(wide, -1e300), 5006.0) << threads << " threads";
            EXPECT_EQ(largestOfTeams(wide, 7000.0), 7000.0);
        }
    }
}
