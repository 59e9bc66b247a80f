#include "Project.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <cstdio>
#include <sstream>

#include "AtomicFile.h"
#include "bake/PhysicalSky.h"
#include "ParameterTable.h"
#include "water/Water.h"

namespace terralux {
namespace {

// A pattern compiles once: every edit reads the whole project back, and compiling the names'
// patterns each time was a tenth of an edit's milliseconds on the UI thread. A compiled regex
// is only read after, from any thread.
const std::regex& compiledPattern(const std::string& pattern) {
    static std::mutex mutex;
    static std::map<std::string, std::regex> compiled;
    const std::lock_guard<std::mutex> lock(mutex);
    auto it = compiled.find(pattern);
    if (it == compiled.end()) it = compiled.emplace(pattern, std::regex(pattern)).first;
    return it->second;
}

using nlohmann::json;

std::string show(const json& v) {
    // replace: a string from the command line may hold bytes that are not UTF-8.
    std::string s = v.dump(-1, ' ', false, json::error_handler_t::replace);
    if (s.size() > 60) s = s.substr(0, 57) + "...";
    return s;
}

// Where s stops being well-formed UTF-8 (RFC 3629: no overlong forms, surrogates or code
// points past U+10FFFF), or npos.
size_t firstInvalidUtf8(const std::string& s) {
    size_t i = 0;
    while (i < s.size()) {
        const auto c = static_cast<unsigned char>(s[i]);
        size_t n = 0;
        unsigned cp = 0, min = 0;
        if (c < 0x80) {
            ++i;
            continue;
        } else if ((c & 0xE0) == 0xC0) {
            n = 1, cp = c & 0x1F, min = 0x80;
        } else if ((c & 0xF0) == 0xE0) {
            n = 2, cp = c & 0x0F, min = 0x800;
        } else if ((c & 0xF8) == 0xF0) {
            n = 3, cp = c & 0x07, min = 0x10000;
        } else {
            return i;
        }
        if (i + n >= s.size()) return i;  // truncated sequence
        for (size_t k = 1; k <= n; ++k) {
            const auto t = static_cast<unsigned char>(s[i + k]);
            if ((t & 0xC0) != 0x80) return i;
            cp = (cp << 6) | (t & 0x3F);
        }
        if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return i;
        i += n + 1;
    }
    return std::string::npos;
}

std::string trim(double d) {
    std::ostringstream s;
    s << d;
    return s.str();
}

[[noreturn]] void reject(const std::string& source, const std::string& path, const json& value,
                         const std::string& rule) {
    throw ProjectError(source + ": " + path + " = " + show(value) + ": " + rule);
}

// The row's own checks: type, range, length, pattern, null. Throws naming path, value and rule.
void checkValue(const ParameterSpec& spec, const json& v, const std::string& path, int count,
                const std::string& source) {
    const std::string orNull = spec.nullable() ? " or null" : "";
    if (v.is_null()) {
        if (spec.nullable()) return;
        reject(source, path, v, "must not be null");
    }
    auto isWhole = [](const json& e) {
        return e.is_number_integer() || (e.is_number_float() && std::isfinite(e.get<double>()) &&
                                         std::floor(e.get<double>()) == e.get<double>());
    };
    auto inRange = [&](double d) {
        return (spec.minExclusive ? d > spec.min : d >= spec.min) &&
               (spec.maxExclusive ? d < spec.max : d <= spec.max);
    };
    // One number of the row (the value itself, or a list element at `at`).
    auto scalar = [&](const json& e, const std::string& at, bool integer, const std::string& suffix) {
        if (!e.is_number()) reject(source, at, e, "must be a number");
        if (!std::isfinite(e.get<double>())) reject(source, at, e, "must be finite");
        if (integer && !isWhole(e)) reject(source, at, e, "must be an integer");
        if (!inRange(e.get<double>())) reject(source, at, e, "must be " + std::string(std::isinf(spec.max) ? "" : "in ") + spec.rangeText() + suffix);
    };
    auto list = [&](bool integer) {
        const bool scalarForm = count == 0 || (count < 0 && spec.scalarAllowed && v.is_number());
        if (scalarForm) return scalar(v, path, integer, orNull);
        const int lo = count > 0 ? count : spec.minItems, hi = count > 0 ? count : spec.maxItems;
        if (!v.is_array() || int(v.size()) < lo || int(v.size()) > hi)
            reject(source, path, v, "must be an array of " + (lo == hi ? std::to_string(lo) : std::to_string(lo) + (hi == lo + 1 ? " or " : " to ") + std::to_string(hi)) + " numbers" + orNull);
        for (size_t i = 0; i < v.size(); ++i) scalar(v[i], path + "[" + std::to_string(i) + "]", integer, "");
    };
    switch (spec.type) {
        case ParamType::Number: return scalar(v, path, false, orNull);
        case ParamType::Integer: return scalar(v, path, true, orNull);
        case ParamType::Boolean:
            if (!v.is_boolean()) reject(source, path, v, "must be true or false");
            return;
        case ParamType::String:
            if (!v.is_string()) reject(source, path, v, "must be a string");
            if (!spec.pattern.empty() && !std::regex_match(v.get<std::string>(), compiledPattern(spec.pattern)))
                reject(source, path, v, spec.patternRule);
            return;
        case ParamType::Choice:
            if (!v.is_string() || std::find(spec.choices.begin(), spec.choices.end(), v.get<std::string>()) == spec.choices.end())
                reject(source, path, v, "must be " + spec.rangeText());
            return;
        case ParamType::Color:
            if (!v.is_array() || v.size() != 3) reject(source, path, v, "must be an array of 3 numbers");
            for (size_t i = 0; i < 3; ++i)
                if (!v[i].is_number() || !std::isfinite(v[i].get<double>()) || !inRange(v[i].get<double>()))
                    reject(source, path + "[" + std::to_string(i) + "]", v[i],
                           "three components, each in [" + trim(spec.min) + ", " + (std::isinf(spec.max) ? std::string("inf") : trim(spec.max)) + "]");
            return;
        case ParamType::NumberList: return list(false);
        case ParamType::IntegerList: return list(true);
    }
}

// Edit distance, for "did you mean" on a misspelt key.
size_t distance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diag = up;
        }
    }
    return row[b.size()];
}

