#include "TradeoffPanel.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLocale>
#include <QMetaObject>
#include <QProgressBar>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSpinBox>
#include <QTableWidget>
#include <QVBoxLayout>
#include <QtCharts/QChart>
#include <QtCharts/QChartView>
#include <QtCharts/QLegendMarker>
#include <QtCharts/QScatterSeries>

#include "ProjectDocument.h"
#include "bake/DiffuseBake.h"

namespace terralux {

namespace {

using nlohmann::json;

enum Column { kKnob, kSetting, kTime, kMemory, kOutput, kMean, kP95, kMax, kFront, kProject, kColumns };

// What a study point is compared on: the scene as the loader reads it, without the view and the
// export settings, which the study neither varies nor measures.
json comparable(json scene) {
    scene.erase("camera");
    scene.erase("export");
    return scene;
}

QTableWidgetItem* cell(const QString& text, bool number = false) {
    auto* i = new QTableWidgetItem(text);
    i->setFlags(i->flags() & ~Qt::ItemIsEditable);
    if (number) i->setTextAlignment(Qt::AlignRight | Qt::AlignVCenter);
    return i;
}

QString percent(double v) { return QString("%1 %").arg(v * 100.0, 0, 'f', 2); }

}  // namespace

TradeoffPanel::TradeoffPanel(ProjectDocument* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
    auto* v = new QVBoxLayout(this);
    v->setContentsMargins(0, 0, 0, 0);

    auto* controls = new QHBoxLayout;
    controls->addWidget(new QLabel("Budget"));
    budget_ = new QSpinBox;
    budget_->setObjectName("tradeoff.budget");
    budget_->setRange(5, 3600);
    budget_->setValue(60);
    budget_->setSuffix(" s");
    budget_->setToolTip("How long the study may take: settings that no longer fit are skipped, cheapest first");
    controls->addWidget(budget_);
    run_ = new QPushButton("Run study");
    run_->setObjectName("tradeoff.run");
    run_->setToolTip("Sweep the bake's knobs one by one, each timed and measured against the path-traced reference");
    cancel_ = new QPushButton("Cancel");
    cancel_->setObjectName("tradeoff.cancel");
    cancel_->setEnabled(false);
    controls->addWidget(run_);
    controls->addWidget(cancel_);
    controls->addStretch(1);
    v->addLayout(controls);

    progress_ = new QProgressBar;
    progress_->setObjectName("tradeoff.progress");
    progress_->setRange(0, 100);
    progress_->setValue(0);
    progress_->setFormat("idle");
    progress_->setTextVisible(true);
    v->addWidget(progress_);

    status_ = new QLabel("No study yet: Run measures what each setting costs and how far it is from the exact answer.");
    status_->setObjectName("tradeoff.status");
    status_->setWordWrap(true);
    status_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    v->addWidget(status_);

    view_ = new QChartView;
    view_->setObjectName("tradeoff.chart");
    view_->setRenderHint(QPainter::Antialiasing);
    view_->setMinimumHeight(420);
    view_->setToolTip("Click a point to select its setting; double-click to apply it");
    v->addWidget(view_, 3);

    table_ = new QTableWidget(0, kColumns, this);
    table_->setObjectName("tradeoff.table");
    table_->setHorizontalHeaderLabels({"Knob", "Setting", "Time", "Memory", "Output", "Error mean", "Error p95",
                                       "Error max", "Front", "Project"});
    table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
    table_->horizontalHeader()->setStretchLastSection(true);
    table_->verticalHeader()->setVisible(false);
    table_->setSelectionBehavior(QAbstractItemView::SelectRows);
    table_->setSelectionMode(QAbstractItemView::SingleSelection);
    table_->setMinimumHeight(160);
    table_->setToolTip("A row per measured setting; double-click to apply it");
    v->addWidget(table_, 2);

    apply_ = new QPushButton("Apply setting");
    apply_->setObjectName("tradeoff.apply");
    apply_->setEnabled(false);
    apply_->setToolTip("Set the selected point's parameters in the project: one undoable edit");
    v->addWidget(apply_);

    connect(run_, &QPushButton::clicked, this, &TradeoffPanel::start);
    connect(cancel_, &QPushButton::clicked, this, &TradeoffPanel::cancel);
    connect(apply_, &QPushButton::clicked, this, [this] { applySelected(); });
    connect(table_, &QTableWidget::itemSelectionChanged, this, [this] {
        const auto rows = table_->selectionModel()->selectedRows();
        selected_ = rows.isEmpty() ? -1 : rows.front().row();
        updateMarks();
    });
    connect(table_, &QTableWidget::cellDoubleClicked, this, [this](int row, int) {
        selectPoint(row);
        applySelected();
    });
    connect(doc_, &ProjectDocument::parametersChanged, this, [this] {
        if (result_) updateMarks();
    });
}

TradeoffPanel::~TradeoffPanel() = default;  // the study's job cancels and waits

void TradeoffPanel::start() {
    if (running_) return;
    running_ = true;
    note_.clear();
    noteIsError_ = false;
    run_->setEnabled(false);
    cancel_->setEnabled(true);
    budget_->setEnabled(false);
    progress_->setValue(0);
    progress_->setFormat("starting %p%");
    updateStatus();
    // The study reads its own copy: edits made while it runs do not reach it.
    startedJson_ = doc_->json();
    const Project project = doc_->project();
    StudyOptions options;
    options.budgetSeconds = budget_->value();
    job_.start([this, project, options](const LatestJob::Context& job) {
        auto onProgress = [this, &job](const std::string& phase, double f) {
            job.post([this, f, p = QString::fromStdString(phase)] {
                if (!running_) return;
                progress_->setValue(int(std::lround(std::clamp(f, 0.0, 1.0) * 100.0)));
                progress_->setFormat(p + " %p%");
            });
        };
        try {
            auto r = std::make_shared<StudyResult>(runStudy(project, options, onProgress, job.cancelFlag()));
            job.post([this, r] {
                result_ = std::move(*r);
                studied_ = startedJson_;
                setIdle();
                showResult();
                emit finished();
            });
        } catch (const BakeCancelled&) {
            job.post([this] {
                setIdle();
                note_ = result_ ? "Cancelled: the last study is still shown." : "Cancelled.";
                updateStatus();
                emit finished();
            });
        } catch (const std::exception& e) {
            job.post([this, m = QString::fromStdString(e.what())] {
                setIdle();
                fail("Study failed: " + m);
                emit finished();
            });
        }
    });
}

void TradeoffPanel::cancel() {
    if (!running_) return;
    job_.cancel();
    cancel_->setEnabled(false);
    progress_->setFormat("cancelling…");
}

void TradeoffPanel::setIdle() {
    running_ = false;
    job_.wait();  // it has handed over its result and is ending
    run_->setEnabled(true);
    cancel_->setEnabled(false);
    budget_->setEnabled(true);
    progress_->setValue(0);
    progress_->setFormat("idle");
}

void TradeoffPanel::fail(const QString& message) {
    // One line: the panel is narrow, the message says what to fix.
    note_ = message.section('\n', 0, 0);
    noteIsError_ = true;
    updateStatus();
    emit rejected(note_);
}

void TradeoffPanel::showResult() {
    const StudyResult& r = *result_;
    summary_ = QString("%1 settings in %2 s").arg(r.points.size()).arg(r.elapsedSeconds, 0, 'f', 1);
    if (!r.skipped.empty()) summary_ += QString("; %1 skipped (over the budget)").arg(r.skipped.size());
    summary_ += ".";

    // Each point's scene, as matchProjectPoint compares it with the document's.
    pointScenes_.assign(r.points.size(), json());
    for (size_t i = 0; i < r.points.size(); ++i) {
        try {
            json doc = studied_;
            for (const std::string& s : r.points[i].sets) applyOverride(doc, s);
            pointScenes_[i] = comparable(sceneToJson(sceneFromJson(doc, "study point", nullptr)));
        } catch (const std::exception&) {
            // A setting the loader no longer takes matches nothing.
        }
    }

    QChart* old = view_->chart();
    chart_ = makeStudyChart(r);
    view_->setChart(chart_.chart);  // the view owns the new chart and lets go of the old one
    delete old;
    for (size_t s = 0; s < chart_.series.size(); ++s) {
        QXYSeries* series = chart_.series[s].first;
        connect(series, &QXYSeries::clicked, this, [this, s](const QPointF& p) { onChartClicked(p, s); });
        connect(series, &QXYSeries::doubleClicked, this, [this, s](const QPointF& p) {
            onChartClicked(p, s);
            applySelected();
        });
    }
    auto marker = [this](const QString& name, QScatterSeries::MarkerShape shape, double size, QColor fill,
                         QColor border) {
        auto* m = new QScatterSeries;
        m->setName(name);
        m->setMarkerShape(shape);
        m->setMarkerSize(size);
        m->setColor(fill);
        QPen pen(border);
        pen.setWidthF(2.5);
        m->setPen(pen);
        chart_.chart->addSeries(m);
        for (QAbstractAxis* a : chart_.chart->axes()) m->attachAxis(a);
        return m;
    };
    projectMark_ = marker("project now", QScatterSeries::MarkerShapeRectangle, 14.0, QColor(46, 160, 67),
                          QColor(10, 70, 20));
    selectedMark_ = marker("selected", QScatterSeries::MarkerShapeCircle, 24.0, Qt::transparent, QColor(20, 20, 20));
    for (QLegendMarker* m : chart_.chart->legend()->markers(selectedMark_)) m->setVisible(false);
    connect(projectMark_, &QXYSeries::clicked, this, [this] { selectPoint(projectPoint_); });
    connect(selectedMark_, &QXYSeries::doubleClicked, this, [this] { applySelected(); });

    QSignalBlocker block(table_);
    table_->clearContents();
    table_->setRowCount(int(r.points.size()));
    const QLocale locale;
    for (int i = 0; i < int(r.points.size()); ++i) {
        const StudyPoint& p = r.points[size_t(i)];
        QStringList sets;
        for (const std::string& s : p.sets) sets << QString::fromStdString(s);
        table_->setItem(i, kKnob, cell(QString::fromStdString(p.knob)));
        auto* setting = cell(QString::fromStdString(p.label));
        setting->setToolTip(sets.isEmpty() ? "the project's settings" : "--set " + sets.join(" --set "));
        table_->setItem(i, kSetting, setting);
        table_->setItem(i, kTime, cell(QString("%1 s").arg(p.seconds, 0, 'f', 2), true));
        // Below the page granularity of the resident-memory mark a setting reads 0: no measurable growth.
        auto* memory = cell(p.peakMemoryBytes ? locale.formattedDataSize(qint64(p.peakMemoryBytes)) : "—", true);
        memory->setToolTip("Resident memory above what was resident when the setting began");
        table_->setItem(i, kMemory, memory);
        table_->setItem(i, kOutput, cell(p.outputBytes ? locale.formattedDataSize(qint64(p.outputBytes)) : "—", true));
        const QString meaning = studyMetricMeaning(p.metric);
        for (auto [c, value] : {std::pair{kMean, p.errorMean}, {kP95, p.errorP95}, {kMax, p.errorMax}}) {
            auto* e = cell(percent(value), true);
            e->setToolTip(meaning);
            table_->setItem(i, c, e);
        }
        table_->setItem(i, kFront, cell(p.pareto ? "yes" : ""));
        table_->setItem(i, kProject, cell(""));
    }
    selected_ = -1;
    table_->clearSelection();
    block.unblock();
    updateMarks();
}

void TradeoffPanel::onChartClicked(const QPointF& at, size_t series) {
    if (series >= chart_.series.size()) return;
    const auto& [s, indices] = chart_.series[series];
    // Nearest on the log axes, where the points are drawn.
    auto logOf = [](QPointF p) { return QPointF(std::log10(std::max(p.x(), 1e-12)), std::log10(std::max(p.y(), 1e-12))); };
    const QPointF q = logOf(at);
    int best = -1;
    double bestD = std::numeric_limits<double>::infinity();
    for (int i = 0; i < s->count() && size_t(i) < indices.size(); ++i) {
        const QPointF d = logOf(s->at(i)) - q;
        const double dd = d.x() * d.x() + d.y() * d.y();
        if (dd < bestD) bestD = dd, best = i;
    }
    if (best >= 0) selectPoint(int(indices[size_t(best)]));
}

void TradeoffPanel::selectPoint(int index) {
    if (!result_ || index < 0 || index >= int(result_->points.size())) {
        table_->clearSelection();
        return;
    }
    table_->selectRow(index);
    table_->scrollToItem(table_->item(index, 0));
}

int TradeoffPanel::matchProjectPoint() const {
    if (!result_) return -1;
    json now;
    try {
        now = comparable(sceneToJson(doc_->project().scene));
    } catch (const std::exception&) {
        return -1;
    }
    // The current point first: another point whose assignments change nothing is the same setting.
    for (size_t i = 0; i < result_->points.size(); ++i)
        if (result_->points[i].current && pointScenes_[i] == now) return int(i);
    for (size_t i = 0; i < result_->points.size(); ++i)
        if (!pointScenes_[i].is_null() && pointScenes_[i] == now) return int(i);
    return -1;
}

void TradeoffPanel::updateMarks() {
    projectPoint_ = matchProjectPoint();
    // Where a point is drawn: its place in a series of the chart.
    auto place = [this](int index) -> std::optional<QPointF> {
        for (const auto& [s, indices] : chart_.series)
            for (size_t i = 0; i < indices.size(); ++i)
                if (int(indices[i]) == index && int(i) < s->count()) return s->at(int(i));
        return std::nullopt;
    };
    // The chart's star marks the settings the study measured from; the square, another point
    // the project has been set to since.
    const bool moved = result_ && projectPoint_ >= 0 && !result_->points[size_t(projectPoint_)].current;
    if (projectMark_) {
        projectMark_->clear();
        if (auto p = place(projectPoint_); p && moved) projectMark_->append(*p);
        for (QLegendMarker* m : chart_.chart->legend()->markers(projectMark_)) m->setVisible(moved);
    }
    if (selectedMark_) {
        selectedMark_->clear();
        if (auto p = place(selected_)) selectedMark_->append(*p);
    }
    if (result_) {
        for (int i = 0; i < table_->rowCount() && i < int(result_->points.size()); ++i) {
            QStringList marks;
            if (result_->points[size_t(i)].current) marks << "measured from";
            if (i == projectPoint_) marks << "now";
            if (QTableWidgetItem* it = table_->item(i, kProject)) it->setText(marks.join(", "));
            for (int c = 0; c < kColumns; ++c)
                if (QTableWidgetItem* it = table_->item(i, c)) {
                    QFont f = it->font();
                    f.setBold(i == projectPoint_);
                    it->setFont(f);
                }
        }
    }
    const bool applicable = result_ && selected_ >= 0 && !result_->points[size_t(selected_)].sets.empty() &&
                            selected_ != projectPoint_;
    apply_->setEnabled(applicable);
    updateStatus();
}

void TradeoffPanel::updateStatus() {
    QStringList lines;
    if (running_) lines << QString("Running a study of at most %1 s…").arg(budget_->value());
    if (result_) {
        QString line = summary_;
        const int current = [&] {
            for (size_t i = 0; i < result_->points.size(); ++i)
                if (result_->points[i].current) return int(i);
            return -1;
        }();
        if (projectPoint_ != current) {
            line += " The plot was measured before the edit: ";
            line += projectPoint_ >= 0
                        ? QString("the project now has %1.").arg(QString::fromStdString(result_->points[size_t(projectPoint_)].label))
                        : QString("the project's settings are no point of it now.");
        }
        lines << line;
    }
    if (!note_.isEmpty()) lines << note_;
    if (lines.isEmpty()) return;
    status_->setText(lines.join('\n'));
    status_->setStyleSheet(noteIsError_ ? "QLabel { color: #c62828 }" : "");
}

bool TradeoffPanel::applySelected() {
    if (!result_ || selected_ < 0 || selected_ >= int(result_->points.size())) return false;
    const StudyPoint& p = result_->points[size_t(selected_)];
    if (p.sets.empty()) return false;
    QString error;
    if (!doc_->setAssignments(p.sets, &error)) {
        fail("Not applied: " + error);
        return false;
    }
    note_.clear();
    noteIsError_ = false;
    updateMarks();
    return true;
}

}  // namespace terralux
