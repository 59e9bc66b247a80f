#include "TerrainLoading.h"

#include <filesystem>
#include <fstream>

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
    return p;
}

DemImportResult loadProjectTerrain(const Project& project) {
    DemImportOptions options;
    options.maxResolution = project.scene.terrain.maxResolution;
    options.verticalScale = project.scene.terrain.verticalScale;
    const std::filesystem::path dem = project.demPath();
    if (dem.empty())
        return importDemFromMemory(kSampleTerrainName, sampleTerrainBytes(), sampleTerrainSize(),
                                   options);
    return importDem(dem.string(), options);
}

}  // namespace terralux
