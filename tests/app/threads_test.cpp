// The default thread count (app/Threads.h): the cores a cgroup quota grants, and the cores this
// process may use.

#include "app/Threads.h"

#include <gtest/gtest.h>

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
