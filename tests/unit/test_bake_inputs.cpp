// What a bake reads comes from the parameter table (ParameterSpec::bake): these tests walk every
// row. A row the bake reads changes the bake's inputs when it changes; a row it ignores does not,
// and a bake with every ignored row changed writes the same probes, byte for byte.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "BakeJob.h"
#include "ImageFile.h"
#include "ParameterTable.h"
#include "Project.h"

using namespace terralux;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

const fs::path kCrop = fs::path(TERRALUX_TEST_DATA) / "dem" / "bigtujunga_utm11_crop.tif";

// Scenes that between them read every row: each switches on what the defaults leave off
// (water with a wave, a light, reflection probes, shadows, fog, detail, AO, the LPV) and picks
// one mode of each choice that hides rows.
std::vector<SceneDescription> coveringScenes(json doc = defaultProjectJson(), const std::string& albedoMap = "albedo.png",
                                             const std::string& hdr = "sky.hdr") {
    doc["water"]["enabled"] = true;
    doc["water"]["waves"] = json::array({json{{"amplitude", 0.2}}});
    doc["lights"] = json::array({json{{"type", "spot"}}});
    doc["scenarios"] = json::array({json{{"name", "dusk"}}});
    for (const char* section : {"reflection_probes", "shadows", "fog", "detail", "ao", "lpv"})
        doc[section]["enabled"] = true;
    std::vector<json> docs;
    auto with = [&](const std::string& pointer, const json& value) {
        json d = doc;
        d[json::json_pointer(pointer)] = value;
        docs.push_back(d);
    };
    docs.push_back(doc);
    with("/terrain/albedo_mode", "constant");
    with("/terrain/albedo_mode", "ramp");
    with("/terrain/albedo_mode", "map");
    with("/sky/mode", "uniform");
    with("/sky/mode", "physical");
    with("/sky/mode", "hdr");
    with("/sun/mode", "date_time");
    with("/scenarios/0/sky/mode", "physical");
    with("/scenarios/0/sky/mode", "hdr");
    with("/scenarios/0/sun/mode", "date_time");
    with("/probe_volumes/0/placement", "box");
    docs.back()["probe_volumes"][0]["grid_dims"] = {4, 2, 4};
    with("/probe_volumes/0/placement", "adaptive");
    with("/shadows/split_mode", "manual");
    docs.back()["shadows"]["splits"] = {100.0, 300.0, 1000.0};
    with("/shadows/split_mode", "practical");
    with("/camera/exposure_mode", "manual");
    with("/lighting/indirect", "both");
    with("/lpv/quality", 2);
    with("/water/waves", json::array({json{{"steepness", 0.1}}}));
    std::vector<SceneDescription> scenes;
    for (json& d : docs) {
        if (d["terrain"]["albedo_mode"] == "map") d["terrain"]["albedo_map"] = albedoMap;
        if (d["sky"]["mode"] == "hdr") d["sky"]["hdr"] = hdr;
        if (d["scenarios"][0].value("sky", json::object()).value("mode", "") == "hdr") d["scenarios"][0]["sky"]["hdr"] = hdr;
        scenes.push_back(sceneFromJson(d, "covering scene", nullptr));
    }
    return scenes;
}

// The JSON pointer of a row's value in element 0 of its list.
json::json_pointer pointerOf(const ParameterSpec& spec) {
    std::string p = spec.inList() ? spec.listPath() + ".0." + spec.localPath() : spec.path;
    std::replace(p.begin(), p.end(), '.', '/');
    return json::json_pointer("/" + p);
}

