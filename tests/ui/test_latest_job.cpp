// LatestJob, the "latest job wins" worker every panel uses: a superseded job's result never
// lands, stop() drops what is queued, cancel reaches the running job, and posts land in order on
// the owner's thread.
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <QCoreApplication>
#include <QObject>

#include "LatestJob.h"

using namespace terralux;

namespace {

QCoreApplication& app() {
    static int argc = 1;
    static char name[] = "test_latest_job";
    static char* argv[] = {name, nullptr};
    static QCoreApplication a(argc, argv);
    return a;
}

// Runs the owner's event loop until `done` or `limit` passes.
template <class F>
void pump(F done, std::chrono::milliseconds limit = std::chrono::seconds(2)) {
    const auto until = std::chrono::steady_clock::now() + limit;
    while (!done() && std::chrono::steady_clock::now() < until) {
        QCoreApplication::processEvents(QEventLoop::AllEvents, 10);
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    QCoreApplication::processEvents();
}

}  // namespace

TEST(LatestJob, ASupersededJobsResultNeverLands) {
    app();
    QObject owner;
    std::vector<int> landed;
    {
        LatestJob job(&owner);
        // The first job posts its result; it is queued, not yet run, when the second starts.
        job.start([&](const LatestJob::Context& c) { c.post([&] { landed.push_back(1); }); });
        job.wait();
        job.start([&](const LatestJob::Context& c) { c.post([&] { landed.push_back(2); }); });
        job.wait();
        pump([&] { return !landed.empty(); });
    }
    EXPECT_EQ(landed, std::vector<int>{2});
}

TEST(LatestJob, StopDropsWhatIsQueuedAndCancelReachesTheJob) {
    app();
    QObject owner;
    std::vector<int> landed;
    std::atomic<bool> sawCancel{false};
    LatestJob job(&owner);
    job.start([&](const LatestJob::Context& c) {
        c.post([&] { landed.push_back(1); });
        while (!c.cancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        sawCancel = c.cancelFlag()->load();
        c.post([&] { landed.push_back(2); });
    });
    job.stop();
    pump([] { return false; }, std::chrono::milliseconds(200));  // anything queued would run here
    EXPECT_TRUE(sawCancel);
    EXPECT_TRUE(landed.empty());
    // After a stop a new job's posts land, in order.
    job.start([&](const LatestJob::Context& c) {
        for (int i = 3; i < 6; ++i) c.post([&, i] { landed.push_back(i); });
    });
    pump([&] { return landed.size() == 3; });
    EXPECT_EQ(landed, (std::vector<int>{3, 4, 5}));
}

TEST(LatestJob, CancelLetsTheJobReportItself) {
    app();
    QObject owner;
    std::vector<int> landed;
    LatestJob job(&owner);
    job.start([&](const LatestJob::Context& c) {
        while (!c.cancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        c.post([&] { landed.push_back(7); });  // "cancelled", as the bake and the study say
    });
    job.cancel();
    pump([&] { return !landed.empty(); });
    EXPECT_EQ(landed, std::vector<int>{7});
}

// startBeside does not wait for the cancelled job: a job that notices its cancellation only after
// 300 ms winds down beside the new one, and of the two only the new one's posts land; wait()
// waits for both.
TEST(LatestJob, StartBesideLeavesTheCancelledJobToWindDown) {
    app();
    QObject owner;
    std::vector<int> landed;
    std::atomic<bool> oldEnded{false}, oldSawCancel{false};
    LatestJob job(&owner);
    job.start([&](const LatestJob::Context& c) {
        std::this_thread::sleep_for(std::chrono::milliseconds(300));  // a stretch that polls nothing
        oldSawCancel = c.cancelled();
        c.post([&] { landed.push_back(1); });
        oldEnded = true;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto before = std::chrono::steady_clock::now();
    job.startBeside([&](const LatestJob::Context& c) { c.post([&] { landed.push_back(2); }); });
    const auto took = std::chrono::steady_clock::now() - before;
    EXPECT_LT(took, std::chrono::milliseconds(100));
    EXPECT_FALSE(oldEnded.load());  // still running when the new job started
    pump([&] { return !landed.empty(); });
    EXPECT_EQ(landed, std::vector<int>{2});
    job.wait();
    EXPECT_TRUE(oldEnded.load());
    EXPECT_TRUE(oldSawCancel.load());
    pump([] { return false; }, std::chrono::milliseconds(100));  // the old job's post would run here
    EXPECT_EQ(landed, std::vector<int>{2});
    // start() still waits, for a job winding down beside the current one too: the slow job is
    // set beside by a quick one, and start() returns only once it has ended.
    std::atomic<bool> slowEnded{false};
    job.startBeside([&](const LatestJob::Context& c) {
        while (!c.cancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        slowEnded = true;
    });
    job.startBeside([](const LatestJob::Context&) {});
    EXPECT_FALSE(slowEnded.load());  // beside, cancelled, still winding down
    job.start([&](const LatestJob::Context& c) { c.post([&] { landed.push_back(3); }); });
    EXPECT_TRUE(slowEnded.load());
    pump([&] { return landed.size() == 2; });
    EXPECT_EQ(landed, (std::vector<int>{2, 3}));
}

// Edits faster than a cancellation is noticed do not pile up jobs: with two winding down, the
// next startBeside waits for the oldest.
TEST(LatestJob, AtMostTwoJobsWindDownBesideTheCurrentOne) {
    app();
    QObject owner;
    std::atomic<int> ended{0};
    LatestJob job(&owner);
    const auto deaf = [&](const LatestJob::Context&) {  // notices nothing for 300 ms
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        ++ended;
    };
    const auto start = std::chrono::steady_clock::now();
    job.startBeside(deaf);
    job.startBeside(deaf);
    job.startBeside(deaf);  // two beside, one current: none waited
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(200));
    EXPECT_EQ(ended.load(), 0);
    job.startBeside(deaf);  // a third would be beside: the first is joined
    EXPECT_GE(ended.load(), 1);
    job.wait();
    EXPECT_EQ(ended.load(), 4);
}

// dismiss() is stop() without the wait: the job's posts never land, and the owner's thread goes
// on while the job notices its cancellation; wait() joins it.
TEST(LatestJob, DismissDropsTheJobWithoutWaitingForIt) {
    app();
    QObject owner;
    std::vector<int> landed;
    std::atomic<bool> ended{false}, sawCancel{false};
    LatestJob job(&owner);
    job.start([&](const LatestJob::Context& c) {
        c.post([&] { landed.push_back(1); });  // queued before the dismissal
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        sawCancel = c.cancelled();
        c.post([&] { landed.push_back(2); });  // posted after it
        ended = true;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto before = std::chrono::steady_clock::now();
    job.dismiss();
    EXPECT_LT(std::chrono::steady_clock::now() - before, std::chrono::milliseconds(100));
    EXPECT_FALSE(ended.load());
    job.wait();
    EXPECT_TRUE(ended.load());
    EXPECT_TRUE(sawCancel.load());
    pump([] { return false; }, std::chrono::milliseconds(100));  // both posts would run here
    EXPECT_TRUE(landed.empty());
    // A job started after a dismissal posts as any other.
    job.startBeside([&](const LatestJob::Context& c) { c.post([&] { landed.push_back(3); }); });
    pump([&] { return !landed.empty(); });
    EXPECT_EQ(landed, std::vector<int>{3});
}
