#pragma once
// A volume's placement as the bake places it (placeProbes), kept until that volume or the terrain
// changes: the docks (the parameter table's auto values), the window's estimate and the viewport's
// markers ask for it on every edit of the project, and placing a 16 384² grid's default volume
// takes 40 ms.

#include <cstddef>
#include <memory>

#include "bake/ProbePlacement.h"
#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"

namespace terralux {

// The placements kept at most: eight, within this many bytes as their .shprobe would take
// (ProbeLayout::fileBytes, which bounds their memory: a probe's position and flags take less
// than its coefficients, a cell the same 4 bytes). The newest is always kept.
inline constexpr size_t kKeptPlacements = 8;
inline constexpr size_t kKeptPlacementBytes = size_t(64) << 20;

// Volume `volume` of `scene` placed on `hf`, kept under the terrain's serial and the volume's
// settings. A volume the bake refuses throws placeProbes' PlacementError, kept too (each call
// throws the same message); any other failure (no such volume, memory) is thrown as it is, and
// not kept.
std::shared_ptr<const ProbeLayout> keptPlacement(const SceneDescription& scene, size_t volume, const Heightfield& hf);

// How many placements are kept, and their bytes as counted above.
size_t keptPlacements();
size_t keptPlacementBytes();

}  // namespace terralux
