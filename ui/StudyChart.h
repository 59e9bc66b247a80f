#pragma once
// The study's plot (docs/lighting.md, "The speed/accuracy study"): error (p95) against time, log-log,
// one series per knob, the Pareto front of the probe settings drawn as a line and the project's
// settings marked. The Trade-off panel shows it live; `terralux --study` renders it to study.png.

#include <filesystem>
#include <utility>
#include <vector>

#include <QtGlobal>

#include "Study.h"

QT_BEGIN_NAMESPACE
class QChart;
class QXYSeries;
QT_END_NAMESPACE

namespace terralux {

struct StudyChart {
    QChart* chart = nullptr;  // owned by the caller (or the view it is given to)
    // Each clickable series and, per its point, the index into StudyResult::points.
    std::vector<std::pair<QXYSeries*, std::vector<size_t>>> series;
};

StudyChart makeStudyChart(const StudyResult& result);

// Renders the chart to a PNG of `width` × `height` pixels, written atomically. Needs a
// QApplication; without one (the command line) it starts one on the offscreen platform.
void writeStudyPlotPng(const StudyResult& result, const std::filesystem::path& png, int width = 1280,
                       int height = 800);

}  // namespace terralux
