#include "TileMerge.h"

#include <fstream>

namespace terralux {

namespace {

std::optional<nlohmann::json> readJson(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return std::nullopt;
    try {
        return nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception&) {
        return std::nullopt;
    }
}

// What makes two bakes of a tile the same tile: the cut, its place and the halos asked for.
nlohmann::json tileKey(const nlohmann::json& tile) {
    return {tile.value("tiles", nlohmann::json()), tile.value("ix", -1), tile.value("iz", -1),
            tile.value("halo_setting_m", nlohmann::json()), tile.value("near_halo_setting_m", nlohmann::json()),
            tile.value("contract", 1)};
}

}  // namespace

std::optional<std::string> unchangedTile(const BakeRequest& request) {
    if (!request.tile) return std::nullopt;
    const std::filesystem::path dir = request.project.outDir();
    const std::optional<nlohmann::json> report = readJson(dir / "bake_report.json");
    if (!report || !report->contains("tile") || !report->contains("inputs") || !report->contains("files"))
        return std::nullopt;
    const TileSpec& t = *request.tile;
    const nlohmann::json now = {{"tiles", {t.nx, t.nz}}, {"ix", t.ix}, {"iz", t.iz},
                                {"halo_setting_m", t.haloMetres ? nlohmann::json(*t.haloMetres) : nlohmann::json()},
                                {"near_halo_setting_m", t.nearHaloMetres ? nlohmann::json(*t.nearHaloMetres) : nlohmann::json()},
                                {"contract", kTileContract}};
    if (tileKey((*report)["tile"]) != tileKey(now)) return std::nullopt;
    if (!bakeInputDifferences((*report)["inputs"], bakeInputs(request.project)).empty()) return std::nullopt;
    std::error_code ec;
    for (const auto& f : (*report)["files"])
        if (!f.is_string() || !std::filesystem::is_regular_file(dir / f.get<std::string>(), ec)) return std::nullopt;
    return "its inputs are unchanged since its bake in " + dir.string();
}

}  // namespace terralux

#include <QCryptographicHash>
#include <QFile>

#include <algorithm>
#include <map>

#include "GltfExport.h"
#include "OutputFolder.h"

