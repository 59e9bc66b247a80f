// Background threads yield the processor to the UI thread (system/BackgroundPriority.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include <tbb/concurrent_vector.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "system/BackgroundPriority.h"

using namespace terralux;

namespace {

// Busy for about `us` microseconds: long enough that every worker joins a loop of these.
void spin(int us) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::microseconds(us);
    while (std::chrono::steady_clock::now() < end) {
    }
}

}  // namespace

// A thread that holds a BackgroundThread runs at kBackgroundNice, and so does every TBB worker
// that takes part in its parallel loops; the thread that made it (here the test's) keeps its own.
TEST(BackgroundThread, LowersItsThreadAndTheWorkersOfItsLoops) {
#ifndef __linux__
    GTEST_SKIP() << "thread priorities are lowered on Linux only";
#endif
    const int before = threadNice();
    ASSERT_LT(before, kBackgroundNice) << "the test runs at nice " << before << " already";
    int held = 0;
    tbb::concurrent_vector<int> workers;
    std::thread([&] {
        const BackgroundThread background;
        held = threadNice();
        const std::thread::id self = std::this_thread::get_id();
        tbb::parallel_for(0, 2000, [&](int) {
            spin(100);
            if (std::this_thread::get_id() != self) workers.push_back(threadNice());
        });
    }).join();
    EXPECT_EQ(held, kBackgroundNice);
    EXPECT_EQ(threadNice(), before);
    // (One thread a loop, as in the ThreadSanitizer build, leaves no worker to hold.)
    if (tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1) {
        ASSERT_FALSE(workers.empty()) << "no worker joined the loop";
    }
    EXPECT_TRUE(std::all_of(workers.begin(), workers.end(), [](int n) { return n == kBackgroundNice; }));
}
