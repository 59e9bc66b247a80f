// The generated parts of the documentation match the tables they come from. After changing a
// parameter or a debug view, rewrite them with:
//   TERRALUX_UPDATE_DOCS=1 build/release/tests/test_docs
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "ParameterTable.h"
#include "scene/DebugViews.h"

namespace fs = std::filesystem;
using namespace terralux;

namespace {

const fs::path kSource = TERRALUX_SOURCE_DIR;

std::string readText(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

bool updating() {
    const char* v = std::getenv("TERRALUX_UPDATE_DOCS");
    return v && std::string(v) == "1";
}

// The text between `<!-- name:begin -->` and `<!-- name:end -->` in `file` must be `generated`.
void expectBlock(const fs::path& file, const std::string& name, const std::string& generated) {
    std::string text = readText(kSource / file);
    const std::string begin = "<!-- " + name + ":begin -->\n", end = "<!-- " + name + ":end -->";
    const size_t a = text.find(begin), b = text.find(end);
    ASSERT_NE(a, std::string::npos) << file << " has no " << begin;
    ASSERT_NE(b, std::string::npos) << file << " has no " << end;
    ASSERT_LT(a, b);
    const std::string current = text.substr(a + begin.size(), b - a - begin.size());
    if (updating() && current != generated) {
        text.replace(a + begin.size(), b - a - begin.size(), generated);
        std::ofstream(kSource / file, std::ios::binary) << text;
        return;
    }
    EXPECT_EQ(current, generated) << file << " block " << name
                                  << " is out of date: run TERRALUX_UPDATE_DOCS=1 test_docs";
}

}  // namespace

TEST(Docs, ParameterReferenceIsTheTable) {
    const fs::path file = kSource / "docs" / "parameters.md";
    const std::string generated = parameterReferenceMarkdown();
    if (updating() && readText(file) != generated) std::ofstream(file, std::ios::binary) << generated;
    EXPECT_EQ(readText(file), generated) << "docs/parameters.md is out of date: run TERRALUX_UPDATE_DOCS=1 test_docs";
    // Every parameter is in it.
    for (const auto& spec : parameterTable())
        EXPECT_NE(generated.find("`" + spec.path + "`"), std::string::npos) << spec.path;
}

TEST(Docs, WidgetNamesAreTheTable) {
    const std::string generated = uiObjectNamesMarkdown();
    for (const auto& spec : parameterTable())
        if (spec.uiRow) {
            EXPECT_NE(generated.find(uiObjectName(spec)), std::string::npos) << spec.path;
        }
    expectBlock("docs/UI_OBJECT_NAMES.md", "parameters", generated);
}

TEST(Docs, DebugViewTablesAreTheViewTable) {
    const std::string generated = debugViewsMarkdown();
    for (const auto& v : debugViews())
        EXPECT_NE(generated.find("| " + std::to_string(v.number) + " | `" + v.name + "` |"), std::string::npos);
    expectBlock("docs/lighting.md", "debug-views", generated);
    expectBlock("README.md", "debug-views", generated);
}
