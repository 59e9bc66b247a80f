#pragma once
// "Latest job wins": the one worker thread of one kind of background job of a QObject (the
// preview bake, the horizon AO, the LPV update, a terrain import, the study, the bake). start()
// cancels the job running, waits for it and starts the new one; what a job posts back runs on the
// owner's thread, and only while no newer job has started and stop() has not run, so the result
// of a superseded job that is already queued never lands. startBeside() and dismiss() cancel
// without waiting.

#include <atomic>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

#include <QObject>

namespace terralux {

class LatestJob {
public:
    // What a running job sees.
    class Context {
    public:
        bool cancelled() const { return cancel_->load(); }
        // For calls that poll a flag themselves (previewBake, runBake, runStudy).
        const std::atomic<bool>* cancelFlag() const { return cancel_.get(); }
        // Runs `f` on the owner's thread, unless a newer job has started or stop() ran by then.
        void post(std::function<void()> f) const;

    private:
        friend class LatestJob;
        LatestJob* job_ = nullptr;
        unsigned generation_ = 0;
        std::shared_ptr<std::atomic<bool>> cancel_;
    };

    explicit LatestJob(QObject* owner) : owner_(owner) {}
    ~LatestJob() { stop(); }
    LatestJob(const LatestJob&) = delete;
    LatestJob& operator=(const LatestJob&) = delete;

    // Cancels the job running and waits for it, then runs `work` on a new worker thread.
    void start(std::function<void(const Context&)> work);
    // Cancels the job running and runs `work` on a new worker thread at once: the cancelled job
    // winds down beside it and nothing it posts lands. For jobs whose runs share no output (the
    // draft preview), so an edit never waits for the last one's cancellation to be noticed.
    void startBeside(std::function<void(const Context&)> work);
    // Cancels the running job and drops whatever it posted or still posts, without waiting: it
    // winds down beside the next job as one startBeside cancelled does. For results that must
    // not land (an edit undone back to a current bake) where nothing else waits on the job.
    void dismiss();
    // Asks the running job to stop (Context::cancelled); what it still posts lands.
    void cancel();
    // Cancels, waits, and drops whatever the job posted that has not landed.
    void stop();
    // Waits for the worker to end (after the job's last post, it has nothing left to do), and
    // for cancelled ones still winding down.
    void wait();

private:
    struct Retiring {
        std::thread thread;
        std::shared_ptr<std::atomic<bool>> ended;
    };
    void launch(std::function<void(const Context&)> work);

    QObject* owner_;
    std::thread thread_;
    std::shared_ptr<std::atomic<bool>> ended_ = std::make_shared<std::atomic<bool>>(true);
    std::vector<Retiring> retiring_;  // cancelled by startBeside or dismiss, not yet joined
    std::shared_ptr<std::atomic<bool>> cancel_ = std::make_shared<std::atomic<bool>>(false);
    unsigned generation_ = 0;  // the owner's thread only
};

}  // namespace terralux
