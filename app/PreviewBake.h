#pragma once
// A draft bake held in memory for the viewport: what the probes of the current settings look
// like, seconds after an edit, without touching the output folder.

#include <atomic>
#include <memory>
#include <vector>

#include "Project.h"
#include "bake/ReflectionBake.h"
#include "render/TerrainRenderer.h"
#include "terrain/Heightfield.h"

namespace terralux {

// Every enabled volume at draft quality (rays and bounces of the draft preset), with the
// diagnostics the bake writes (an error map of at most 32 points a side). Throws
// BakeCancelled when `cancel` is set, PlacementError for bad volume settings. The terrain albedo
// is the project's (surfaceAlbedoOf), or terrain.albedo where its map cannot be read.
std::vector<GpuProbeVolume> previewProbes(const Project& project, const Heightfield& hf,
                                          const std::atomic<bool>* cancel);

// The same, with the reflection probes when they are enabled: the bake's grid, cube size and
// encoding at no more than 4 rays per texel, lit like the draft (null when disabled).
struct PreviewBake {
    std::vector<GpuProbeVolume> volumes;
    std::shared_ptr<const ReflectionProbeSet> reflections;
};
PreviewBake previewBake(const Project& project, const Heightfield& hf, const std::atomic<bool>* cancel);

}  // namespace terralux