// Values to try in place of `v`, in order: the first the project accepts is the edit.
std::vector<json> candidatesFor(const ParameterSpec& spec, const json& v) {
    std::vector<json> out;
    auto numbers = [&](double x) {
        std::vector<double> c = {x * 2.0, x + 1.0, x * 0.5, x - 1.0, 1.0, 0.5, 2.0, 10.0, 100.0};
        if (std::isfinite(spec.min)) c.push_back(spec.min + (spec.type == ParamType::Integer ? 1.0 : 0.01));
        if (std::isfinite(spec.max)) c.push_back(spec.max);
        return c;
    };
    switch (spec.type) {
    case ParamType::Boolean: out.push_back(!v.get<bool>()); break;
    case ParamType::Choice:
        for (const std::string& c : spec.choices) out.push_back(c);
        break;
    case ParamType::String: out = {json("other"), json("renamed volume"), json("2024-12-21")}; break;
    case ParamType::Number:
    case ParamType::Integer:
        for (double c : numbers(v.is_number() ? v.get<double>() : 1.0))
            out.push_back(spec.type == ParamType::Integer ? json(std::llround(c)) : json(c));
        break;
    case ParamType::Color: out = {json{0.2, 0.3, 0.4}, json{0.5, 0.5, 0.5}}; break;
    case ParamType::NumberList:
    case ParamType::IntegerList: {
        json base = v;
        if (!base.is_array() || base.empty()) {
            base = json::array();
            for (int i = 0; i < std::max(spec.minItems, 1); ++i) base.push_back(spec.type == ParamType::Integer ? 1 : 1.0);
            out.push_back(base);
        }
        for (size_t i = 0; i < base.size(); ++i)
            for (double c : numbers(base[i].get<double>())) {
                json e = base;
                e[i] = spec.type == ParamType::IntegerList ? json(std::llround(c)) : json(c);
                out.push_back(e);
            }
        if (spec.autoMeaning) out.push_back(nullptr);
        break;
    }
    }
    if (spec.autoMeaning && !v.is_null()) out.push_back(nullptr);
    return out;
}

// `scene` with the row changed to the first candidate the project accepts and reads back
// changed, after passing over `skip` such candidates; none when no candidate is left.
std::optional<SceneDescription> edited(const SceneDescription& scene, const ParameterSpec& spec, int skip = 0) {
    const json now = spec.get(scene, 0);
    std::set<json> seen;
    for (const json& c : candidatesFor(spec, now)) {
        if (c == now) continue;
        json doc = sceneToJson(scene);
        doc[pointerOf(spec)] = c;
        try {
            SceneDescription s = sceneFromJson(doc, "edit", nullptr);
            if (spec.get(s, 0) != now && seen.insert(spec.get(s, 0)).second && skip-- == 0) return s;
        } catch (const std::exception&) {
        }
    }
    return std::nullopt;
}

std::string bytesOf(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

// Every file a bake wrote but its report (which records times and the inputs themselves), by
// path under the output folder.
std::map<std::string, std::string> bakeOutputs(Project p, const fs::path& out) {
    fs::remove_all(out);
    p.scene.exportSettings.outDir = out.string();
    std::map<std::string, std::string> files;
    try {
        runBake(BakeRequest{p, 1, false, {}}, {}, nullptr);
    } catch (const std::exception& e) {
        return {{"refused", e.what()}};  // an edit the bake refuses is one it reads
    }
    for (const auto& e : fs::recursive_directory_iterator(out))
        if (e.is_regular_file() && e.path().filename() != "bake_report.json")
            files[fs::relative(e.path(), out).string()] = bytesOf(e.path());
    return files;
}

// A small, quick bake of the committed crop with everything the defaults leave off switched on.
json quickBakeDocument() {
    json doc = defaultProjectJson();
    doc["terrain"]["dem"] = kCrop.string();
    doc["terrain"]["max_resolution"] = 48;
    doc["probe_volumes"][0]["adaptive"]["min_cell_size"] = 100.0;
    doc["water"]["level"] = 500.0;
    doc["reflection_probes"]["grid_dims"] = {2, 2};
    doc["reflection_probes"]["resolution"] = 16;
    doc["probe_volumes"][0]["grid_dims"] = {5, 5};
    doc["bake"]["quality"] = "draft";
    doc["bake"]["rays"] = 32;
    doc["bake"]["bounces"] = 1;
    doc["bake"]["error_map_resolution"] = 16;
    doc["scenarios"] = json::array({json{{"name", "dusk"}, {"sun", {{"elevation_deg", 10.0}}}}});
    return doc;
}

}  // namespace

