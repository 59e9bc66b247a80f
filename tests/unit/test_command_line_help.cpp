// The help of both binaries and their manual pages come from one set of entries: what one says,
// the other says, and the headless binary offers nothing it cannot do.
#include <gtest/gtest.h>

#include <regex>

#include "CommandLineHelp.h"
#include "ParameterTable.h"

using namespace terralux;

namespace {

std::vector<std::string> optionNames(const CommandLineHelp& h) {
    std::vector<std::string> names;
    for (const auto* list : {&h.commands, &h.options})
        for (const HelpEntry& e : *list) names.push_back(e.syntax.substr(0, e.syntax.find_first_of(" ,")));
    return names;
}

// "--debug-view" as roff writes it: "\-\-debug\-view".
std::string roffName(const std::string& s) { return std::regex_replace(s, std::regex("-"), "\\-"); }

}  // namespace

TEST(CommandLineHelp, HeadlessOffersNoAuthoringCommand) {
    const CommandLineHelp full = commandLineHelp(Binary::Authoring), bake = commandLineHelp(Binary::Headless);
    const auto fullNames = optionNames(full), bakeNames = optionNames(bake);
    for (const std::string& only : authoringOnlyOptions()) {
        EXPECT_NE(std::find(fullNames.begin(), fullNames.end(), "--" + only), fullNames.end()) << only;
        EXPECT_EQ(std::find(bakeNames.begin(), bakeNames.end(), "--" + only), bakeNames.end()) << only;
    }
    // Everything else is in both.
    EXPECT_EQ(fullNames.size(), bakeNames.size() + authoringOnlyOptions().size());
    const std::string text = helpText(bake);
    EXPECT_EQ(text.rfind("Usage: terralux-bake ", 0), 0u) << text;
    EXPECT_EQ(text.find("--render"), text.find("--render and --study are in terralux")) << text;
    EXPECT_NE(text.find("--bake [PROJECT]"), std::string::npos);
}

TEST(CommandLineHelp, HelpLinesFitAndEveryEntryIsListed) {
    for (Binary b : {Binary::Authoring, Binary::Headless}) {
        const CommandLineHelp h = commandLineHelp(b);
        const std::string text = helpText(h);
        std::istringstream lines(text);
        std::string line;
        while (std::getline(lines, line)) EXPECT_LE(line.size(), 97u) << line;
        for (const std::string& name : optionNames(h)) EXPECT_NE(text.find("  " + name), std::string::npos) << name;
    }
}

TEST(CommandLineHelp, ManualPageCarriesTheHelpAndEveryParameter) {
    for (Binary b : {Binary::Authoring, Binary::Headless}) {
        const CommandLineHelp h = commandLineHelp(b);
        const std::string page = manualPage(h, "1.2.3", "2026-11-26");
        EXPECT_EQ(page.find(".TH " + std::string(b == Binary::Authoring ? "TERRALUX" : "TERRALUX\\-BAKE") +
                            " 1 \"2026-11-26\" \"" + roffName(h.program) + " 1.2.3\""),
                  page.find(".TH ")) << page.substr(0, 300);
        for (const std::string& name : optionNames(h))
            EXPECT_NE(page.find("\\fB" + roffName(name) + "\\fR"), std::string::npos) << h.program << " " << name;
        for (const ParameterSpec& spec : parameterTable())
            EXPECT_NE(page.find("\\fB" + roffName(spec.path) + "\\fR"), std::string::npos) << spec.path;
        for (const HelpEntry& code : h.exitCodes) EXPECT_NE(page.find(".B " + code.syntax + "\n"), std::string::npos);
        // No line of prose may start as a roff request by accident.
        std::istringstream lines(page);
        std::string line;
        while (std::getline(lines, line)) {
            if (!line.empty() && (line[0] == '.' || line[0] == '\'')) {
                EXPECT_TRUE(std::regex_match(line, std::regex(R"(^\.(\\"|TH|SH|SS|TP|PP|B|BI|BR|I|br|nh)( .*)?$)"))) << line;
            }
        }
    }
}

TEST(CommandLineHelp, ManualPageEscapesRoff) {
    CommandLineHelp h = commandLineHelp(Binary::Headless);
    h.options.push_back({"--odd", ".starts with a dot\n'and a quote, a back\\slash"});
    const std::string page = manualPage(h, "1", "d");
    EXPECT_NE(page.find("\\&.starts with a dot"), std::string::npos);
    EXPECT_NE(page.find("\\&'and a quote, a back\\eslash"), std::string::npos);
}
