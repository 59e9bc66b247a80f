// The lpv.ini writer's round trip. The input is the project's `lpv` section as JSON text: the
// loader's rules decide what an engine may receive, and for every section they accept, lpv.ini
// holds one `NAME=value` line per console variable, in the documented order, whose value reads
// back as exactly the setting (integers exactly, numbers as the same double), and
// TERRALUX_lighting.lpv's console variables say the same. Refusals are ProjectError.

#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "FuzzSupport.h"
#include "LpvConsoleVariables.h"
#include "Project.h"

using namespace terralux;
using json = nlohmann::json;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const json section = json::parse(std::string(reinterpret_cast<const char*>(data), size), nullptr, false);
    if (section.is_discarded() || !section.is_object()) return 0;
    json doc = defaultProjectJson();
    for (const auto& [key, value] : section.items()) doc["lpv"][key] = value;
    SceneDescription scene;
    try {
        scene = sceneFromJson(doc, "fuzz.terralux.json", nullptr);
    } catch (const ProjectError&) {
        return 0;
    }
    // A null size is resolved on the terrain before anything writes it; any resolved value here.
    LpvSettings lpv = scene.lpv;
    if (!lpv.size) lpv.size = 5312.0;
    const std::string ini = lpvIni(lpv);
    const auto variables = lpvConsoleVariables(lpv);
    const json asJson = lpvConsoleVariablesJson(lpv);

    std::istringstream in(ini);
    std::string line;
    FUZZ_CHECK(std::getline(in, line) && line == "[SystemSettings]");
    for (const auto& [name, value] : variables) {
        FUZZ_CHECK(std::getline(in, line));
        FUZZ_CHECK(line == name + "=" + value);
        char* end = nullptr;
        const double read = std::strtod(value.c_str(), &end);
        FUZZ_CHECK(end && *end == '\0');
        FUZZ_CHECK(asJson.contains(name) && asJson[name].get<double>() == read);
    }
    FUZZ_CHECK(std::getline(in, line) && line.rfind("; IndirectLightingIntensity=", 0) == 0);
    FUZZ_CHECK(!std::getline(in, line));

    // Every setting the section names reads back from its line.
    auto cvar = [&](const char* name) {
        for (const auto& [n, v] : variables)
            if (n == name) return std::strtod(v.c_str(), nullptr);
        FUZZ_CHECK(!"console variable missing");
        return 0.0;
    };
    FUZZ_CHECK(cvar("rEx.GI.Method") == (lpv.enabled ? 1.0 : 0.0));
    FUZZ_CHECK(cvar("rEx.LPV.Size") == *lpv.size);
    FUZZ_CHECK(cvar("rEx.LPV.FadeRange") == lpv.fadeRange);
    FUZZ_CHECK(cvar("rEx.LPV.PropagationWeight") == lpv.propagationWeight);
    FUZZ_CHECK(cvar("rEx.LPV.PropagationIterations") == lpv.propagationIterations);
    FUZZ_CHECK(cvar("rEx.LPV.UpdateInterval") == lpv.updateInterval);
    FUZZ_CHECK(cvar("rEx.LPV.NumCascades") == lpv.cascades);
    FUZZ_CHECK(cvar("rEx.LPV.CascadeRatio") == lpv.cascadeRatio);
    FUZZ_CHECK(cvar("rEx.LPV.AutoCascadeMinSize") == lpv.autoCascadeMinSize);
    FUZZ_CHECK(cvar("rEx.LPV.CascadeForwardOffset") == lpv.cascadeForwardOffset);
    FUZZ_CHECK(cvar("rEx.LPV.EnableLocalLights") == (lpv.localLights ? 1.0 : 0.0));
    FUZZ_CHECK(cvar("rEx.LPV.Quality") == lpv.quality);
    FUZZ_CHECK(cvar("rEx.LPV.ConeTraceSamples") == lpv.coneTraceSamples);
    return 0;
}