std::string suggestion(const std::string& normalisedPath) {
    std::string best;
    size_t bestDistance = 4;  // further than 3 edits is no suggestion
    auto consider = [&](const std::string& candidate) {
        const size_t d = distance(normalisedPath, candidate);
        if (d < bestDistance) bestDistance = d, best = candidate;
    };
    for (const auto& p : parameterTable()) {
        consider(p.path);
        for (size_t dot = p.path.find('.'); dot != std::string::npos; dot = p.path.find('.', dot + 1))
            consider(p.path.substr(0, dot));
    }
    return best.empty() ? "" : " (did you mean '" + best + "'?)";
}

// Every key of `doc` must be a parameter or a section holding parameters.
void checkKeys(const json& obj, const std::string& path, const std::string& normalised,
               const std::string& source) {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
        const std::string child = path.empty() ? it.key() : path + "." + it.key();
        const std::string key = normalised.empty() ? it.key() : normalised + "." + it.key();
        if (path.empty() && (it.key() == "format" || it.key() == "version" || it.key() == "$schema")) continue;
        if (findParameter(key)) continue;
        if (std::find(objectLists().begin(), objectLists().end(), key) != objectLists().end()) {
            if (!it->is_array()) reject(source, child, *it, "must be an array");
            for (size_t i = 0; i < it->size(); ++i) {
                const std::string at = child + "[" + std::to_string(i) + "]";
                if (!(*it)[i].is_object()) reject(source, at, (*it)[i], "must be an object");
                checkKeys((*it)[i], at, key + "[]", source);
            }
            continue;
        }
        if (isParameterSection(key)) {
            if (!it->is_object()) reject(source, child, *it, "must be an object");
            checkKeys(*it, child, key, source);
            continue;
        }
        std::string suggested = suggestion(key);
        if (suggested.empty()) suggested = " (terralux --print-project lists them)";
        throw ProjectError(source + ": unknown key '" + child + "'" + suggested);
    }
}

// The value at a dotted path below `obj`; nullptr when absent.
const json* lookup(const json& obj, const std::string& dotted) {
    const json* node = &obj;
    size_t start = 0;
    while (true) {
        const size_t dot = dotted.find('.', start);
        const std::string key = dotted.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
        if (!node->is_object()) return nullptr;
        const auto it = node->find(key);
        if (it == node->end()) return nullptr;
        node = &*it;
        if (dot == std::string::npos) return node;
        start = dot + 1;
    }
}

