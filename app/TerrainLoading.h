#pragma once
// Shared by every command and, later, the UI: the effective project and its terrain.

#include <string>
#include <vector>

#include "DemImport.h"
#include "Project.h"

namespace terralux {

// Defaults, then PROJECT (if given), then each --set in order; then validation. A --dem FILE
// replaces terrain.dem (resolved against the current directory).
Project loadEffectiveProject(const std::string& projectFile, const std::vector<std::string>& sets,
                             const std::string& demOverride, std::vector<std::string>* warnings);

// The project's DEM, or the embedded sample when it names none.
DemImportResult loadProjectTerrain(const Project& project);

}  // namespace terralux