namespace terralux {

namespace {

namespace fs = std::filesystem;

struct BakedTile {
    std::string name;
    fs::path dir;
    nlohmann::json report, gltf;
};

std::string sha256Of(const fs::path& file) {
    QFile f(QString::fromStdString(file.string()));
    if (!f.open(QIODevice::ReadOnly)) throw ProjectError(file.string() + ": cannot read it to hash it");
    QCryptographicHash h(QCryptographicHash::Sha256);
    h.addData(&f);
    return h.result().toHex().toStdString();
}

// Adds `offset` to the integer at `key` of `o`, when there is one.
void shift(nlohmann::json& o, const char* key, size_t offset) {
    if (o.is_object() && o.contains(key) && o[key].is_number_integer()) o[key] = o[key].get<size_t>() + offset;
}

// A material's texture references: every object under a "...Texture" key holds an "index".
void shiftTextures(nlohmann::json& j, size_t offset) {
    if (j.is_object()) {
        for (auto it = j.begin(); it != j.end(); ++it) {
            const std::string& key = it.key();
            if (key.size() >= 7 && key.compare(key.size() - 7, 7, "Texture") == 0) shift(it.value(), "index", offset);
            else shiftTextures(it.value(), offset);
        }
    }
}

// One probe grid of a tile: its seed-001 record and, per lighting scenario (in the order of
// TERRALUX_lighting.scenarios), its file of that scenario, each addressed through the tile's folder.
struct MergedGrid {
    nlohmann::json grid;
    std::vector<std::string> scenarioPaths;
};

// The keys of TERRALUX_lighting.reflection_probes that describe one bake's own set of probes
// (its files, its share of the grid and resolved blend distance), not what every tile shares.
constexpr const char* kReflectionSetKeys[] = {"uri",  "simvx_desktop_uri", "simvx_wire_uri", "probes",
                                              "grid", "grid_dims", "fallback_blend_distance",
                                              "simvx_probes", "simvx_ids"};

// The tiles' reflection probes as one section (docs/farm.md, "The merge"): the authored section
// and what every tile resolves alike (encoding, face size, mips), the probes summed, and under
// `sets` each tile's own set, its files addressed through the tile's folder, in tile order.
// Nothing when no tile has reflection probes; a ProjectError when only some have, or their
// shared keys differ (tiles of other inputs are refused before).
std::optional<nlohmann::json> mergedReflections(const std::vector<BakedTile>& tiles) {
    std::optional<nlohmann::json> merged;
    std::string firstWith;
    nlohmann::json sets = nlohmann::json::array();
    size_t probes = 0;
    std::vector<std::string> without;
    for (const BakedTile& t : tiles) {
        const nlohmann::json& g = t.gltf;
        const nlohmann::json lighting = g["scenes"][g.value("scene", 0)]
                                            .value("extensions", nlohmann::json::object())
                                            .value("TERRALUX_lighting", nlohmann::json::object());
        if (!lighting.contains("reflection_probes")) {
            without.push_back(t.name);
            continue;
        }
        nlohmann::json shared = lighting["reflection_probes"];
        nlohmann::json set = {{"tile", t.name}};
        for (const char* k : kReflectionSetKeys) {
            if (!shared.contains(k)) continue;
            set[k] = shared[k];
            shared.erase(k);
        }
        const std::string prefix = std::string(kTilesFolder) + "/" + t.name + "/";
        for (const char* k : {"uri", "simvx_desktop_uri", "simvx_wire_uri"})
            if (set.contains(k) && set[k].is_string()) set[k] = prefix + set[k].get<std::string>();
        probes += set.value("probes", size_t(0));
        sets.push_back(set);
        if (!merged) {
            merged = shared;
            firstWith = t.name;
        } else if (*merged != shared) {
            throw ProjectError((t.dir / "scene.gltf").string() + ": reflection probes resolved otherwise than in " +
                               firstWith + "; bake the tiles again");
        }
    }
    if (!merged) return std::nullopt;
    if (!without.empty()) {
        std::string list;
        for (const std::string& n : without) list += (list.empty() ? "" : ", ") + n;
        throw ProjectError(std::to_string(without.size()) + " of " + std::to_string(tiles.size()) +
                           " tiles without reflection probes, which " + firstWith + " has: " + list +
                           "; bake them again");
    }
    (*merged)["probes"] = probes;
    (*merged)["sets"] = sets;
    return merged;
}

// The tiles' glTF documents as one: each tile's nodes, meshes, materials and buffers appended with
// their indices moved, buffers and images addressed through the tile's folder, and the probe
// grids of every tile listed in the scene's VULKAN_SCHNEE_engine_properties, sorted by file name;
// each lighting scenario's files listed in that same order; the reflection probes of every tile
// (mergedReflections).
nlohmann::json mergedGltf(const std::vector<BakedTile>& tiles, const nlohmann::json& region) {
    nlohmann::json out = {{"asset", tiles.front().gltf["asset"]}, {"scene", 0}};
    nlohmann::json used = nlohmann::json::array(), roots = nlohmann::json::array();
    std::vector<MergedGrid> grids;
    nlohmann::json sceneExt = tiles.front().gltf["scenes"][0].value("extensions", nlohmann::json::object());
    static const char* kArrays[] = {"nodes", "meshes", "materials", "samplers", "images", "textures",
                                    "accessors", "bufferViews", "buffers"};
    for (const char* a : kArrays) out[a] = nlohmann::json::array();
    for (size_t t = 0; t < tiles.size(); ++t) {
        const nlohmann::json& g = tiles[t].gltf;
        const std::string prefix = std::string(kTilesFolder) + "/" + tiles[t].name + "/";
        std::map<std::string, size_t> off;
        for (const char* a : kArrays) off[a] = out[a].size();
        for (const auto& e : g.value("extensionsUsed", nlohmann::json::array()))
            if (std::find(used.begin(), used.end(), e) == used.end()) used.push_back(e);
        const nlohmann::json& scene = g["scenes"][g.value("scene", 0)];
        for (const auto& i : scene["nodes"]) roots.push_back(i.get<size_t>() + off["nodes"]);
        for (nlohmann::json n : g.value("nodes", nlohmann::json::array())) {
            shift(n, "mesh", off["meshes"]);
            if (n.contains("children"))
                for (auto& c : n["children"]) c = c.get<size_t>() + off["nodes"];
            n["name"] = tiles[t].name + "/" + n.value("name", std::string("node"));
            out["nodes"].push_back(n);
        }
        for (nlohmann::json m : g.value("meshes", nlohmann::json::array())) {
            for (auto& p : m["primitives"]) {
                for (auto& [k, v] : p["attributes"].items()) v = v.get<size_t>() + off["accessors"];
                shift(p, "indices", off["accessors"]);
                shift(p, "material", off["materials"]);
            }
            out["meshes"].push_back(m);
        }
        for (nlohmann::json m : g.value("materials", nlohmann::json::array())) {
            shiftTextures(m, off["textures"]);
            out["materials"].push_back(m);
        }
        for (const auto& s : g.value("samplers", nlohmann::json::array())) out["samplers"].push_back(s);
        for (nlohmann::json i : g.value("images", nlohmann::json::array())) {
            shift(i, "bufferView", off["bufferViews"]);
            if (i.contains("uri")) i["uri"] = prefix + i["uri"].get<std::string>();
            out["images"].push_back(i);
        }
        for (nlohmann::json x : g.value("textures", nlohmann::json::array())) {
            shift(x, "sampler", off["samplers"]);
            shift(x, "source", off["images"]);
            out["textures"].push_back(x);
        }
        for (nlohmann::json x : g.value("accessors", nlohmann::json::array())) {
            shift(x, "bufferView", off["bufferViews"]);
            out["accessors"].push_back(x);
        }
        for (nlohmann::json x : g.value("bufferViews", nlohmann::json::array())) {
            shift(x, "buffer", off["buffers"]);
            out["bufferViews"].push_back(x);
        }
        for (nlohmann::json x : g.value("buffers", nlohmann::json::array())) {
            if (x.contains("uri")) x["uri"] = prefix + x["uri"].get<std::string>();
            out["buffers"].push_back(x);
        }
        const nlohmann::json ext = scene.value("extensions", nlohmann::json::object());
        const nlohmann::json scenarios =
            ext.value("TERRALUX_lighting", nlohmann::json::object()).value("scenarios", nlohmann::json::array());
        if (ext.contains("VULKAN_SCHNEE_engine_properties")) {
            const nlohmann::json tileGrids = ext["VULKAN_SCHNEE_engine_properties"].value("shProbeGrids", nlohmann::json::array());
            for (size_t k = 0; k < tileGrids.size(); ++k) {
                MergedGrid m{tileGrids[k], {}};
                m.grid["shProbePath"] = prefix + m.grid["shProbePath"].get<std::string>();
                for (const auto& s : scenarios) {
                    const nlohmann::json paths = s.value("shProbePaths", nlohmann::json::array());
                    if (k >= paths.size() || !paths[k].is_string())
                        throw ProjectError((tiles[t].dir / "scene.gltf").string() + ": scenario " + s.value("name", std::string("?")) +
                                           " lists " + std::to_string(paths.size()) + " files for " +
                                           std::to_string(tileGrids.size()) + " grids; bake the tile again");
                    m.scenarioPaths.push_back(prefix + paths[k].get<std::string>());
                }
                grids.push_back(std::move(m));
            }
        }
    }
    // The seed's rule: grids sorted by file name; the first that holds a point wins.
    std::stable_sort(grids.begin(), grids.end(), [](const MergedGrid& a, const MergedGrid& b) {
        return a.grid["shProbePath"].get<std::string>() < b.grid["shProbePath"].get<std::string>();
    });
    nlohmann::json gridList = nlohmann::json::array();
    for (const MergedGrid& m : grids) gridList.push_back(m.grid);
    sceneExt["VULKAN_SCHNEE_engine_properties"]["shProbeGrids"] = gridList;
    // Each scenario's files in the order of the grids (the tiles share one set of scenarios: they
    // were baked from the same inputs).
    if (sceneExt.contains("TERRALUX_lighting") && sceneExt["TERRALUX_lighting"].contains("scenarios")) {
        nlohmann::json& scenarios = sceneExt["TERRALUX_lighting"]["scenarios"];
        for (size_t s = 0; s < scenarios.size(); ++s) {
            nlohmann::json paths = nlohmann::json::array();
            for (const MergedGrid& m : grids) paths.push_back(m.scenarioPaths.at(s));
            scenarios[s]["shProbePaths"] = paths;
        }
    }
    if (const std::optional<nlohmann::json> reflections = mergedReflections(tiles))
        sceneExt["TERRALUX_lighting"]["reflection_probes"] = *reflections;
    // The region's grid and stride, not the first tile's.
    if (sceneExt.contains("TERRALUX_geo")) {
        sceneExt["TERRALUX_geo"]["gridSize"] = region["region_grid"];
        sceneExt["TERRALUX_geo"].erase("meshStride");
        sceneExt["TERRALUX_geo"]["tiles"] = region["tiles"];
    }
    // Per tile, on the tile's scene only; the merged report sums them.
    sceneExt.erase("TERRALUX_bake");
    used.erase(std::remove(used.begin(), used.end(), nlohmann::json("TERRALUX_bake")), used.end());
    out["extensionsUsed"] = used;
    out["scenes"] = nlohmann::json::array({{{"name", "region"}, {"nodes", roots}, {"extensions", sceneExt}}});
    for (const char* a : kArrays)
        if (out[a].empty()) out.erase(a);
    return out;
}

// The tiles' reports summed: rays and time, and per volume its probes and their error.
nlohmann::json mergedReport(const std::vector<BakedTile>& tiles, const nlohmann::json& region) {
    double time = 0.0, longest = 0.0;
    uint64_t rays = 0, probeRays = 0;
    struct Volume {
        size_t probes = 0, mapPoints = 0;
        double seSum = 0.0, seMax = 0.0, mapSum = 0.0, mapMax = 0.0;
    };
    std::map<std::string, Volume> volumes;
    // Reflection probes: the tiles' probes, bytes and time summed.
    nlohmann::json reflections = nlohmann::json::object();
    nlohmann::json perTile = nlohmann::json::array();
    for (const BakedTile& t : tiles) {
        const nlohmann::json& r = t.report;
        const double s = r.value("time_s", 0.0);
        time += s;
        longest = std::max(longest, s);
        rays += r.value("rays", uint64_t(0));
        probeRays += r.value("probe_rays", uint64_t(0));
        for (const auto& v : r.value("volumes", nlohmann::json::array())) {
            Volume& m = volumes[v.value("name", std::string())];
            const size_t n = v.value("probes", size_t(0));
            m.probes += n;
            if (v.contains("standard_error")) {
                m.seSum += v["standard_error"].value("mean", 0.0) * double(n);
                m.seMax = std::max(m.seMax, v["standard_error"].value("max", 0.0));
            }
            if (v.contains("error_map") && v["error_map"].value("points", 0) > 0) {
                const size_t p = v["error_map"]["points"].get<size_t>();
                m.mapPoints += p;
                m.mapSum += v["error_map"].value("mean", 0.0) * double(p);
                m.mapMax = std::max(m.mapMax, v["error_map"].value("max", 0.0));
            }
        }
        if (r.contains("reflection_probes")) {
            const nlohmann::json& rr = r["reflection_probes"];
            reflections["probes"] = reflections.value("probes", uint64_t(0)) + rr.value("probes", uint64_t(0));
            reflections["bytes"] = reflections.value("bytes", uint64_t(0)) + rr.value("bytes", uint64_t(0));
            reflections["time_s"] = reflections.value("time_s", 0.0) + rr.value("time_s", 0.0);
        }
        perTile.push_back({{"name", t.name}, {"time_s", s}, {"rays", r.value("rays", uint64_t(0))}});
    }
    nlohmann::json vs = nlohmann::json::array();
    for (const auto& [name, m] : volumes) {
        nlohmann::json v = {{"name", name},
                            {"probes", m.probes},
                            {"standard_error", {{"mean", m.probes ? m.seSum / double(m.probes) : 0.0}, {"max", m.seMax}}}};
        if (m.mapPoints)
            v["error_map"] = {{"points", m.mapPoints}, {"mean", m.mapSum / double(m.mapPoints)}, {"max", m.mapMax}};
        vs.push_back(v);
    }
    nlohmann::json out = {{"generator", tiles.front().report.value("generator", std::string())},
            {"region", region},
            {"inputs", tiles.front().report["inputs"]},
            {"tiles", perTile},
            {"time_s", time},
            {"longest_tile_time_s", longest},
            {"rays", rays},
            {"probe_rays", probeRays},
            {"volumes", vs},
            {"failures", nlohmann::json::array()}};
    if (!reflections.empty()) out["reflection_probes"] = reflections;
    return out;
}

}  // namespace

MergeOutcome mergeTiles(const fs::path& dirIn) {
    const fs::path dir = fs::absolute(dirIn).lexically_normal();
    const fs::path tilesDir = dir / kTilesFolder;
    std::error_code ec;
    std::vector<BakedTile> tiles;
    for (const auto& e : fs::directory_iterator(tilesDir, ec)) {
        if (!e.is_directory(ec) || e.path().filename().string().rfind("tile_", 0) != 0) continue;
        BakedTile t{e.path().filename().string(), e.path(), {}, {}};
        const std::optional<nlohmann::json> r = readJson(t.dir / "bake_report.json");
        if (!r || !r->contains("tile") || !r->contains("inputs"))
            throw ProjectError((t.dir / "bake_report.json").string() +
                               ": missing or not a tile's bake report; bake the tile again (--bake --tile)");
        t.report = *r;
        if ((*r)["tile"].value("name", std::string()) != t.name)
            throw ProjectError(t.dir.string() + ": holds the bake of " + (*r)["tile"].value("name", std::string("?")) +
                               ", not of " + t.name);
        tiles.push_back(std::move(t));
    }
    if (tiles.empty())
        throw ProjectError(tilesDir.string() + ": no baked tiles; bake them first with --bake --tiles NX,NZ --tile I/N --out " +
                           dir.string());
    std::sort(tiles.begin(), tiles.end(), [](const BakedTile& a, const BakedTile& b) { return a.name < b.name; });

    // One cut, one set of inputs: every tile must agree with the first.
    const nlohmann::json& first = tiles.front().report;
    auto sameInputs = [&](const nlohmann::json& inputs) {
        for (const std::string& d : bakeInputDifferences(first["inputs"], inputs))
            if (d.rfind("export.out_dir", 0) != 0) return d;
        return std::string();
    };
    std::vector<std::string> mismatched;
    for (const BakedTile& t : tiles) {
        const nlohmann::json& tile = t.report["tile"];
        std::string why;
        if (tile["tiles"] != first["tile"]["tiles"]) why = "cut " + tile["tiles"].dump() + ", not " + first["tile"]["tiles"].dump();
        else if (tile.value("contract", 1) != first["tile"].value("contract", 1))
            why = "tile contract " + std::to_string(tile.value("contract", 1)) + ", not " +
                  std::to_string(first["tile"].value("contract", 1));
        else if (tile.value("halo_setting_m", nlohmann::json()) != first["tile"].value("halo_setting_m", nlohmann::json()))
            why = "halo " + tile.value("halo_setting_m", nlohmann::json()).dump();
        else if (tile.value("near_halo_setting_m", nlohmann::json()) != first["tile"].value("near_halo_setting_m", nlohmann::json()))
            why = "near halo " + tile.value("near_halo_setting_m", nlohmann::json()).dump();
        else if (tile["region_grid"] != first["tile"]["region_grid"]) why = "region grid " + tile["region_grid"].dump();
        else why = sameInputs(t.report["inputs"]);
        if (!why.empty()) mismatched.push_back(t.name + " (" + why + ")");
    }
    if (!mismatched.empty()) {
        std::string list;
        for (const auto& m : mismatched) list += (list.empty() ? "" : ", ") + m;
        throw ProjectError(tilesDir.string() + ": tiles baked from other inputs than " + tiles.front().name + ": " + list +
                           "; bake them again");
    }
    const int nx = first["tile"]["tiles"][0].get<int>(), nz = first["tile"]["tiles"][1].get<int>();
    std::vector<std::string> missing;
    for (int iz = 0; iz < nz; ++iz)
        for (int ix = 0; ix < nx; ++ix) {
            TileSpec s;
            s.nx = nx, s.nz = nz, s.ix = ix, s.iz = iz;
            const std::string name = tileName(s);
            if (!std::any_of(tiles.begin(), tiles.end(), [&](const BakedTile& t) { return t.name == name; }))
                missing.push_back(name);
        }
    if (!missing.empty()) {
        std::string list;
        for (size_t i = 0; i < missing.size() && i < 16; ++i) list += (i ? ", " : "") + missing[i];
        if (missing.size() > 16) list += ", ... (" + std::to_string(missing.size()) + " in all)";
        throw ProjectError(tilesDir.string() + ": " + std::to_string(missing.size()) + " of " + std::to_string(nx * nz) +
                           " tiles missing: " + list + "; bake them first");
    }
    if (int(tiles.size()) != nx * nz)
        throw ProjectError(tilesDir.string() + ": " + std::to_string(tiles.size()) + " tile folders for a " +
                           std::to_string(nx) + " x " + std::to_string(nz) + " cut; remove the others");

    nlohmann::json index = nlohmann::json::array();
    for (BakedTile& t : tiles) {
        const std::optional<nlohmann::json> g = readJson(t.dir / "scene.gltf");
        if (!g) throw ProjectError((t.dir / "scene.gltf").string() + ": missing or unreadable; bake the tile with export.gltf on");
        // Every later read indexes its scene: one that is not there is a file to bake again.
        const nlohmann::json* scenes = g->contains("scenes") ? &(*g)["scenes"] : nullptr;
        const nlohmann::json scene = g->value("scene", nlohmann::json(0));
        if (!scenes || !scenes->is_array() || !scene.is_number_unsigned() || scene.get<size_t>() >= scenes->size() ||
            !(*scenes)[scene.get<size_t>()].is_object())
            throw ProjectError((t.dir / "scene.gltf").string() + ": has no scene " + scene.dump() + "; bake the tile again");
        t.gltf = *g;
        nlohmann::json files = nlohmann::json::array();
        for (const auto& f : t.report.value("files", nlohmann::json::array())) {
            const fs::path p = t.dir / f.get<std::string>();
            files.push_back({{"path", (fs::path(kTilesFolder) / t.name / f.get<std::string>()).generic_string()},
                             {"bytes", fs::file_size(p, ec)},
                             {"sha256", sha256Of(p)}});
        }
        index.push_back({{"name", t.name},
                         {"ix", t.report["tile"]["ix"]},
                         {"iz", t.report["tile"]["iz"]},
                         {"bounds_m", t.report["tile"]["bounds_m"]},
                         {"files", files}});
    }
    const nlohmann::json& ft = first["tile"];
    const nlohmann::json region = {{"tiles", ft["tiles"]}, {"region_grid", ft["region_grid"]}, {"halo", ft["halo"]},
                                   {"near_halo", ft.value("near_halo", nlohmann::json())}};
    MergeOutcome out;
    out.dir = dir;
    out.tiles = int(tiles.size());
    const nlohmann::json gltf = mergedGltf(tiles, region);
    out.grids = gltf["scenes"][0]["extensions"]["VULKAN_SCHNEE_engine_properties"]["shProbeGrids"].size();
    out.report = mergedReport(tiles, region);
    const nlohmann::json tilesJson = {{"region", region}, {"tiles", index}};

    const OutputFolderLock lock(dir);
    removeStaleTemporaries(dir);
    writeFilesTogether(dir, {{"tiles.json", tilesJson.dump(2) + "\n"},
                             {"scene.gltf", gltf.dump(2) + "\n"},
                             {"bake_report.json", out.report.dump(2) + "\n"}});
    out.files = {dir / "tiles.json", dir / "scene.gltf", dir / "bake_report.json"};
    return out;
}

}  // namespace terralux