void place(json& obj, const std::string& dotted, json value) {
    json* node = &obj;
    size_t start = 0;
    while (true) {
        const size_t dot = dotted.find('.', start);
        if (dot == std::string::npos) {
            (*node)[dotted.substr(start)] = std::move(value);
            return;
        }
        node = &(*node)[dotted.substr(start, dot - start)];
        start = dot + 1;
    }
}

// Reads one row from `obj` (absent: its default), checks it and sets it into the scene.
void readRow(const ParameterSpec& spec, const json& obj, const std::string& prefix, size_t volume,
             SceneDescription& s, const std::string& source) {
    const json* found = lookup(obj, spec.localPath());
    const json value = found ? *found : spec.defaultValue();
    const std::string path = prefix + spec.localPath();
    const int count = spec.items ? spec.items(s, volume) : -1;
    if (spec.items && count < 0) return;  // not read for this scene (adaptive grid_dims)
    checkValue(spec, value, path, count, source);
    try {
        spec.set(s, volume, value);
    } catch (const ParameterRejection& r) {
        reject(source, path + r.subPath, value, r.rule);
    }
}

// The elements of one list of objects (objectLists), each with every row of its elements.
json listToJson(const SceneDescription& s, const std::string& list, size_t count) {
    json out = json::array();
    for (size_t i = 0; i < count; ++i) {
        json element = json::object();
        for (const auto& spec : parameterTable())
            if (spec.listPath() == list) place(element, spec.localPath(), spec.get(s, i));
        out.push_back(std::move(element));
    }
    return out;
}

// Reads the rows of every element of `list` from the array `elements`; the scene already holds
// that many default elements.
void readList(const std::string& list, const json& elements, SceneDescription& s, const std::string& source) {
    for (size_t i = 0; i < elements.size(); ++i) {
        const std::string prefix = list + "[" + std::to_string(i) + "].";
        for (const auto& spec : parameterTable())
            if (spec.listPath() == list) readRow(spec, elements[i], prefix, i, s, source);
    }
}

}  // namespace

json sceneToJson(const SceneDescription& s) {
    json doc = {{"format", "terralux-project"}, {"version", kProjectVersion}};
    for (const auto& spec : parameterTable())
        if (!spec.inList()) place(doc, spec.path, spec.get(s, 0));
    place(doc, "probe_volumes", listToJson(s, "probe_volumes", s.probeVolumes.size()));
    place(doc, "water.waves", listToJson(s, "water.waves", s.water.waves.size()));
    place(doc, "lights", listToJson(s, "lights", s.lights.size()));
    place(doc, "scenarios", listToJson(s, "scenarios", s.scenarios.size()));
    return doc;
}

json defaultProjectJson() { return sceneToJson(SceneDescription{}); }

namespace {

// A version's value in scene units as the photometric unit it stands for (lux, candela, cd/m²),
// to the thousandth: the scene units' decimals give no more, and the sun's 3 gives 100 000 lx.
double fromSceneUnits(double v) { return std::round(v / kSceneUnitsPerLux * 1000.0) / 1000.0; }

// section[key] when it is an object, else null: a step leaves anything else for the check to name.
json* objectIn(json& section, const char* key) {
    if (!section.is_object() || !section.contains(key) || !section[key].is_object()) return nullptr;
    return &section[key];
}

// A radiance in scene units, `section`.color, as a colour in [0, 1] (divided by its largest
// component; black stays black) and `section`.luminance in cd/m² (that component,
// fromSceneUnits): the same light. The note names `where` + `name`; anything but three
// non-negative numbers is left for the check to name.
void radianceToLuminance(json& section, const std::string& name, const std::string& where,
                         std::vector<std::string>& notes) {
    if (!section.contains("color") || !section["color"].is_array() || section["color"].size() != 3) return;
    double peak = 0.0;
    for (const json& c : section["color"]) {
        if (!c.is_number() || c.get<double>() < 0.0) return;
        peak = std::max(peak, c.get<double>());
    }
    const json before = section["color"];
    const double cd = fromSceneUnits(peak);
    if (peak > 0.0)
        for (json& c : section["color"]) c = shortestDecimal(float(c.get<double>() / peak));
    section["luminance"] = cd;
    notes.push_back(where + name + ".color " + before.dump() + " is " + section["color"].dump() + " at " +
                    json(cd).dump() + " cd/m²");
}

// A migration step's edit of a sun or sky applied to the project's own lighting and to each
// scenario's: fn(section, where), where "" or "scenarios[i]." prefixes the step's notes.
template <typename Fn>
void forEachLighting(json& doc, Fn&& fn) {
    fn(doc, std::string());
    if (doc.contains("scenarios") && doc["scenarios"].is_array())
        for (size_t i = 0; i < doc["scenarios"].size(); ++i)
            fn(doc["scenarios"][i], "scenarios[" + std::to_string(i) + "].");
}

}  // namespace

