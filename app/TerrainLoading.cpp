#include "TerrainLoading.h"

#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>

#include <sys/stat.h>

#include "AlbedoImport.h"
#include "EnvironmentImage.h"
#include "SampleTerrain.h"

namespace terralux {

Project loadEffectiveProject(const std::string& projectFile, const std::vector<std::string>& sets,
                             const std::string& demOverride, std::vector<std::string>* warnings) {
    Project p;
    nlohmann::json doc = defaultProjectJson();
    std::string source = "defaults";
    if (!projectFile.empty()) {
        p = loadProject(projectFile, warnings);  // validates the file on its own first
        doc = projectToJson(p);
        source = projectFile;
    }
    if (!demOverride.empty()) {
        doc["terrain"]["dem"] =
            std::filesystem::absolute(demOverride).lexically_normal().generic_string();
    }
    if (!sets.empty() || !demOverride.empty()) {
        for (const std::string& s : sets) applyOverride(doc, s);
        p.scene = sceneFromJson(doc, sets.empty() ? source : "--set", warnings);
    }
    // A sky image is checked whenever one is named, even while sky.mode is "uniform": a typo
    // must not wait for the day the mode is switched.
    if (!p.scene.sky.hdr.empty()) {
        try {
            checkEquirectImage(p.hdrPath().string());
        } catch (const ImageError& e) {
            throw ImageError(std::string("sky.hdr: ") + e.what());
        }
    }
    // So is an albedo map, whatever the mode, for the same reason.
    if (!p.scene.terrain.albedoMap.empty()) checkAlbedoMap(p.albedoMapPath().string());
    return p;
}

namespace {
DemImportOptions importOptions(const Project& project) {
    DemImportOptions options;
    options.maxResolution = project.scene.terrain.maxResolution;
    options.verticalScale = project.scene.terrain.verticalScale;
    return options;
}
}  // namespace

DemImportResult loadProjectTerrain(const Project& project, const std::optional<GridWindow>& window) {
    DemImportOptions options = importOptions(project);
    options.window = window;
    const std::filesystem::path dem = project.demPath();
    if (dem.empty())
        return importDemFromMemory(kSampleTerrainName, sampleTerrainBytes(), sampleTerrainSize(),
                                   options);
    return importDem(dem.string(), options);
}

std::optional<int64_t> modifiedUnixNanoseconds(const std::filesystem::path& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return std::nullopt;
    return int64_t(st.st_mtim.tv_sec) * 1000000000 + int64_t(st.st_mtim.tv_nsec);
}

DemGrid loadProjectGrid(const Project& project) {
    const std::filesystem::path dem = project.demPath();
    if (dem.empty())
        return demGridFromMemory(kSampleTerrainName, sampleTerrainBytes(), sampleTerrainSize(), importOptions(project));
    return demGrid(dem.string(), importOptions(project));
}

namespace {

// What a map import depends on: the file as it is on disk, the footprint and the fallback.
struct MapKey {
    std::string path;
    std::filesystem::file_time_type time;
    std::uintmax_t size = 0;
    int width = 0, depth = 0;
    double cellX = 0, cellZ = 0;
    double easting = 0, northing = 0;
    std::string crs;
    float fallback[3] = {0, 0, 0};
    bool operator==(const MapKey&) const = default;
};

std::mutex mapMutex;
std::optional<MapKey> lastMapKey;
std::shared_ptr<const SurfaceAlbedo> lastMap;

}  // namespace

std::shared_ptr<const SurfaceAlbedo> surfaceAlbedoOf(const Project& project, const Heightfield& terrain) {
    const TerrainSettings& t = project.scene.terrain;
    switch (t.albedoMode) {
        case AlbedoMode::Constant: return nullptr;
        case AlbedoMode::Ramp:
            return std::make_shared<const SurfaceAlbedo>(rampAlbedo(terrain, t.ramp, t.verticalScale, t.albedo));
        case AlbedoMode::Map: break;
    }
    const std::string path = project.albedoMapPath().string();
    MapKey key{path, {}, 0, terrain.width(), terrain.depth(), terrain.cellSizeX(), terrain.cellSizeZ(),
               terrain.geo.easting, terrain.geo.northing, terrain.geo.crsWkt, {t.albedo.x, t.albedo.y, t.albedo.z}};
    std::error_code ec;
    key.time = std::filesystem::last_write_time(path, ec);
    if (!ec) key.size = std::filesystem::file_size(path, ec);
    {
        std::lock_guard lock(mapMutex);
        if (!ec && lastMapKey && *lastMapKey == key) return lastMap;
    }
    const std::filesystem::path dem = project.demPath();
    auto field = std::make_shared<const SurfaceAlbedo>(
        importAlbedoMap(path, terrain, dem.empty() ? std::string(kSampleTerrainName) : dem.string(), t.albedo));
    if (!ec) {
        std::lock_guard lock(mapMutex);
        lastMapKey = key;
        lastMap = field;
    }
    return field;
}

}  // namespace terralux
