// The debug-view table: one definition (shaders/debug_views.def) for the numbers, read by the
// C++ table, the shaders and every user of a view number.
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "scene/DebugViews.h"

using namespace terralux;

TEST(DebugViews, NumbersAndNamesAreUnique) {
    std::set<int> numbers;
    std::set<std::string> names;
    for (const auto& v : debugViews()) {
        EXPECT_TRUE(numbers.insert(v.number).second) << "number " << v.number << " twice";
        EXPECT_TRUE(names.insert(v.name).second) << "name " << v.name << " twice";
        EXPECT_NE(std::string(v.shows), "") << v.name;
    }
}

TEST(DebugViews, TableAndShaderListAgree) {
    // The shaders get kView<Name> constants and their dispatch from the same list: the table must
    // hold exactly those numbers, in the same order.
    std::vector<int> table;
    for (const auto& v : debugViews()) table.push_back(v.number);
    EXPECT_EQ(table, shaderViewNumbers());
}

TEST(DebugViews, LookUpByNumberAndName) {
    for (const auto& v : debugViews()) {
        ASSERT_TRUE(findDebugView(v.number));
        EXPECT_EQ(findDebugView(v.number)->name, std::string(v.name));
        EXPECT_EQ(findDebugView(std::string(v.name))->number, v.number);
        EXPECT_EQ(findDebugView(std::to_string(v.number))->number, v.number);
    }
    EXPECT_FALSE(findDebugView("no-such-view"));
    EXPECT_EQ(std::string(findDebugView(kViewInterpolationError)->name), "interpolation-error");
}

TEST(DebugViews, NeedsAreConsistent) {
    for (const auto& v : debugViews()) {
        // A view reads probe light or its diagnostics, never both (one attribute per vertex).
        EXPECT_FALSE(v.needs.probeLight && v.needs.probeDiagnostics) << v.name;
        // Markers of moved and rejected probes only make sense with their diagnostics.
        if (v.needs.probeMarkers) {
            EXPECT_TRUE(v.needs.probeDiagnostics) << v.name;
        }
    }
    EXPECT_TRUE(findDebugView(kViewProbeValidity)->needs.probeMarkers);
    EXPECT_EQ(diagnosticsViewList(), "views " + std::to_string(kViewProbeValidity) + " and " +
                                         std::to_string(kViewInterpolationError));
}
