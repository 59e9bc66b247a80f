#pragma once
// The farm's two ends around a tile bake (docs/farm.md): whether a tile needs baking again, and
// the merge of a region's baked tiles into one scene.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "BakeJob.h"

namespace terralux {

// Why the tile `request` names need not be baked again ("unchanged since its bake"): its folder
// holds a complete bake of the same tile with the same inputs. Nothing when it must be baked.
std::optional<std::string> unchangedTile(const BakeRequest& request);

struct MergeOutcome {
    std::filesystem::path dir;
    int tiles = 0;
    size_t grids = 0;
    nlohmann::json report;
    std::vector<std::filesystem::path> files;
};

// Merges DIR/tiles/*/ into DIR/scene.gltf, DIR/tiles.json and DIR/bake_report.json, staged and
// committed whole. Throws ProjectError naming the missing or mismatched tiles, FileWriteError
// when the write fails.
MergeOutcome mergeTiles(const std::filesystem::path& dir);

}  // namespace terralux
