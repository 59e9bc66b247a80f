#pragma once
// `terralux` on the command line: argument handling, the commands and their exit codes.

namespace terralux {

enum ExitCode : int {
    kExitOk = 0,
    kExitUsage = 2,        // bad usage or invalid input
    kExitRuntime = 3,      // the work itself failed
    kExitInterrupted = 130,
};

int runCommandLine(int argc, char** argv);

}  // namespace terralux
