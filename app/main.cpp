#include <cstdlib>
#include <cstring>
#include <iostream>

#include "AuthoringCommands.h"
#include "MainWindow.h"
#include "StudyChart.h"

int main(int argc, char** argv) {
    // `terralux` and `terralux PROJECT` open the authoring window; anything with an option is
    // the command line, which never needs a display.
    const bool gui = argc == 1 || (argc == 2 && argv[1][0] != '-');
    if (!gui)
        return terralux::runCommandLine(
            argc, argv, terralux::Binary::Authoring,
            terralux::authoringCommands([](const terralux::StudyResult& r, const std::filesystem::path& png) {
                terralux::writeStudyPlotPng(r, png);
            }));
    if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY") && !std::getenv("QT_QPA_PLATFORM")) {
        std::cerr << "terralux: no display for the authoring window; the headless commands are in "
                     "'terralux --help'\n";
        return terralux::kExitUsage;
    }
    return terralux::runGui(argc, argv);
}
