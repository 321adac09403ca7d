// The default thread count (app/Threads.h): the cores a cgroup quota grants, the cores this
// process may use, and the governor that gives cores up to other processes.

#include "app/Threads.h"

#include <gtest/gtest.h>
#include <omp.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <thread>

TEST(Threads, ACgroupQuotaGrantsItsCeilingOfCores) {
    EXPECT_EQ(rend::coresFromCpuMax("max 100000"), 0);  // no limit
    EXPECT_EQ(rend::coresFromCpuMax("max 100000\n"), 0);
    EXPECT_EQ(rend::coresFromCpuMax("200000 100000\n"), 2);
    EXPECT_EQ(rend::coresFromCpuMax("150000 100000"), 2);  // one and a half cores: 2 threads
    EXPECT_EQ(rend::coresFromCpuMax("50000 100000"), 1);   // half a core: still one thread
    EXPECT_EQ(rend::coresFromCpuMax("400000 100000"), 4);
    EXPECT_EQ(rend::coresFromCpuMax(""), 0);
    EXPECT_EQ(rend::coresFromCpuMax("lots"), 0);
    EXPECT_EQ(rend::coresFromCpuMax("-1 100000"), 0);
    EXPECT_EQ(rend::coresFromCpuMax("100000 0"), 0);
}

TEST(Threads, TheUsableCoresAreSomeOfTheMachines) {
    const int cores = rend::usableCores();
    EXPECT_GE(cores, 1);
    if (std::thread::hardware_concurrency() > 0)
        EXPECT_LE(cores, int(std::thread::hardware_concurrency()));
}

TEST(Threads, TheBusyTimeOfAllCoresIsReadFromProcStat) {
    // user nice system idle iowait irq softirq steal, in ticks of 1/100 s
    const char* stat = "cpu  1000 50 200 9000 30 10 5 7 0 0\ncpu0 500 25 100 4500 15 5 2 3 0 0\n";
    EXPECT_DOUBLE_EQ(rend::busySecondsFromProcStat(stat, 100.0),
                     (1000 + 50 + 200 + 10 + 5) / 100.0);
    EXPECT_EQ(rend::busySecondsFromProcStat("intr 5\n", 100.0), -1.0);
    EXPECT_EQ(rend::busySecondsFromProcStat("cpu  12 x\n", 100.0), -1.0);
}

TEST(Threads, OtherProcessesBusyCoresLeaveTheRestAtLeastOne) {
    EXPECT_EQ(rend::threadsBeside(2, 0.0), 2);
    EXPECT_EQ(rend::threadsBeside(2, 0.3), 2);   // a light task leaves both
    EXPECT_EQ(rend::threadsBeside(2, 0.67), 1);  // one busy loop sharing two cores with us
    EXPECT_EQ(rend::threadsBeside(2, 3.0), 1);
    EXPECT_EQ(rend::threadsBeside(8, 2.4), 6);
    EXPECT_EQ(rend::threadsBeside(4, -1.0), 4);  // rounding of the ticks
}

TEST(Threads, TheGovernorGivesUpACoreABusyProcessTakes) {
    const int usable = rend::usableCores();
    if (usable < 2) GTEST_SKIP() << "one usable core: nothing to give up";
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        for (volatile unsigned long k = 0;; k = k + 1) {
        }
    }
    rend::ThreadGovernor governor(usable);
    governor.atFrame();  // the first look starts the window
    std::this_thread::sleep_for(std::chrono::duration<double>(1.5 * governor.kWindowSeconds));
    const int threads = governor.atFrame();
    kill(child, SIGKILL);
    waitpid(child, nullptr, 0);
    EXPECT_LE(threads, usable - 1) << "a busy process beside it";  // more load: fewer still
    EXPECT_GE(threads, 1);
    omp_set_num_threads(usable);
}
