#pragma once
// The command line's documentation, written once: `--help` of both binaries and their manual
// pages (terralux(1), terralux-bake(1)) are drawn from these entries and the parameter table.

#include <string>
#include <vector>

namespace terralux {

enum class Binary {
    Authoring,  // terralux: the window and every command
    Headless,   // terralux-bake: the commands that need no display and no GPU
};

struct HelpEntry {
    std::string syntax;  // "--bake [PROJECT]"
    // Prose; '\n' starts a new line, and a line starting with spaces is kept as it is (examples).
    std::string text;
};

struct CommandLineHelp {
    std::string program;  // "terralux"
    std::string summary;  // one line, the manual's NAME
    struct Usage {
        std::string arguments, meaning;
    };
    std::vector<Usage> usage;
    std::string description;
    std::vector<HelpEntry> commands, options;
    std::string sample;  // what the commands use without a project
    std::vector<HelpEntry> exitCodes;
};

CommandLineHelp commandLineHelp(Binary binary);

// The commands only the authoring binary has, for the headless binary's refusal.
const std::vector<std::string>& authoringOnlyOptions();

// `--help`: wrapped to 97 columns, the prose in a column of its own.
std::string helpText(const CommandLineHelp& help);

// The manual page in roff (man(7)): the help, the project parameters from the parameter table, the
// environment and the files. `date` is the release date, "2026-11-26".
std::string manualPage(const CommandLineHelp& help, const std::string& version, const std::string& date);

}  // namespace terralux
