#pragma once
// The command line of both binaries: argument handling, the commands and their exit codes.
// terralux-bake runs the commands that need no display and no GPU; terralux adds the ones that
// do (AuthoringCommands), which live above this layer with the renderer and the charts.

#include <functional>

#include "CommandLineHelp.h"

namespace terralux {

namespace cli {
struct Args;
}

enum ExitCode : int {
    kExitOk = 0,
    kExitUsage = 2,        // bad usage or invalid input
    kExitRuntime = 3,      // the work itself failed
    kExitInterrupted = 130,
};

// --render and --study; absent in terralux-bake, which refuses their options by name.
struct AuthoringCommands {
    std::function<int(const cli::Args&)> render, study;
};

int runCommandLine(int argc, char** argv, Binary binary, const AuthoringCommands& authoring = {});

}  // namespace terralux