const std::vector<ProjectMigration>& projectMigrations() {
    static const std::vector<ProjectMigration> steps = {
        {1,
         "terrain.albedo_mode's default became the height ramp: a version-1 file without it lit the "
         "terrain with terrain.albedo alone, so it gets \"constant\"; reflection_probes.ground_color became "
         "an albedo, so channels above 1 are clamped to 1",
         [](json& doc, std::vector<std::string>& notes) {
             if (!doc.contains("terrain") || !doc["terrain"].is_object()) doc["terrain"] = json::object();
             if (!doc["terrain"].contains("albedo_mode")) {
                 doc["terrain"]["albedo_mode"] = "constant";
                 notes.push_back("terrain.albedo_mode set to \"constant\", what version 1 drew without it");
             }
             if (doc.contains("reflection_probes") && doc["reflection_probes"].is_object() &&
                 doc["reflection_probes"].contains("ground_color") && doc["reflection_probes"]["ground_color"].is_array()) {
                 json& c = doc["reflection_probes"]["ground_color"];
                 bool clamped = false;
                 for (auto& x : c)
                     if (x.is_number() && x.get<double>() > 1.0) {
                         x = 1.0;
                         clamped = true;
                     }
                 if (clamped) notes.push_back("reflection_probes.ground_color clamped to [0, 1] (it is an albedo since version 2)");
             }
         }},
        {2,
         "fog.height_falloff (1/m) became fog.scale_height (m), its reciprocal: the same fog",
         [](json& doc, std::vector<std::string>& notes) {
             if (!doc.contains("fog") || !doc["fog"].is_object() || !doc["fog"].contains("height_falloff")) return;
             json& fog = doc["fog"];
             const json falloff = fog["height_falloff"];
             fog.erase("height_falloff");
             // Anything but a number is left for the check to name under its new key.
             if (!falloff.is_number()) {
                 fog["scale_height"] = falloff;
                 return;
             }
             const double f = falloff.get<double>();
             fog["scale_height"] = f > 0.0 ? 1.0 / f : f;
             notes.push_back("fog.height_falloff " + falloff.dump() + " is fog.scale_height " + fog["scale_height"].dump() + " m");
         }},
        {3,
         "sun.illuminance became lux: a version-3 value in scene units is divided by kSceneUnitsPerLux "
         "(3 became 100 000 lx), the same light; so are the scenarios' suns",
         [](json& doc, std::vector<std::string>& notes) {
             auto toLux = [&](json& section, const std::string& where) {
                 json* sun = objectIn(section, "sun");
                 if (!sun || !sun->contains("illuminance") || !(*sun)["illuminance"].is_number()) return;
                 const double before = (*sun)["illuminance"].get<double>();
                 const double lux = fromSceneUnits(before);
                 (*sun)["illuminance"] = lux;
                 notes.push_back(where + "sun.illuminance " + json(before).dump() + " is " + json(lux).dump() + " lx");
             };
             forEachLighting(doc, toLux);
         }},
        {4,
         "lights[].intensity became candela: a version-4 value in scene units at 1 m is divided by "
         "kSceneUnitsPerLux (1000 became 33 333 333 cd), the same light",
         [](json& doc, std::vector<std::string>& notes) {
             if (!doc.contains("lights") || !doc["lights"].is_array()) return;
             for (size_t i = 0; i < doc["lights"].size(); ++i) {
                 json& light = doc["lights"][i];
                 // Anything but a number is left for the check to name.
                 if (!light.is_object() || !light.contains("intensity") || !light["intensity"].is_number()) continue;
                 const double before = light["intensity"].get<double>();
                 const double cd = fromSceneUnits(before);
                 light["intensity"] = cd;
                 notes.push_back("lights[" + std::to_string(i) + "].intensity " + json(before).dump() + " is " +
                                 json(cd).dump() + " cd");
             }
         }},
        {5,
         "the uniform sky's sky.color (radiance in scene units) became a colour in [0, 1] and sky.luminance in cd/m²: "
         "the colour is divided by its largest component and the luminance is that component divided by "
         "kSceneUnitsPerLux ((0.09, 0.11, 0.15) became (0.6, 0.733, 1) at 5 000 cd/m²), the same sky; so are the scenarios' skies",
         [](json& doc, std::vector<std::string>& notes) {
             // An absent colour was version 5's default, which is version 6's default sky.
             forEachLighting(doc, [&](json& section, const std::string& where) {
                 if (json* sky = objectIn(section, "sky")) radianceToLuminance(*sky, "sky", where, notes);
             });
         }},
        {6,
         "fog.color (the fog's ambient radiance in scene units) became a colour in [0, 1] and fog.luminance in "
         "cd/m², as the uniform sky's did in version 6: the same fog; an unset colour stays unset (the sky's mean)",
         [](json& doc, std::vector<std::string>& notes) {
             if (json* fog = objectIn(doc, "fog")) radianceToLuminance(*fog, "fog", "", notes);
         }},
        {7,
         "sun.follow_sky now takes an image sky's sun as the sun: a version-7 image sky lit whole, the authored "
         "sun beside it, so it gets sun.follow_sky false; so do the scenarios' image skies",
         [](json& doc, std::vector<std::string>& notes) {
             forEachLighting(doc, [&](json& section, const std::string& where) {
                 const json* sky = objectIn(section, "sky");
                 if (!sky || !sky->contains("mode") || (*sky)["mode"] != "hdr") return;
                 if (!section.contains("sun")) section["sun"] = json::object();
                 // Anything but an object under "sun" is left for the check to name.
                 if (json* sun = objectIn(section, "sun")) {
                     (*sun)["follow_sky"] = false;
                     notes.push_back(where + "sun.follow_sky set to false: version 7 lit the image whole with the authored sun");
                 }
             });
         }},
    };
    return steps;
}

