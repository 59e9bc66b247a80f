#include "LatestJob.h"

#include <QMetaObject>

namespace terralux {

void LatestJob::Context::post(std::function<void()> f) const {
    QMetaObject::invokeMethod(job_->owner_, [job = job_, generation = generation_, f = std::move(f)] {
        if (generation == job->generation_) f();
    }, Qt::QueuedConnection);
}

void LatestJob::start(std::function<void(const Context&)> work) {
    stop();
    cancel_ = std::make_shared<std::atomic<bool>>(false);
    Context c;
    c.job_ = this;
    c.generation_ = generation_;
    c.cancel_ = cancel_;
    thread_ = std::thread([work = std::move(work), c] { work(c); });
}

void LatestJob::cancel() { *cancel_ = true; }

void LatestJob::stop() {
    cancel();
    wait();
    ++generation_;  // what it queued must not land
}

void LatestJob::wait() {
    if (thread_.joinable()) thread_.join();
}

}  // namespace terralux
