#pragma once
// What the viewport draws and lets the user grab over the terrain (docs/user-guide.md, "Volumes
// in the viewport"): the bounds of every probe volume, of the reflection-probe grid, of the LPV
// cascades and of the water plane; the sun's direction; and, for the selected one, handles
// whose drags become parameter edits. Resolved from the settings by the placement's own rules
// (ProbePlacement.h's frames, placeReflectionProbes, waterLevel, placeCascades), so the box
// drawn is where the bake puts the probes. No Qt: the window turns these into lines and edits.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "scene/OrbitCamera.h"
#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"

namespace terralux {

enum class BoundsKind { ProbeVolume, ReflectionGrid, LpvCascade, Water, Sun };
inline constexpr int kBoundsKinds = 5;

// One thing drawn as a box (the water as a flat one; the sun as its point, min = max).
struct VolumeBounds {
    BoundsKind kind = BoundsKind::ProbeVolume;
    int index = 0;            // probe volume or LPV cascade index; 0 for the others
    std::string name;         // "volume 'probes'", "reflection probes", "LPV cascade 0", "water", "sun"
    glm::vec3 min{0.0f}, max{0.0f};
    bool operator==(const VolumeBounds&) const = default;
};

// The bounds of the enabled probe volumes, the reflection grid (when on), the water (when on and
// it has a level). A volume whose settings the placement refuses is left out.
std::vector<VolumeBounds> sceneBounds(const SceneDescription& scene, const Heightfield& hf);
// The LPV cascades (when on) around `camera`, where the viewport's update places them.
std::vector<VolumeBounds> lpvBounds(const SceneDescription& scene, const Heightfield& hf, const OrbitCamera& camera);
// The sun: a point `distance` from the camera's target toward the sun (manual or resolved).
std::optional<VolumeBounds> sunBounds(const SceneDescription& scene, const Heightfield& hf,
                                      const OrbitCamera& camera, float distance);

// A date_time sun's path over its day, the point every quarter hour from 00:00 to 24:00 at
// `distance` from the camera's target (97 points); empty for a manual sun or one without a place.
std::vector<glm::vec3> sunPath(const SceneDescription& scene, const Heightfield& hf, const OrbitCamera& camera,
                               float distance);

// What dragging a handle changes.
enum class HandleRole {
    Move,       // the box across the ground (x, z)
    MinCorner,  // the min (x, z) corner; the opposite one stays
    MaxCorner,  // the max (x, z) corner; the origin stays
    Height,     // up and down: height offset, box height or water level
    Sun,        // the sun's direction
};
struct Handle {
    HandleRole role = HandleRole::Move;
    glm::vec3 at{0.0f};
    bool vertical() const { return role == HandleRole::Height; }
};
// The handles of `b`: none for an LPV cascade (it follows the camera); a surface volume only
// its height; the water its level; the sun its point.
std::vector<Handle> handlesOf(const VolumeBounds& b, const SceneDescription& scene);

// The parameter values that put handle `role` of `b` `delta` metres from where the drag began
// (horizontal handles use x and z, Height uses y), against the scene as it was when the drag
// began, with a label for the undo step ("Move volume 'probes'"). Values are those of the
// project file (the same paths as `--set`); they keep the grid's other corner, count and
// spacing as the role says. For the sun, `delta` is the new direction toward it (unit): a
// manual sun takes it as its azimuth and elevation, a date_time sun moves along its day to the
// local time whose direction is nearest (sun.time_h, to 0.01 h).
struct HandleEdit {
    std::vector<std::pair<std::string, nlohmann::json>> values;
    std::string label;
};
HandleEdit dragHandle(const SceneDescription& scene, const Heightfield& hf, const VolumeBounds& b,
                      HandleRole role, const glm::vec3& delta);

}  // namespace terralux
