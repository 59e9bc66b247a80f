#pragma once
// Runs a bake off the UI thread: progress, ETA, cancel. A cancelled or failed bake leaves the
// previous outputs as they were (runBake stages and renames).

#include <chrono>

#include <QObject>
#include <QString>

#include <nlohmann/json.hpp>

#include "LatestJob.h"
#include "Project.h"

namespace terralux {

class BakeController : public QObject {
    Q_OBJECT
public:
    explicit BakeController(QObject* parent = nullptr);
    ~BakeController() override;

    bool running() const { return running_; }
    void start(const Project& project);
    void cancel();
    // Waits for a running bake to end (closing the window).
    void wait();

signals:
    void progress(double fraction, const QString& phase, double etaSeconds);
    void finished(const nlohmann::json& report);
    void cancelled();
    void failed(const QString& message);

private:
    LatestJob job_{this};  // the bake
    bool running_ = false;
};

}  // namespace terralux