// Every row says whether the bake reads it, and a row whose edit the preview bakes again is one
// the bake reads.
TEST(BakeInputs, EveryRowSaysWhetherTheBakeReadsIt) {
    for (const ParameterSpec& spec : parameterTable()) {
        if (spec.invalidates & (kRebake | kReplace | kReimport)) {
            EXPECT_NE(spec.bake, BakeUse::Ignores) << spec.path << ": its edit bakes the preview again";
        }
        if (spec.bake == BakeUse::File) {
            EXPECT_EQ(spec.type, ParamType::String) << spec.path;
        }
    }
}

// Walks every row: in a scene that reads it, an edit changes the bake's inputs exactly when the
// table says the bake reads the row.
TEST(BakeInputs, AnEditChangesTheInputsExactlyWhenTheBakeReadsTheRow) {
    const std::vector<SceneDescription> scenes = coveringScenes();
    std::vector<std::string> unexercised;
    int reads = 0, ignores = 0;
    for (const ParameterSpec& spec : parameterTable()) {
        // The first covering scene that reads the row and takes an edit of it.
        const SceneDescription* base = nullptr;
        std::optional<SceneDescription> after;
        for (const SceneDescription& s : scenes)
            if (!after && spec.isRead(s, 0) && (after = edited(s, spec))) base = &s;
        if (!after) {
            unexercised.push_back(spec.path);
            continue;
        }
        Project a, b;
        a.scene = *base;
        b.scene = *after;
        const json before = bakeInputs(a), now = bakeInputs(b);
        if (spec.bake == BakeUse::Ignores) {
            EXPECT_EQ(before, now) << spec.path << " is a row the bake ignores: "
                                   << ::testing::PrintToString(bakeInputDifferences(before, now));
            ++ignores;
        } else {
            const std::vector<std::string> diff = bakeInputDifferences(before, now);
            ASSERT_FALSE(diff.empty()) << spec.path << " is a row the bake reads";
            // The difference names the row (a file row by its path under "files").
            const std::string name = spec.inList() ? spec.listPath() + "[0]." + spec.localPath() : spec.path;
            bool named = false;
            for (const std::string& d : diff) named = named || d.find(name) != std::string::npos;
            EXPECT_TRUE(named) << spec.path << ": " << ::testing::PrintToString(diff);
            ++reads;
        }
    }
    EXPECT_TRUE(unexercised.empty()) << ::testing::PrintToString(unexercised);
    EXPECT_GT(reads, 50);
    EXPECT_GT(ignores, 50);
}

