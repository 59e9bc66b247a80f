#include "BakeController.h"

#include <QMetaObject>

#include "BakeJob.h"
#include "bake/DiffuseBake.h"

namespace terralux {

BakeController::BakeController(QObject* parent) : QObject(parent) {
    qRegisterMetaType<nlohmann::json>("nlohmann::json");
}

BakeController::~BakeController() {
    cancel();
    wait();
}

void BakeController::start(const Project& project) {
    if (running_) return;
    wait();
    running_ = true;
    cancel_ = false;
    worker_ = std::thread([this, project] {
        const auto start = std::chrono::steady_clock::now();
        auto onProgress = [&](const std::string& phase, double f) {
            const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const double eta = f > 0.02 ? elapsed * (1.0 - f) / f : -1.0;
            QMetaObject::invokeMethod(this, [this, f, p = QString::fromStdString(phase), eta] {
                emit progress(f, p, eta);
            }, Qt::QueuedConnection);
        };
        try {
            BakeRequest request;
            request.project = project;
            const BakeOutcome outcome = runBake(request, onProgress, &cancel_);
            QMetaObject::invokeMethod(this, [this, report = outcome.report] {
                running_ = false;
                emit finished(report);
            }, Qt::QueuedConnection);
        } catch (const BakeCancelled&) {
            QMetaObject::invokeMethod(this, [this] {
                running_ = false;
                emit cancelled();
            }, Qt::QueuedConnection);
        } catch (const std::exception& e) {
            QMetaObject::invokeMethod(this, [this, m = QString::fromStdString(e.what())] {
                running_ = false;
                emit failed(m);
            }, Qt::QueuedConnection);
        }
    });
}

void BakeController::cancel() { cancel_ = true; }

void BakeController::wait() {
    if (worker_.joinable()) worker_.join();
}

}  // namespace terralux