json migrateProjectJson(json doc, const std::string& source, std::vector<std::string>* notes) {
    if (!doc.is_object()) throw ProjectError(source + ": the project must be a JSON object");
    const json* v = lookup(doc, "version");
    if (!v) return doc;
    if (!v->is_number_integer() || v->get<long long>() < 1) reject(source, "version", *v, "must be an integer >= 1");
    if (v->get<long long>() > kProjectVersion)
        reject(source, "version", *v,
               "is newer than this Terralux reads (" + std::to_string(kProjectVersion) + "); open it with a newer Terralux");
    for (int from = int(v->get<long long>()); from < kProjectVersion; ++from) {
        const auto& steps = projectMigrations();
        const auto step = std::find_if(steps.begin(), steps.end(), [&](const ProjectMigration& m) { return m.from == from; });
        std::vector<std::string> stepNotes;
        step->apply(doc, stepNotes);
        doc["version"] = from + 1;
        if (notes)
            for (const auto& n : stepNotes)
                notes->push_back(source + ": version " + std::to_string(from) + " migrated to " + std::to_string(from + 1) + ": " + n);
    }
    return doc;
}

SceneDescription sceneFromJson(const json& original, const std::string& source,
                               std::vector<std::string>* warnings) {
    const json doc = migrateProjectJson(original, source, warnings);
    checkKeys(doc, "", "", source);
    if (const json* f = lookup(doc, "format"); f && *f != "terralux-project")
        reject(source, "format", *f, "must be \"terralux-project\"");

    SceneDescription s;
    if (const json* volumes = lookup(doc, "probe_volumes")) {
        s.probeVolumes.assign(volumes->size(), ProbeVolumeSettings{});
        readList("probe_volumes", *volumes, s, source);
        std::set<std::string> names;
        for (size_t i = 0; i < volumes->size(); ++i)
            if (!names.insert(s.probeVolumes[i].name).second)
                reject(source, "probe_volumes[" + std::to_string(i) + "].name", s.probeVolumes[i].name,
                       "must be unique among volumes");
    }
    if (const json* waves = lookup(doc, "water.waves")) {
        if (waves->size() > size_t(WaterSettings::kMaxWaves))
            reject(source, "water.waves", *waves,
                   "must hold at most " + std::to_string(WaterSettings::kMaxWaves) + " waves (has " +
                       std::to_string(waves->size()) + ")");
        s.water.waves.assign(waves->size(), GerstnerWave{});
        readList("water.waves", *waves, s, source);
        // Each wave passed its rows; what is left is the rule of the set (Σ k·A <= 1).
        if (const std::string rule = water::checkWaves(s.water.waves); !rule.empty())
            reject(source, "water.waves", *waves, rule);
    }
    if (const json* lights = lookup(doc, "lights")) {
        if (lights->size() > size_t(kMaxLocalLights))
            reject(source, "lights", *lights,
                   "must hold at most " + std::to_string(kMaxLocalLights) + " lights (has " +
                       std::to_string(lights->size()) + ")");
        s.lights.assign(lights->size(), LocalLight{});
        readList("lights", *lights, s, source);
    }
    if (const json* scenarios = lookup(doc, "scenarios")) {
        if (scenarios->size() > size_t(kMaxScenarios))
            reject(source, "scenarios", *scenarios,
                   "must hold at most " + std::to_string(kMaxScenarios) + " scenarios (has " +
                       std::to_string(scenarios->size()) + ")");
        s.scenarios.assign(scenarios->size(), LightingScenario{});
        readList("scenarios", *scenarios, s, source);
        std::set<std::string> names{kDefaultScenario};
        for (size_t i = 0; i < s.scenarios.size(); ++i)
            if (!names.insert(s.scenarios[i].name).second)
                reject(source, "scenarios[" + std::to_string(i) + "].name", s.scenarios[i].name,
                       std::string("must be unique among scenarios and not \"") + kDefaultScenario +
                           "\" (the project's own sun and sky)");
    }
    for (const auto& spec : parameterTable())
        if (!spec.inList()) readRow(spec, doc, "", 0, s, source);
    return s;
}

