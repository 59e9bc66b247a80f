#pragma once
// One bake, start to finish: terrain, sky, placement, integration, optional reference
// comparison, then the export (.shprobe per volume, glTF scene, bake_report.json). Nothing is
// written until everything is computed, and files are staged and renamed, so a cancelled or
// failed bake leaves earlier outputs untouched.

#include <atomic>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "Project.h"

namespace terralux {

struct BakeRequest {
    Project project;
    int threads = 0;                          // 0 = all cores
    bool compareReference = false;            // also run the reference and report the error
};

struct BakeOutcome {
    nlohmann::json report;
    std::filesystem::path outDir;
    std::vector<std::filesystem::path> files;
};

// Phase name and progress in [0, 1] of the whole bake.
using BakeProgress = std::function<void(const std::string& phase, double fraction)>;

// Throws DemError / ImageError / ProjectError / PlacementError for bad input, BakeCancelled
// when `cancel` was set, FileWriteError when the export fails.
BakeOutcome runBake(const BakeRequest& request, const BakeProgress& progress,
                    const std::atomic<bool>* cancel);

}  // namespace terralux
