#include "render/DebugViews.h"

namespace terralux {

const std::vector<DebugView>& debugViews() {
    static const std::vector<DebugView> views = {
        {0, "beauty", "final image", false},
        {1, "albedo", "surface albedo", false},
        {2, "normal", "world normal as colour", false},
        {30, "ndotl", "N·L", false},
        {32, "linear", "pre-tonemap colour", true},
        {50, "probe-irradiance", "probe irradiance × weight", true},
        {51, "probe-weight", "probe blend weight", false},
        {54, "probe-validity",
         "invalid / relocated probes: grey lit by probes at their placement, cyan by moved probes, "
         "red inside a volume with no valid probe; markers cyan moved, red rejected (with the probe "
         "overlay also gold valid)",
         false},
        {56, "interpolation-error",
         "interpolation error heat map: blue 0 %, cyan 2.5 %, green 5 %, yellow 7.5 %, red 10 % and "
         "above, grey unmeasured (EXR: error in red, 1 in green where measured)",
         true},
    };
    return views;
}

std::optional<DebugView> findDebugView(const std::string& s) {
    for (const auto& v : debugViews())
        if (s == v.name || s == std::to_string(v.number)) return v;
    return std::nullopt;
}

std::string debugViewList() {
    std::string out;
    for (const auto& v : debugViews())
        out += (out.empty() ? "" : ", ") + std::to_string(v.number) + " " + v.name;
    return out;
}

}  // namespace terralux
