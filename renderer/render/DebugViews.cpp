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