// The table's word against the bake itself: a bake with every row it calls ignored changed (the
// renderer's water, shadows, fog, detail, AO, LPV, lights, camera, the surface's roughness)
// writes the same probes and reflection probes, byte for byte.
TEST(BakeInputs, ABakeWithEveryIgnoredRowChangedWritesTheSameProbes) {
    const fs::path dir = fs::temp_directory_path() / ("terralux_bake_inputs_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    Project p;
    json doc = defaultProjectJson();
    doc["terrain"]["dem"] = kCrop.string();
    doc["water"]["enabled"] = true;
    doc["water"]["level"] = 500.0;
    doc["water"]["waves"] = json::array({json{{"amplitude", 0.2}}});
    doc["lights"] = json::array({json{{"type", "spot"}}});
    for (const char* section : {"reflection_probes", "shadows", "fog", "detail", "ao", "lpv"})
        doc[section]["enabled"] = true;
    doc["reflection_probes"]["grid_dims"] = {2, 2};
    doc["reflection_probes"]["resolution"] = 16;
    doc["probe_volumes"][0]["grid_dims"] = {6, 6};
    doc["bake"]["quality"] = "draft";
    doc["bake"]["error_map_resolution"] = 0;
    doc["export"]["gltf"] = false;
    p.scene = sceneFromJson(doc, "base", nullptr);
    SceneDescription changed = p.scene;
    int edits = 0;
    // The switches last, so that the rows they hide are edited first.
    for (const bool switches : {false, true})
        for (const ParameterSpec& spec : parameterTable()) {
            if (spec.bake != BakeUse::Ignores || (spec.type == ParamType::Boolean) != switches ||
                !spec.isRead(changed, 0) || spec.path == "export.out_dir")
                continue;
            if (std::optional<SceneDescription> s = edited(changed, spec)) {
                changed = *s;
                ++edits;
            }
        }
    EXPECT_GT(edits, 50);
    Project q = p;
    q.scene = changed;
    p.scene.exportSettings.outDir = (dir / "a").string();
    q.scene.exportSettings.outDir = (dir / "b").string();
    const BakeOutcome a = runBake(BakeRequest{p, 1, false, {}}, {}, nullptr);
    const BakeOutcome b = runBake(BakeRequest{q, 1, false, {}}, {}, nullptr);
    int probeFiles = 0;
    for (const fs::path& f : a.files) {
        const fs::path rel = fs::relative(f, dir / "a");
        const std::string ext = rel.extension().string();
        // The probes and the reflection probes; the report carries times, and lpv.ini and the
        // glTF export the renderer's settings on purpose.
        if (ext != ".shprobe" && rel.string().find("reflection") == std::string::npos) continue;
        EXPECT_TRUE(bytesOf(f) == bytesOf(dir / "b" / rel)) << rel << " differs";
        ++probeFiles;
    }
    EXPECT_GE(probeFiles, 2);
    EXPECT_EQ(a.report["volumes"][0]["probes"], b.report["volumes"][0]["probes"]);
    fs::remove_all(dir);
}

// The table's word against the bake, the other way: a bake with one row it reads changed writes
// something else (probes, reflection probes, error maps, the glTF, lpv.ini), row by row. A row the
// bake reads that changes nothing it writes would mark bakes stale for nothing.
TEST(BakeInputs, EveryRowTheBakeReadsChangesWhatItWrites) {
    const fs::path dir = fs::temp_directory_path() / ("terralux_bake_reads_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path hdr = dir / "sky.exr";
    std::vector<float> rgba(32 * 16 * 4, 1.0f);
    for (size_t i = 0; i < rgba.size(); i += 4) rgba[i] = float(i % 7) * 0.3f;  // not uniform
    writeImage(hdr, 32, 16, rgba);
    const fs::path albedo = fs::path(TERRALUX_TEST_DATA) / "dem" / "albedo_utm11.tif";
    std::vector<SceneDescription> scenes = coveringScenes(quickBakeDocument(), albedo.string(), hdr.string());
    // Rows the bake reads never depend on the LPV (the export propagates it for lpv.ini): off, so
    // that each bake takes a tenth of a second.
    for (SceneDescription& s : scenes) s.lpv.enabled = false;
    std::map<size_t, std::map<std::string, std::string>> baseline;
    std::vector<std::string> unchanged;
    int rows = 0;
    for (const ParameterSpec& spec : parameterTable()) {
        if (spec.bake != BakeUse::Reads) continue;
        // The first covering scene that reads the row, and up to three of its edits: one must
        // change what the bake writes.
        size_t base = scenes.size();
        for (size_t i = 0; i < scenes.size() && base == scenes.size(); ++i)
            if (spec.isRead(scenes[i], 0) && edited(scenes[i], spec)) base = i;
        if (base == scenes.size()) continue;  // the walk above holds every row to be exercised
        if (!baseline.count(base)) {
            Project a;
            a.scene = scenes[base];
            baseline[base] = bakeOutputs(a, dir / "base");
            ASSERT_FALSE(baseline[base].count("refused")) << baseline[base]["refused"];
        }
        bool changed = false;
        for (int skip = 0; skip < 3 && !changed; ++skip) {
            std::optional<SceneDescription> after = edited(scenes[base], spec, skip);
            if (!after) break;
            Project b;
            b.scene = *after;
            changed = bakeOutputs(b, dir / "edited") != baseline[base];
        }
        if (!changed) unchanged.push_back(spec.path);
        ++rows;
    }
    EXPECT_TRUE(unchanged.empty()) << ::testing::PrintToString(unchanged);
    EXPECT_GT(rows, 50);
    fs::remove_all(dir);
}
