#pragma once
// Shared by every command and, later, the UI: the effective project and its terrain.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "DemImport.h"
#include "Project.h"
#include "terrain/SurfaceAlbedo.h"

namespace terralux {

// Defaults, then PROJECT (if given), then each --set in order; then validation. A --dem FILE
// replaces terrain.dem (resolved against the current directory).
Project loadEffectiveProject(const std::string& projectFile, const std::vector<std::string>& sets,
                             const std::string& demOverride, std::vector<std::string>* warnings);

// The project's DEM, or the embedded sample when it names none; `window`: only that window of its
// grid (DemImportOptions::window).
DemImportResult loadProjectTerrain(const Project& project, const std::optional<GridWindow>& window = std::nullopt);
// The grid loadProjectTerrain makes, without holding the DEM where it can (demGrid).
DemGrid loadProjectGrid(const Project& project);

// A file's modification time in nanoseconds since the Unix epoch, as stat(2) gives it
// (std::filesystem's file clock has its own epoch); none when the file cannot be read.
std::optional<int64_t> modifiedUnixNanoseconds(const std::filesystem::path& path);

// The project's terrain albedo over `terrain` (its DEM's import), as the bake, the preview, the
// renderer and the glTF export all use it: null in mode constant (terrain.albedo everywhere), the
// ramp, or terrain.albedo_map imported onto the footprint (throws AlbedoMapError). The last map
// import is kept and reused while the map file, the footprint and terrain.albedo are the same.
std::shared_ptr<const SurfaceAlbedo> surfaceAlbedoOf(const Project& project, const Heightfield& terrain);

}  // namespace terralux
