#include "BakeController.h"

#include <QMetaObject>

#include "BakeJob.h"
#include "bake/DiffuseBake.h"

namespace terralux {

BakeController::BakeController(QObject* parent) : QObject(parent) {
    qRegisterMetaType<nlohmann::json>("nlohmann::json");
}

BakeController::~BakeController() = default;  // the bake's job cancels and waits

void BakeController::start(const Project& project) {
    if (running_) return;
    running_ = true;
    job_.start([this, project](const LatestJob::Context& job) {
        const auto start = std::chrono::steady_clock::now();
        auto onProgress = [&](const std::string& phase, double f) {
            const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const double eta = f > 0.02 ? elapsed * (1.0 - f) / f : -1.0;
            job.post([this, f, p = QString::fromStdString(phase), eta] { emit progress(f, p, eta); });
        };
        try {
            BakeRequest request;
            request.project = project;
            const BakeOutcome outcome = runBake(request, onProgress, job.cancelFlag());
            job.post([this, report = outcome.report] {
                running_ = false;
                emit finished(report);
            });
        } catch (const BakeCancelled&) {
            job.post([this] {
                running_ = false;
                emit cancelled();
            });
        } catch (const std::exception& e) {
            job.post([this, m = QString::fromStdString(e.what())] {
                running_ = false;
                emit failed(m);
            });
        }
    });
}

void BakeController::cancel() { job_.cancel(); }

void BakeController::wait() { job_.wait(); }

}  // namespace terralux
