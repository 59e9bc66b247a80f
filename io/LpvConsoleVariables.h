#pragma once
// The LPV settings as the engine's console variables (seed 003; docs/formats.md, "lpv.ini"): one
// place for the key-to-variable mapping, read by the lpv.ini writer and TERRALUX_lighting.lpv.

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/SceneDescription.h"

namespace terralux {

// (console variable, value) in the order of the parameter table's lpv rows: rEx.GI.Method first.
// Booleans are 0 or 1, integers plain, numbers the shortest decimal that reads back as the same
// double. lpv.indirect_intensity is a post-process setting, not a console variable: not here.
std::vector<std::pair<std::string, std::string>> lpvConsoleVariables(const LpvSettings& lpv);
// The same as a JSON object of numbers, {"rEx.GI.Method": 1, ...}.
nlohmann::json lpvConsoleVariablesJson(const LpvSettings& lpv);
// lpv.ini: a `[SystemSettings]` section, one `NAME=value` line per console variable, and the
// indirect intensity as a comment line. "\n" line ends.
std::string lpvIni(const LpvSettings& lpv);

}  // namespace terralux