std::vector<std::string> scenarioNames(const SceneDescription& scene) {
    std::vector<std::string> names{kDefaultScenario};
    for (const LightingScenario& l : scene.scenarios) names.push_back(l.name);
    return names;
}

std::string knownScenario(const SceneDescription& scene, const std::string& name) {
    for (const LightingScenario& l : scene.scenarios)
        if (l.name == name) return name;
    return kDefaultScenario;
}

SceneDescription scenarioScene(const SceneDescription& scene, const std::string& name) {
    SceneDescription lit = scene;
    if (name == kDefaultScenario) return lit;
    for (const LightingScenario& l : scene.scenarios)
        if (l.name == name) {
            lit.sun = l.sun;
            lit.sky = l.sky;
            return lit;
        }
    std::string known;
    for (const std::string& n : scenarioNames(scene)) known += (known.empty() ? "" : ", ") + n;
    throw ProjectError("scenario '" + name + "': the project has no such lighting scenario (it has " + known + ")");
}

void applyOverride(json& doc, const std::string& assignment) {
    // JSON strings are UTF-8: a value that is not could neither be saved nor reported.
    if (const size_t bad = firstInvalidUtf8(assignment); bad != std::string::npos) {
        char byte[8];
        std::snprintf(byte, sizeof byte, "0x%02X", unsigned(static_cast<unsigned char>(assignment[bad])));
        throw ProjectError("--set: byte " + std::to_string(bad) + " (" + byte +
                           ") of the assignment is not UTF-8; parameters and paths must be UTF-8 text");
    }
    const size_t eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0)
        throw ProjectError("--set " + assignment + ": expected key.path=value");
    const std::string path = assignment.substr(0, eq);
    const std::string text = assignment.substr(eq + 1);

    // Tokens: names separated by '.', and [index] subscripts.
    json* node = &doc;
    std::string walked;
    size_t i = 0;
    while (i < path.size()) {
        if (path[i] == '.') {
            ++i;
            continue;
        }
        if (path[i] == '[') {
            const size_t close = path.find(']', i);
            const std::string idx = close == std::string::npos ? "" : path.substr(i + 1, close - i - 1);
            if (idx.empty() || idx.size() > 9 || idx.find_first_not_of("0123456789") != std::string::npos)
                throw ProjectError("--set " + path + ": bad index in '" + path.substr(i) + "'");
            const size_t n = std::stoul(idx);
            walked += "[" + idx + "]";
            if (!node->is_array() || n >= node->size())
                throw ProjectError("--set " + path + ": unknown parameter '" + walked + "'" +
                                   (node->is_array() ? " (there are " + std::to_string(node->size()) +
                                                           ")" : ""));
            node = &(*node)[n];
            i = close + 1;
            continue;
        }
        size_t end = path.find_first_of(".[", i);
        if (end == std::string::npos) end = path.size();
        const std::string key = path.substr(i, end - i);
        walked += (walked.empty() ? "" : ".") + key;
        if (!node->is_object() || !node->contains(key)) {
            const std::string suggested = suggestion(normaliseParameterPath(walked));
            throw ProjectError("--set " + path + ": unknown parameter '" + walked + "'" +
                               (suggested.empty() ? " (terralux --print-project lists them)" : suggested));
        }
        node = &(*node)[key];
        i = end;
    }
    if (node == &doc) throw ProjectError("--set " + assignment + ": expected key.path=value");

    json value = json::parse(text, nullptr, false);
    if (value.is_discarded()) {
        // A comma list sets an array parameter, or one that is unset (null) by default.
        if ((node->is_array() || node->is_null()) && text.find(',') != std::string::npos) {
            value = json::array();
            std::stringstream ss(text);
            std::string item;
            while (std::getline(ss, item, ',')) {
                json e = json::parse(item, nullptr, false);
                value.push_back(e.is_discarded() ? json(item) : e);
            }
        } else {
            value = text;
        }
    }
    *node = value;
}

