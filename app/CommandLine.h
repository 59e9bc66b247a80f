#pragma once
// `terralux` on the command line: argument handling, the commands and their exit codes.

#include "Study.h"

namespace terralux {

enum ExitCode : int {
    kExitOk = 0,
    kExitUsage = 2,        // bad usage or invalid input
    kExitRuntime = 3,      // the work itself failed
    kExitInterrupted = 130,
};

// `writeStudyPlot` draws study.png for --study (the chart lives with the widgets, above this layer);
// without it the study writes its JSON, CSV and HTML only.
int runCommandLine(int argc, char** argv, const StudyPlotWriter& writeStudyPlot = {});

}  // namespace terralux
