// terralux-bake: the headless commands for farm nodes and scripts. It links no GUI toolkit and no
// Vulkan loader (app/CheckHeadless.cmake fails the build if it does).
#include "CommandLine.h"

int main(int argc, char** argv) { return terralux::runCommandLine(argc, argv, terralux::Binary::Headless); }