std::filesystem::path Project::resolve(const std::string& relative) const {
    if (relative.empty()) return {};
    std::filesystem::path p(relative);
    if (p.is_absolute() || relative.rfind("/vsi", 0) == 0) return p;
    return (baseDir / p).lexically_normal();
}
std::filesystem::path Project::demPath() const { return resolve(scene.terrain.dem); }
std::filesystem::path Project::hdrPath() const { return resolve(scene.sky.hdr); }
std::filesystem::path Project::albedoMapPath() const { return resolve(scene.terrain.albedoMap); }
std::filesystem::path Project::outDir() const { return resolve(scene.exportSettings.outDir); }

Project loadProject(const std::filesystem::path& file, std::vector<std::string>* warnings) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw ProjectError(file.string() + ": cannot open the project file");
    json doc = json::parse(in, nullptr, false);
    if (doc.is_discarded()) {
        // Parse again with exceptions on for the position of the error.
        in.clear();
        in.seekg(0);
        try {
            const json again = json::parse(in);
            (void)again;
        } catch (const json::parse_error& e) {
            // "[json.exception.parse_error.101] parse error at line 3, column 5: syntax error ..."
            const std::string what = e.what();
            const size_t at = what.find("at line ");
            throw ProjectError(file.string() + ": not valid JSON " +
                               (at != std::string::npos ? what.substr(at)
                                                        : "(byte " + std::to_string(e.byte) + ")"));
        }
        throw ProjectError(file.string() + ": not valid JSON");
    }
    Project p;
    p.file = std::filesystem::absolute(file);
    p.baseDir = p.file.parent_path();
    p.scene = sceneFromJson(doc, file.string(), warnings);
    return p;
}

json projectToJson(const Project& project) { return sceneToJson(project.scene); }

void saveProject(const Project& project, const std::filesystem::path& file) {
    // Paths stay relative to the project file, so a project folder can move as a whole.
    Project copy = project;
    const std::filesystem::path dir = std::filesystem::absolute(file).parent_path();
    auto rebase = [&](std::string& rel) {
        if (rel.empty() || rel.rfind("/vsi", 0) == 0) return;
        const std::filesystem::path abs = project.resolve(rel);
        rel = abs.lexically_relative(dir).generic_string();
        if (rel.empty()) rel = abs.generic_string();
    };
    rebase(copy.scene.terrain.dem);
    rebase(copy.scene.sky.hdr);
    rebase(copy.scene.terrain.albedoMap);
    rebase(copy.scene.exportSettings.outDir);
    writeFileAtomically(file, projectToJson(copy).dump(2) + "\n");
}

}  // namespace terralux
