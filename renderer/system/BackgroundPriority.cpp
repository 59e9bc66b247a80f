#include "system/BackgroundPriority.h"

#include <cerrno>

#include <tbb/task_scheduler_observer.h>

#ifdef __linux__
#include <sys/resource.h>
#include <unistd.h>
#endif

namespace terralux {
namespace {

void lowerThisThread() {
#ifdef __linux__
    // On a thread id setpriority sets that thread's nice value alone (setpriority(2), NOTES).
    // A failure leaves the thread at its priority, which costs responsiveness only.
    if (getpriority(PRIO_PROCESS, static_cast<id_t>(gettid())) < kBackgroundNice)
        (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kBackgroundNice);
#endif
}

}  // namespace

int threadNice() {
#ifdef __linux__
    errno = 0;
    return getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
#else
    return 0;
#endif
}

// Observes the arena of the thread that made it: the workers that join its loops.
struct BackgroundThread::Observer : tbb::task_scheduler_observer {
    Observer() { observe(true); }
    ~Observer() override { observe(false); }
    void on_scheduler_entry(bool worker) override {
        if (worker) lowerThisThread();
    }
};

BackgroundThread::BackgroundThread() {
    lowerThisThread();
    observer_ = std::make_unique<Observer>();
}

BackgroundThread::~BackgroundThread() = default;

}  // namespace terralux
