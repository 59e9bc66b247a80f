#pragma once
// The commands only terralux has: --render (the Vulkan renderer) and --study (which measures
// shadow settings on the Vulkan device and draws its plot with the widgets' charts).

#include "CommandLine.h"
#include "Study.h"

namespace terralux {

// `writeStudyPlot` draws study.png (the chart lives with the widgets, above this layer); without
// it the study writes its JSON, CSV and HTML only.
AuthoringCommands authoringCommands(StudyPlotWriter writeStudyPlot);

}  // namespace terralux
