#include "LatestJob.h"

#include <QMetaObject>

#include "system/BackgroundPriority.h"

namespace terralux {

void LatestJob::Context::post(std::function<void()> f) const {
    QMetaObject::invokeMethod(job_->owner_, [job = job_, generation = generation_, f = std::move(f)] {
        if (generation == job->generation_) f();
    }, Qt::QueuedConnection);
}

void LatestJob::start(std::function<void(const Context&)> work) {
    stop();
    launch(std::move(work));
}

void LatestJob::startBeside(std::function<void(const Context&)> work) {
    dismiss();
    launch(std::move(work));
}

void LatestJob::dismiss() {
    cancel();
    ++generation_;  // what it queued or still posts must not land
    // Those that have ended are joined now, which does not wait.
    std::erase_if(retiring_, [](Retiring& r) {
        if (!r.ended->load()) return false;
        r.thread.join();
        return true;
    });
    // At most two wind down beside the next job: edits faster than a cancellation is noticed
    // wait for the oldest rather than pile up bakes and their memory.
    while (retiring_.size() >= 2) {
        retiring_.front().thread.join();
        retiring_.erase(retiring_.begin());
    }
    if (thread_.joinable()) retiring_.push_back({std::move(thread_), ended_});
}

void LatestJob::launch(std::function<void(const Context&)> work) {
    cancel_ = std::make_shared<std::atomic<bool>>(false);
    ended_ = std::make_shared<std::atomic<bool>>(false);
    Context c;
    c.job_ = this;
    c.generation_ = generation_;
    c.cancel_ = cancel_;
    thread_ = std::thread([work = std::move(work), c, ended = ended_]() mutable {
        const BackgroundThread background;
        {
            auto run = std::move(work);  // what the job holds goes before it says it has ended
            run(c);
        }
        *ended = true;
    });
}

void LatestJob::cancel() { *cancel_ = true; }

void LatestJob::stop() {
    cancel();
    wait();
    ++generation_;  // what it queued must not land
}

void LatestJob::wait() {
    if (thread_.joinable()) thread_.join();
    for (Retiring& r : retiring_) r.thread.join();
    retiring_.clear();
}

}  // namespace terralux
