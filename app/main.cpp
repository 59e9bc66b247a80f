#include "CommandLine.h"

int main(int argc, char** argv) { return terralux::runCommandLine(argc, argv); }
