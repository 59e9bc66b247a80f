#include "Project.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <regex>
#include <set>
#include <sstream>

#include "AtomicFile.h"

namespace terralux {
namespace {

using nlohmann::json;

std::string show(const json& v) {
    std::string s = v.dump();
    if (s.size() > 60) s = s.substr(0, 57) + "...";
    return s;
}

[[noreturn]] void reject(const std::string& source, const std::string& path, const json& value,
                         const std::string& rule) {
    throw ProjectError(source + ": " + path + " = " + show(value) + ": " + rule);
}

// Typed, rule-checked reads. Each names the JSON path in its message.
class Reader {
public:
    explicit Reader(std::string source) : source_(std::move(source)) {}

    double number(const json& v, const std::string& path) const {
        if (!v.is_number()) reject(source_, path, v, "must be a number");
        const double d = v.get<double>();
        if (!std::isfinite(d)) reject(source_, path, v, "must be finite");
        return d;
    }
    double numberIn(const json& v, const std::string& path, double lo, double hi) const {
        const double d = number(v, path);
        if (d < lo || d > hi)
            reject(source_, path, v, "must be in [" + trim(lo) + ", " + trim(hi) + "]");
        return d;
    }
    double numberAtLeast(const json& v, const std::string& path, double lo, bool strict) const {
        const double d = number(v, path);
        if (strict ? !(d > lo) : !(d >= lo))
            reject(source_, path, v, std::string("must be ") + (strict ? "> " : ">= ") + trim(lo));
        return d;
    }
    int integer(const json& v, const std::string& path, int lo, int hi) const {
        if (!v.is_number_integer() && !(v.is_number_float() && std::floor(v.get<double>()) ==
                                                                  v.get<double>()))
            reject(source_, path, v, "must be an integer");
        const double d = v.get<double>();
        if (d < lo || d > hi)
            reject(source_, path, v, "must be in [" + std::to_string(lo) + ", " +
                                         std::to_string(hi) + "]");
        return int(d);
    }
    long long count(const json& v, const std::string& path, long long lo, long long hi) const {
        if (!v.is_number_integer() && !(v.is_number_float() && std::floor(v.get<double>()) ==
                                                                  v.get<double>()))
            reject(source_, path, v, "must be an integer");
        const double d = v.get<double>();
        if (d < double(lo) || d > double(hi))
            reject(source_, path, v, "must be in [" + std::to_string(lo) + ", " +
                                         std::to_string(hi) + "]");
        return v.is_number_unsigned() ? (long long)v.get<unsigned long long>() : v.get<long long>();
    }
    bool boolean(const json& v, const std::string& path) const {
        if (!v.is_boolean()) reject(source_, path, v, "must be true or false");
        return v.get<bool>();
    }
    std::string string(const json& v, const std::string& path) const {
        if (!v.is_string()) reject(source_, path, v, "must be a string");
        return v.get<std::string>();
    }
    std::string oneOf(const json& v, const std::string& path,
                      std::initializer_list<const char*> allowed) const {
        const std::string s = string(v, path);
        std::string list;
        for (const char* a : allowed) {
            if (s == a) return s;
            list += (list.empty() ? "" : " | ") + std::string(a);
        }
        reject(source_, path, v, "must be one of " + list);
    }
    const json& array(const json& v, const std::string& path, size_t n) const {
        if (!v.is_array() || v.size() != n)
            reject(source_, path, v, "must be an array of " + std::to_string(n) + " numbers");
        return v;
    }
    glm::vec3 color(const json& v, const std::string& path, double lo, double hi) const {
        array(v, path, 3);
        glm::vec3 c;
        for (int i = 0; i < 3; ++i) {
            const std::string p = path + "[" + std::to_string(i) + "]";
            if (!v[i].is_number() || !std::isfinite(v[i].get<double>()) || v[i].get<double>() < lo ||
                v[i].get<double>() > hi)
                reject(source_, p, v[i],
                       "three components, each in [" + trim(lo) + ", " +
                           (std::isinf(hi) ? std::string("inf") : trim(hi)) + "]");
            c[i] = v[i].get<float>();
        }
        return c;
    }
    const std::string& source() const { return source_; }

private:
    static std::string trim(double d) {
        std::ostringstream s;
        s << d;
        return s.str();
    }
    std::string source_;
};

const char* qualityName(QualityPreset q) {
    switch (q) {
        case QualityPreset::Draft: return "draft";
        case QualityPreset::Standard: return "standard";
        case QualityPreset::High: return "high";
        case QualityPreset::Reference: return "reference";
    }
    return "standard";
}

json optionalNumber(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }
json optionalInt(const std::optional<int>& v) { return v ? json(*v) : json(nullptr); }
json vec(const glm::vec3& v, int n) {
    json a = json::array();
    for (int i = 0; i < n; ++i) a.push_back(double(v[i]));
    return a;
}

json adaptiveToJson(const AdaptiveVolumeSettings& a) {
    return {{"min_cell_size", optionalNumber(a.minCellSize)},
            {"max_cell_size", optionalNumber(a.maxCellSize)},
            {"height_range", a.heightRange},
            {"size", a.size ? vec(*a.size, 3) : json(nullptr)},
            {"surface_band", optionalNumber(a.surfaceBand)},
            {"tolerance", optionalNumber(a.tolerance)},
            {"max_probes", optionalInt(a.maxProbes)},
            {"max_bytes", a.maxBytes ? json(*a.maxBytes) : json(nullptr)},
            {"max_move_share", a.maxMoveShare}};
}

json volumeToJson(const ProbeVolumeSettings& v) {
    const bool box = v.placement == ProbePlacement::Box;
    const bool adaptive = v.placement == ProbePlacement::Adaptive;
    // Adaptive volumes ignore grid_dims and spacing; they keep the terrain defaults so that a
    // document reads back as it was written.
    const ProbeVolumeSettings defaults;
    const auto& gd = adaptive ? defaults.gridDims : v.gridDims;
    json dims = box ? json{gd[0], gd[1], gd[2]} : json{gd[0], gd[2]};
    json origin = nullptr, spacing = nullptr;
    if (v.origin) origin = box || adaptive ? vec(*v.origin, 3) : json{v.origin->x, v.origin->z};
    if (v.spacing && !adaptive)
        spacing = box ? json(double(v.spacing->x)) : json{v.spacing->x, v.spacing->z};
    return {{"name", v.name},
            {"enabled", v.enabled},
            {"placement", placementName(v.placement)},
            {"grid_dims", dims},
            {"origin", origin},
            {"spacing", spacing},
            {"height_offset", v.heightOffset},
            {"ray_count", optionalInt(v.rayCount)},
            {"fallback_blend_distance", optionalNumber(v.fallbackBlendDistance)},
            {"adaptive", adaptiveToJson(v.adaptive)}};
}

// Deepest octree: max_cell_size up to min_cell_size x 2^16 (seed 001's own defaults are 2^5),
// as AdaptivePlacement.cpp checks again for sizes the terrain decides.
constexpr int kMaxOctreeLevels = 16;

AdaptiveVolumeSettings adaptiveFromJson(const json& o, const std::string& path, const Reader& r) {
    if (!o.is_object()) reject(r.source(), path, o, "must be an object");
    AdaptiveVolumeSettings a;
    if (const json& v = o.at("min_cell_size"); !v.is_null())
        a.minCellSize = r.numberAtLeast(v, path + ".min_cell_size", 0.0, true);
    if (const json& v = o.at("max_cell_size"); !v.is_null()) {
        const double max = r.numberAtLeast(v, path + ".max_cell_size", 0.0, true);
        if (a.minCellSize) {
            const double ratio = max / *a.minCellSize;
            const double k = std::round(std::log2(ratio));
            if (!(ratio >= 1.0) || k > kMaxOctreeLevels ||
                std::abs(ratio - std::exp2(k)) > 1e-9 * ratio)
                reject(r.source(), path + ".max_cell_size", v,
                       "must be min_cell_size (" + show(o.at("min_cell_size")) +
                           ") times 2^k, k in [0, " + std::to_string(kMaxOctreeLevels) + "]");
        }
        a.maxCellSize = max;
    }
    a.heightRange = r.numberAtLeast(o.at("height_range"), path + ".height_range", 0.0, false);
    if (const json& v = o.at("size"); !v.is_null()) {
        r.array(v, path + ".size", 3);
        glm::vec3 s;
        for (size_t i = 0; i < 3; ++i)
            s[int(i)] = float(r.numberAtLeast(v[i], path + ".size[" + std::to_string(i) + "]", 0.0, true));
        a.size = s;
    }
    if (const json& v = o.at("surface_band"); !v.is_null())
        a.surfaceBand = r.numberAtLeast(v, path + ".surface_band", 0.0, false);
    if (const json& v = o.at("tolerance"); !v.is_null()) {
        const double t = r.number(v, path + ".tolerance");
        if (!(t > 0.0) || t > 1.0) reject(r.source(), path + ".tolerance", v, "must be in (0, 1] or null");
        a.tolerance = t;
    }
    if (const json& v = o.at("max_probes"); !v.is_null())
        a.maxProbes = r.integer(v, path + ".max_probes", 1, std::numeric_limits<int>::max());
    if (const json& v = o.at("max_bytes"); !v.is_null())
        a.maxBytes = r.count(v, path + ".max_bytes", 1, 1ll << 53);
    a.maxMoveShare = r.numberIn(o.at("max_move_share"), path + ".max_move_share", 0.0, 0.5);
    return a;
}

ProbeVolumeSettings volumeFromJson(const json& o, const std::string& path, const Reader& r) {
    ProbeVolumeSettings v;
    v.name = r.string(o.at("name"), path + ".name");
    static const std::regex kName("[A-Za-z0-9_-]{1,64}");
    if (!std::regex_match(v.name, kName))
        reject(r.source(), path + ".name", o.at("name"),
               "must be 1-64 letters, digits, '_' or '-' (it names the .shprobe file)");
    v.enabled = r.boolean(o.at("enabled"), path + ".enabled");
    const std::string placement =
        r.oneOf(o.at("placement"), path + ".placement", {"terrain", "box", "adaptive"});
    v.placement = placement == "box"        ? ProbePlacement::Box
                  : placement == "adaptive" ? ProbePlacement::Adaptive
                                            : ProbePlacement::Terrain;
    v.heightOffset = r.number(o.at("height_offset"), path + ".height_offset");
    if (const json& rc = o.at("ray_count"); !rc.is_null())
        v.rayCount = r.integer(rc, path + ".ray_count", 1, 1 << 20);
    if (const json& fb = o.at("fallback_blend_distance"); !fb.is_null())
        v.fallbackBlendDistance = r.numberAtLeast(fb, path + ".fallback_blend_distance", 0.0, false);
    v.adaptive = adaptiveFromJson(o.at("adaptive"), path + ".adaptive", r);
    if (v.placement == ProbePlacement::Adaptive) {
        if (const json& origin = o.at("origin"); !origin.is_null()) {
            r.array(origin, path + ".origin", 3);
            glm::vec3 p;
            for (size_t i = 0; i < 3; ++i)
                p[int(i)] = float(r.number(origin[i], path + ".origin[" + std::to_string(i) + "]"));
            v.origin = p;
        }
        return v;
    }
    const bool box = v.placement == ProbePlacement::Box;
    const size_t n = box ? 3 : 2;
    const json& dims = o.at("grid_dims");
    r.array(dims, path + ".grid_dims", n);
    long long product = 1;
    std::array<int, 3> d{1, 1, 1};
    for (size_t i = 0; i < n; ++i) {
        const int value = r.integer(dims[i], path + ".grid_dims[" + std::to_string(i) + "]", 1,
                                    box ? kMaxBoxGridProbes : kMaxTerrainGridProbes);
        product *= value;
        d[box ? i : (i == 0 ? 0 : 2)] = value;
    }
    const int limit = box ? kMaxBoxGridProbes : kMaxTerrainGridProbes;
    if (product > limit)
        reject(r.source(), path + ".grid_dims", dims,
               "must be >= 1 each with a product <= " + std::to_string(limit) + " (is " +
                   std::to_string(product) + ")");
    v.gridDims = d;
    if (const json& origin = o.at("origin"); !origin.is_null()) {
        r.array(origin, path + ".origin", n);
        glm::vec3 p{0.0f};
        for (size_t i = 0; i < n; ++i) {
            const float c = float(r.number(origin[i], path + ".origin[" + std::to_string(i) + "]"));
            if (box) p[int(i)] = c;
            else p[i == 0 ? 0 : 2] = c;
        }
        v.origin = p;
    }
    if (const json& spacing = o.at("spacing"); !spacing.is_null()) {
        glm::vec3 s{0.0f};
        if (box) {
            s = glm::vec3(float(r.numberAtLeast(spacing, path + ".spacing", 0.0, true)));
        } else {
            r.array(spacing, path + ".spacing", 2);
            s.x = float(r.numberAtLeast(spacing[0], path + ".spacing[0]", 0.0, true));
            s.z = float(r.numberAtLeast(spacing[1], path + ".spacing[1]", 0.0, true));
            s.y = std::min(s.x, s.z);
        }
        v.spacing = s;
    }
    return v;
}

// Recursive merge of `doc` over `base`, dropping (with a warning) keys `base` lacks.
void mergeInto(json& base, const json& doc, const std::string& path, const std::string& source,
               std::vector<std::string>* warnings) {
    for (auto it = doc.begin(); it != doc.end(); ++it) {
        const std::string childPath = path.empty() ? it.key() : path + "." + it.key();
        if (!base.contains(it.key())) {
            if (warnings) warnings->push_back(source + ": unknown key '" + childPath + "' ignored");
            continue;
        }
        json& target = base[it.key()];
        if (childPath == "probe_volumes" && it->is_array()) {
            const json volumeDefaults = target.empty() ? volumeToJson(ProbeVolumeSettings{})
                                                       : target[0];
            json volumes = json::array();
            for (size_t i = 0; i < it->size(); ++i) {
                json v = volumeDefaults;
                if ((*it)[i].is_object())
                    mergeInto(v, (*it)[i], childPath + "[" + std::to_string(i) + "]", source,
                              warnings);
                else
                    v = (*it)[i];
                volumes.push_back(v);
            }
            target = volumes;
        } else if (target.is_object() && it->is_object()) {
            mergeInto(target, *it, childPath, source, warnings);
        } else {
            target = *it;
        }
    }
}

}  // namespace

json sceneToJson(const SceneDescription& s) {
    json volumes = json::array();
    for (const auto& v : s.probeVolumes) volumes.push_back(volumeToJson(v));
    return {
        {"format", "terralux-project"},
        {"version", kProjectVersion},
        {"terrain",
         {{"dem", s.terrain.dem},
          {"vertical_scale", s.terrain.verticalScale},
          {"albedo", vec(s.terrain.albedo, 3)},
          {"max_resolution", s.terrain.maxResolution},
          {"skirt", s.terrain.skirt}}},
        {"sun",
         {{"azimuth_deg", s.sun.azimuthDeg},
          {"elevation_deg", s.sun.elevationDeg},
          {"illuminance", s.sun.illuminance},
          {"color", vec(s.sun.color, 3)},
          {"angular_radius_deg", s.sun.angularRadiusDeg}}},
        {"sky",
         {{"mode", s.sky.mode == SkyMode::Hdr ? "hdr" : "uniform"},
          {"color", vec(s.sky.color, 3)},
          {"intensity", s.sky.intensity},
          {"hdr", s.sky.hdr},
          {"rotation_deg", s.sky.rotationDeg}}},
        {"probe_volumes", volumes},
        {"reflection_probes",
         {{"enabled", s.reflectionProbes.enabled},
          {"grid_dims", {s.reflectionProbes.gridDims[0], s.reflectionProbes.gridDims[1]}},
          {"height_offset", s.reflectionProbes.heightOffset},
          {"ray_count", s.reflectionProbes.rayCount},
          {"ground_color", vec(s.reflectionProbes.groundColor, 3)},
          {"strength", s.reflectionProbes.strength}}},
        {"bake",
         {{"quality", qualityName(s.bake.quality)},
          {"rays", optionalInt(s.bake.rays)},
          {"bounces", optionalInt(s.bake.bounces)},
          {"sh_encoding", s.bake.encoding == ShEncoding::Irradiance ? "irradiance" : "radiance"},
          {"deringing", s.bake.deringing},
          {"error_map_resolution", s.bake.errorMapResolution}}},
        {"camera",
         {{"target", s.camera.target ? vec(*s.camera.target, 3) : json(nullptr)},
          {"radius", optionalNumber(s.camera.radius)},
          {"azimuth_deg", s.camera.azimuthDeg},
          {"elevation_deg", s.camera.elevationDeg},
          {"fov_deg", s.camera.fovDeg}}},
        {"export",
         {{"out_dir", s.exportSettings.outDir},
          {"gltf", s.exportSettings.gltf},
          {"default_scale", s.exportSettings.defaultScale},
          {"default_ambient", s.exportSettings.defaultAmbient}}},
    };
}

json defaultProjectJson() { return sceneToJson(SceneDescription{}); }

json mergeOverDefaults(const json& doc, const std::string& source,
                       std::vector<std::string>* warnings) {
    if (!doc.is_object()) throw ProjectError(source + ": the project must be a JSON object");
    json base = defaultProjectJson();
    mergeInto(base, doc, "", source, warnings);
    return base;
}

SceneDescription sceneFromJson(const json& doc, const std::string& source,
                               std::vector<std::string>* warnings) {
    const json d = mergeOverDefaults(doc, source, warnings);
    Reader r(source);
    if (d.at("format") != "terralux-project")
        reject(source, "format", d.at("format"), "must be \"terralux-project\"");
    const int version = r.integer(d.at("version"), "version", 1, 1 << 20);
    if (version > kProjectVersion)
        reject(source, "version", d.at("version"),
               "is newer than this Terralux reads (" + std::to_string(kProjectVersion) + ")");

    SceneDescription s;
    const json& t = d.at("terrain");
    s.terrain.dem = r.string(t.at("dem"), "terrain.dem");
    s.terrain.verticalScale = r.numberAtLeast(t.at("vertical_scale"), "terrain.vertical_scale", 0.0, true);
    s.terrain.albedo = r.color(t.at("albedo"), "terrain.albedo", 0.0, 1.0);
    s.terrain.maxResolution = r.integer(t.at("max_resolution"), "terrain.max_resolution", 0, 1 << 20);
    if (s.terrain.maxResolution == 1)
        reject(source, "terrain.max_resolution", t.at("max_resolution"), "must be 0 (off) or >= 2");
    s.terrain.skirt = r.boolean(t.at("skirt"), "terrain.skirt");

    const json& sun = d.at("sun");
    s.sun.azimuthDeg = r.number(sun.at("azimuth_deg"), "sun.azimuth_deg");
    s.sun.elevationDeg = r.numberIn(sun.at("elevation_deg"), "sun.elevation_deg", -90.0, 90.0);
    s.sun.illuminance = r.numberAtLeast(sun.at("illuminance"), "sun.illuminance", 0.0, false);
    s.sun.color = r.color(sun.at("color"), "sun.color", 0.0, INFINITY);
    s.sun.angularRadiusDeg = r.numberIn(sun.at("angular_radius_deg"), "sun.angular_radius_deg", 0.0, 45.0);

    const json& sky = d.at("sky");
    s.sky.mode = r.oneOf(sky.at("mode"), "sky.mode", {"uniform", "hdr"}) == "hdr" ? SkyMode::Hdr
                                                                                 : SkyMode::Uniform;
    s.sky.color = r.color(sky.at("color"), "sky.color", 0.0, INFINITY);
    s.sky.intensity = r.numberAtLeast(sky.at("intensity"), "sky.intensity", 0.0, false);
    s.sky.hdr = r.string(sky.at("hdr"), "sky.hdr");
    s.sky.rotationDeg = r.number(sky.at("rotation_deg"), "sky.rotation_deg");
    if (s.sky.mode == SkyMode::Hdr && s.sky.hdr.empty())
        reject(source, "sky.hdr", sky.at("hdr"), "must name an image when sky.mode is \"hdr\"");

    const json& volumes = d.at("probe_volumes");
    if (!volumes.is_array()) reject(source, "probe_volumes", volumes, "must be an array");
    s.probeVolumes.clear();
    std::set<std::string> names;
    for (size_t i = 0; i < volumes.size(); ++i) {
        const std::string path = "probe_volumes[" + std::to_string(i) + "]";
        if (!volumes[i].is_object()) reject(source, path, volumes[i], "must be an object");
        ProbeVolumeSettings v = volumeFromJson(volumes[i], path, r);
        if (!names.insert(v.name).second)
            reject(source, path + ".name", volumes[i].at("name"), "must be unique among volumes");
        s.probeVolumes.push_back(std::move(v));
    }

    const json& rp = d.at("reflection_probes");
    s.reflectionProbes.enabled = r.boolean(rp.at("enabled"), "reflection_probes.enabled");
    r.array(rp.at("grid_dims"), "reflection_probes.grid_dims", 2);
    const int rx = r.integer(rp.at("grid_dims")[0], "reflection_probes.grid_dims[0]", 1, kMaxReflectionProbes);
    const int rz = r.integer(rp.at("grid_dims")[1], "reflection_probes.grid_dims[1]", 1, kMaxReflectionProbes);
    if (rx * rz > kMaxReflectionProbes)
        reject(source, "reflection_probes.grid_dims", rp.at("grid_dims"),
               "must be >= 1 each with a product <= " + std::to_string(kMaxReflectionProbes));
    s.reflectionProbes.gridDims = {rx, rz};
    s.reflectionProbes.heightOffset = r.number(rp.at("height_offset"), "reflection_probes.height_offset");
    s.reflectionProbes.rayCount = r.integer(rp.at("ray_count"), "reflection_probes.ray_count", 1, 1 << 20);
    s.reflectionProbes.groundColor = r.color(rp.at("ground_color"), "reflection_probes.ground_color", 0.0, INFINITY);
    s.reflectionProbes.strength = r.numberIn(rp.at("strength"), "reflection_probes.strength", 0.0, 1.0);

    const json& bake = d.at("bake");
    const std::string q = r.oneOf(bake.at("quality"), "bake.quality", {"draft", "standard", "high", "reference"});
    s.bake.quality = q == "draft"      ? QualityPreset::Draft
                     : q == "high"     ? QualityPreset::High
                     : q == "reference" ? QualityPreset::Reference
                                        : QualityPreset::Standard;
    if (!bake.at("rays").is_null()) s.bake.rays = r.integer(bake.at("rays"), "bake.rays", 1, 1 << 20);
    if (!bake.at("bounces").is_null())
        s.bake.bounces = r.integer(bake.at("bounces"), "bake.bounces", 0, kMaxBounces);
    s.bake.encoding = r.oneOf(bake.at("sh_encoding"), "bake.sh_encoding", {"radiance", "irradiance"}) ==
                              "irradiance"
                          ? ShEncoding::Irradiance
                          : ShEncoding::Radiance;
    s.bake.deringing = r.boolean(bake.at("deringing"), "bake.deringing");
    s.bake.errorMapResolution = r.integer(bake.at("error_map_resolution"), "bake.error_map_resolution",
                                          0, kMaxErrorMapResolution);

    const json& cam = d.at("camera");
    if (!cam.at("target").is_null()) {
        r.array(cam.at("target"), "camera.target", 3);
        glm::vec3 t;
        for (int i = 0; i < 3; ++i)
            t[i] = float(r.number(cam.at("target")[size_t(i)], "camera.target[" + std::to_string(i) + "]"));
        s.camera.target = t;
    }
    if (!cam.at("radius").is_null())
        s.camera.radius = r.numberAtLeast(cam.at("radius"), "camera.radius", 0.0, true);
    s.camera.azimuthDeg = r.number(cam.at("azimuth_deg"), "camera.azimuth_deg");
    s.camera.elevationDeg = r.numberIn(cam.at("elevation_deg"), "camera.elevation_deg", -89.9, 89.9);
    s.camera.fovDeg = r.numberIn(cam.at("fov_deg"), "camera.fov_deg", 1.0, 150.0);

    const json& ex = d.at("export");
    s.exportSettings.outDir = r.string(ex.at("out_dir"), "export.out_dir");
    if (s.exportSettings.outDir.empty())
        reject(source, "export.out_dir", ex.at("out_dir"), "must name a folder");
    s.exportSettings.gltf = r.boolean(ex.at("gltf"), "export.gltf");
    s.exportSettings.defaultScale = r.number(ex.at("default_scale"), "export.default_scale");
    s.exportSettings.defaultAmbient = r.numberAtLeast(ex.at("default_ambient"), "export.default_ambient", 0.0, false);
    return s;
}

void applyOverride(json& doc, const std::string& assignment) {
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
            if (idx.empty() || idx.find_first_not_of("0123456789") != std::string::npos)
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
        if (!node->is_object() || !node->contains(key))
            throw ProjectError("--set " + path + ": unknown parameter '" + walked +
                               "' (terralux --print-project lists them)");
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
            throw ProjectError(file.string() + ": not valid JSON (byte " + std::to_string(e.byte) + ")");
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
    rebase(copy.scene.exportSettings.outDir);
    writeFileAtomically(file, projectToJson(copy).dump(2) + "\n");
}

}  // namespace terralux
