#include "LpvConsoleVariables.h"

#include <charconv>
#include <stdexcept>

namespace terralux {
namespace {

std::string shortest(double d) {
    char buf[32];
    const auto end = std::to_chars(buf, buf + sizeof buf, d).ptr;
    return std::string(buf, end);
}

}  // namespace

std::vector<std::pair<std::string, std::string>> lpvConsoleVariables(const LpvSettings& s) {
    if (!s.size) throw std::logic_error("lpv.size is unresolved: resolve it on the terrain (lpv::resolvedOn) first");
    auto flag = [](bool b) { return std::string(b ? "1" : "0"); };
    return {
        {"rEx.GI.Method", flag(s.enabled)},
        {"rEx.LPV.Size", shortest(*s.size)},
        {"rEx.LPV.FadeRange", shortest(s.fadeRange)},
        {"rEx.LPV.PropagationWeight", shortest(s.propagationWeight)},
        {"rEx.LPV.PropagationIterations", std::to_string(s.propagationIterations)},
        {"rEx.LPV.UpdateInterval", std::to_string(s.updateInterval)},
        {"rEx.LPV.NumCascades", std::to_string(s.cascades)},
        {"rEx.LPV.CascadeRatio", shortest(s.cascadeRatio)},
        {"rEx.LPV.AutoCascadeMinSize", shortest(s.autoCascadeMinSize)},
        {"rEx.LPV.CascadeForwardOffset", shortest(s.cascadeForwardOffset)},
        {"rEx.LPV.EnableLocalLights", flag(s.localLights)},
        {"rEx.LPV.Quality", std::to_string(s.quality)},
        {"rEx.LPV.ConeTraceSamples", std::to_string(s.coneTraceSamples)},
    };
}

nlohmann::json lpvConsoleVariablesJson(const LpvSettings& s) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [name, value] : lpvConsoleVariables(s)) out[name] = nlohmann::json::parse(value);
    return out;
}

std::string lpvIni(const LpvSettings& s) {
    std::string out = "[SystemSettings]\n";
    for (const auto& [name, value] : lpvConsoleVariables(s)) out += name + "=" + value + "\n";
    out += "; IndirectLightingIntensity=" + shortest(s.indirectIntensity) +
           " (post-process setting, not a console variable)\n";
    return out;
}

}  // namespace terralux
