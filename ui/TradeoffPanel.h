#pragma once
// The Trade-off dock: the speed/accuracy study (runStudy, as `terralux --study`) of the open
// project on a worker, within a time budget, with progress and cancel; its plot and a table of
// its points kept in step. A point picked on the plot or in the table applies its settings to the
// project as one undoable edit.

#include <optional>
#include <vector>

#include <QWidget>

#include <nlohmann/json.hpp>

#include "LatestJob.h"
#include "Study.h"
#include "StudyChart.h"

class QChartView;
class QLabel;
class QProgressBar;
class QPushButton;
class QScatterSeries;
class QSpinBox;
class QTableWidget;

namespace terralux {

class ProjectDocument;

class TradeoffPanel : public QWidget {
    Q_OBJECT
public:
    explicit TradeoffPanel(ProjectDocument* doc, QWidget* parent = nullptr);
    ~TradeoffPanel() override;

    bool running() const { return running_; }
    // The last study that finished; a cancelled or failed one leaves it.
    const std::optional<StudyResult>& result() const { return result_; }
    const StudyChart& chart() const { return chart_; }
    // The point selected on the plot or in the table (an index into result()->points), or -1.
    int selectedPoint() const { return selected_; }
    void selectPoint(int index);
    // The point whose settings the project has now (the study's current one until an edit), or -1.
    int projectPoint() const { return projectPoint_; }

    void start();
    void cancel();
    // Applies the selected point's settings as one undoable edit; false (and says why) if refused.
    bool applySelected();

signals:
    void finished();
    void rejected(const QString& message);

private:
    void showResult();
    void updateMarks();
    void updateStatus();
    void setIdle();
    void fail(const QString& message);
    // The point whose settings the project now has: the study's project with the point's --set
    // assignments applied equals the document's project (the camera aside).
    int matchProjectPoint() const;
    void onChartClicked(const QPointF& at, size_t series);

    ProjectDocument* doc_;
    QSpinBox* budget_;
    QPushButton *run_, *cancel_, *apply_;
    QProgressBar* progress_;
    QLabel* status_;
    QChartView* view_;
    QTableWidget* table_;
    StudyChart chart_;
    QScatterSeries* selectedMark_ = nullptr;
    QScatterSeries* projectMark_ = nullptr;

    std::optional<StudyResult> result_;
    nlohmann::json studied_;          // the document's JSON the last result was measured from
    nlohmann::json startedJson_;      // the JSON the running study was started from
    std::vector<nlohmann::json> pointScenes_;  // per point: the scene it measured, as matchProjectPoint compares
    int selected_ = -1, projectPoint_ = -1;
    QString summary_;                 // the result's line ("29 settings in 4.6 s; 3 skipped")
    QString note_;                    // what happened last (cancelled, failed, refused)
    bool noteIsError_ = false;

    LatestJob job_{this};  // the study
    bool running_ = false;
};

}  // namespace terralux
