#include "VolumeHandles.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "SceneLighting.h"
#include "bake/ProbePlacement.h"
#include "bake/ReflectionBake.h"
#include "bake/Sky.h"
#include "lpv/Lpv.h"
#include "water/Water.h"

namespace terralux {

namespace {

// Values written by a drag: centimetres, so the project file does not fill with float noise.
double tidy(double v) { return std::round(v * 100.0) / 100.0; }

std::string volumeName(const ProbeVolumeSettings& v) { return "volume '" + v.name + "'"; }

// The smallest spacing or box edge a resize leaves: a DEM cell (probes closer than the terrain
// samples see no detail the terrain has), and at least a centimetre.
double smallest(const Heightfield& hf) { return std::max({hf.cellSizeX(), hf.cellSizeZ(), 0.01}); }

// A terrain or reflection grid resized by one corner: the first probe and the spacing that put
// the moved corner `delta` away and keep the other where it was. An axis with one probe keeps
// its spacing (the grid has no extent there; the first probe follows a min-corner drag).
void resizeGrid(glm::dvec2& first, glm::dvec2& spacing, const glm::ivec2& n, HandleRole role, const glm::dvec2& delta,
                double minSpacing) {
    for (int a = 0; a < 2; ++a) {
        if (n[a] <= 1) {
            if (role == HandleRole::MinCorner) first[a] += delta[a];
            spacing[a] = std::max(spacing[a], minSpacing);
            continue;
        }
        const double steps = double(n[a] - 1);
        const double lo = first[a], hi = first[a] + spacing[a] * steps;
        if (role == HandleRole::MaxCorner) {
            spacing[a] = std::max((hi + delta[a] - lo) / steps, minSpacing);
        } else {
            spacing[a] = std::max((hi - (lo + delta[a])) / steps, minSpacing);
            first[a] = hi - spacing[a] * steps;
        }
    }
}

nlohmann::json pair(const glm::dvec2& v) { return nlohmann::json::array({tidy(v.x), tidy(v.y)}); }
nlohmann::json triple(const glm::dvec3& v) { return nlohmann::json::array({tidy(v.x), tidy(v.y), tidy(v.z)}); }

const char* verb(HandleRole role) {
    switch (role) {
        case HandleRole::Move: return "Move ";
        case HandleRole::MinCorner:
        case HandleRole::MaxCorner: return "Resize ";
        case HandleRole::Height: return "Set the height of ";
        case HandleRole::Sun: return "Move ";
    }
    return "Edit ";
}

HandleEdit dragProbeVolume(const SceneDescription& scene, const Heightfield& hf, int index, HandleRole role,
                           const glm::dvec3& d) {
    const ProbeVolumeSettings& v = scene.probeVolumes.at(size_t(index));
    const std::string at = "probe_volumes[" + std::to_string(index) + "].";
    HandleEdit e;
    e.label = verb(role) + volumeName(v);
    if (role == HandleRole::Height && followsSurface(v.placement)) {
        e.values.emplace_back(at + "height_offset", tidy(std::max(v.heightOffset + d.y, 0.1)));
        return e;
    }
    switch (v.placement) {
        case ProbePlacement::Terrain: {
            const TerrainGridFrame f = terrainGridFrame(v, hf);
            glm::dvec2 first(f.first), spacing(f.spacing);
            if (role == HandleRole::Move) {
                e.values.emplace_back(at + "origin", pair(first + glm::dvec2(d.x, d.z)));
                return e;
            }
            resizeGrid(first, spacing, {v.gridDims[0], v.gridDims[2]}, role, {d.x, d.z}, smallest(hf));
            e.values.emplace_back(at + "origin", pair(first));
            e.values.emplace_back(at + "spacing", pair(spacing));
            return e;
        }
        case ProbePlacement::Box: {
            const BoxGridFrame f = boxGridFrame(v, hf);
            glm::dvec3 origin(f.origin);
            std::array<int, 3> dims = v.gridDims;
            const double cell = f.cell;
            if (role == HandleRole::Move) {
                e.values.emplace_back(at + "origin", triple(origin + glm::dvec3(d.x, 0.0, d.z)));
                return e;
            }
            // A box grid keeps its cubic cells: resizing adds or removes whole cells.
            auto cells = [&](double metres) { return int(std::lround(metres / cell)); };
            if (role == HandleRole::Height) {
                dims[1] = std::max(1, dims[1] + cells(d.y));
            } else {
                for (int a : {0, 2}) {
                    const double delta = a == 0 ? d.x : d.z;
                    if (role == HandleRole::MaxCorner) {
                        dims[size_t(a)] = std::max(1, dims[size_t(a)] + cells(delta));
                    } else {
                        const int k = std::min(cells(delta), dims[size_t(a)] - 1);
                        origin[a] += k * cell;
                        dims[size_t(a)] -= k;
                    }
                }
            }
            e.values.emplace_back(at + "origin", triple(origin));
            e.values.emplace_back(at + "spacing", tidy(cell));
            e.values.emplace_back(at + "grid_dims", nlohmann::json::array({dims[0], dims[1], dims[2]}));
            return e;
        }
        case ProbePlacement::Adaptive: {
            const AdaptiveBox box = adaptiveBox(v, hf);
            glm::dvec3 origin = box.origin, size = box.size;
            const double least = smallest(hf);
            if (role == HandleRole::Move) {
                e.values.emplace_back(at + "origin", triple(origin + glm::dvec3(d.x, 0.0, d.z)));
                return e;
            }
            if (role == HandleRole::Height) {
                size.y = std::max(size.y + d.y, least);
            } else {
                for (int a : {0, 2}) {
                    if (role == HandleRole::MaxCorner) {
                        size[a] = std::max(size[a] + d[a], least);
                    } else {
                        const double hi = origin[a] + size[a];
                        origin[a] = std::min(origin[a] + d[a], hi - least);
                        size[a] = hi - origin[a];
                    }
                }
            }
            e.values.emplace_back(at + "origin", triple(origin));
            e.values.emplace_back(at + "adaptive.size", triple(size));
            return e;
        }
        case ProbePlacement::Surface: break;
    }
    throw std::invalid_argument(at + "placement = \"surface\": " + volumeName(v) +
                                " covers the whole footprint, so only its height (" + at + "height_offset) moves");
}

}  // namespace

std::vector<VolumeBounds> sceneBounds(const SceneDescription& scene, const Heightfield& hf) {
    std::vector<VolumeBounds> out;
    const float lowest = hf.minHeight(), highest = hf.maxHeight();
    for (size_t i = 0; i < scene.probeVolumes.size(); ++i) {
        const ProbeVolumeSettings& v = scene.probeVolumes[i];
        if (!v.enabled) continue;
        VolumeBounds b{BoundsKind::ProbeVolume, int(i), volumeName(v)};
        switch (v.placement) {
            case ProbePlacement::Terrain: {
                // The probes' columns, from the lowest ground to the highest probe.
                const TerrainGridFrame f = terrainGridFrame(v, hf);
                const glm::vec2 last = f.first + f.spacing * glm::vec2(float(std::max(v.gridDims[0] - 1, 0)),
                                                                        float(std::max(v.gridDims[2] - 1, 0)));
                b.min = glm::vec3(std::min(f.first.x, last.x), lowest, std::min(f.first.y, last.y));
                b.max = glm::vec3(std::max(f.first.x, last.x), highest + float(v.heightOffset),
                                  std::max(f.first.y, last.y));
                break;
            }
            case ProbePlacement::Box: {
                const BoxGridFrame f = boxGridFrame(v, hf);
                b.min = f.origin;
                b.max = f.origin + f.cell * glm::vec3(float(v.gridDims[0]), float(v.gridDims[1]), float(v.gridDims[2]));
                break;
            }
            case ProbePlacement::Adaptive: {
                const AdaptiveBox box = adaptiveBox(v, hf);
                b.min = glm::vec3(box.origin);
                b.max = glm::vec3(box.origin + box.size);
                break;
            }
            case ProbePlacement::Surface:
                b.min = glm::vec3(hf.minX(), lowest, hf.minZ());
                b.max = glm::vec3(hf.maxX(), highest + float(v.heightOffset), hf.maxZ());
                break;
        }
        out.push_back(b);
    }
    if (scene.reflectionProbes.enabled) {
        try {
            const ReflectionLayout L = placeReflectionProbes(scene.reflectionProbes, hf);
            VolumeBounds b{BoundsKind::ReflectionGrid, 0, "reflection probes"};
            const glm::vec2 last = L.origin + L.spacing * glm::vec2(float(L.dims[0] - 1), float(L.dims[1] - 1));
            float top = lowest, bottom = highest;
            for (size_t i = 0; i < L.count(); ++i) {
                top = std::max(top, L.positions[i].y);
                bottom = std::min(bottom, L.lowestBelow[i]);
            }
            b.min = glm::vec3(L.origin.x, bottom, L.origin.y);
            b.max = glm::vec3(last.x, top, last.y);
            out.push_back(b);
        } catch (const std::exception&) {
            // Settings the placement refuses draw no bounds; the dock says why.
        }
    }
    if (scene.water.enabled) {
        if (const std::optional<double> level = water::waterLevel(scene.water, hf)) {
            VolumeBounds b{BoundsKind::Water, 0, "water"};
            b.min = glm::vec3(hf.minX(), float(*level), hf.minZ());
            b.max = glm::vec3(hf.maxX(), float(*level), hf.maxZ());
            out.push_back(b);
        }
    }
    return out;
}

std::vector<VolumeBounds> lpvBounds(const SceneDescription& scene, const Heightfield& hf, const OrbitCamera& camera) {
    std::vector<VolumeBounds> out;
    if (!scene.lpv.enabled) return out;
    try {
        const std::vector<lpv::CascadeLayout> cascades = lpv::placeCascades(
            lpv::resolvedOn(scene.lpv, hf), glm::dvec3(camera.lpvEye()), glm::dvec3(camera.lpvViewDirection()));
        for (size_t i = 0; i < cascades.size(); ++i) {
            VolumeBounds b{BoundsKind::LpvCascade, int(i), "LPV cascade " + std::to_string(i)};
            b.min = glm::vec3(cascades[i].origin());
            b.max = glm::vec3(cascades[i].origin() + glm::dvec3(cascades[i].size));
            out.push_back(b);
        }
    } catch (const std::exception&) {
    }
    return out;
}

std::optional<VolumeBounds> sunBounds(const SceneDescription& scene, const Heightfield& hf, const OrbitCamera& camera,
                                      float distance) {
    // The image's sun stands where the image has it: no handle moves it.
    if (sunFromSkyImage(scene)) return std::nullopt;
    try {
        const SunAngles a = sunAnglesOf(scene, hf);
        VolumeBounds b{BoundsKind::Sun, 0, "sun"};
        b.min = b.max = camera.target + distance * sunDirection(a.azimuthDeg, a.elevationDeg);
        return b;
    } catch (const std::exception&) {
        return std::nullopt;  // a date_time sun without a place: the Sun & Sky dock says why
    }
}

std::vector<glm::vec3> sunPath(const SceneDescription& scene, const Heightfield& hf, const OrbitCamera& camera,
                               float distance) {
    std::vector<glm::vec3> path;
    if (scene.sun.mode != SunMode::DateTime || sunFromSkyImage(scene)) return path;
    SceneDescription at = scene;
    try {
        for (int q = 0; q <= 96; ++q) {
            at.sun.timeH = q / 4.0;
            const SunAngles a = sunAnglesOf(at, hf);
            path.push_back(camera.target + distance * sunDirection(a.azimuthDeg, a.elevationDeg));
        }
    } catch (const std::exception&) {
        path.clear();  // no place to stand the sun over
    }
    return path;
}

std::vector<Handle> handlesOf(const VolumeBounds& b, const SceneDescription& scene) {
    const glm::vec3 centre = 0.5f * (b.min + b.max);
    const glm::vec3 top(centre.x, b.max.y, centre.z);
    // The height handle stands above the top face, a sixth of the box's diagonal, so it is apart
    // from the move handle in every view but straight down (where height cannot be dragged).
    const float lift = std::max(glm::length(glm::vec2(b.max.x - b.min.x, b.max.z - b.min.z)) / 6.0f, 1.0f);
    switch (b.kind) {
        case BoundsKind::LpvCascade: return {};
        case BoundsKind::Sun: return {{HandleRole::Sun, b.min}};
        case BoundsKind::Water: return {{HandleRole::Height, top}};
        case BoundsKind::ProbeVolume:
            if (scene.probeVolumes.at(size_t(b.index)).placement == ProbePlacement::Surface)
                return {{HandleRole::Height, top + glm::vec3(0.0f, lift, 0.0f)}};
            break;
        case BoundsKind::ReflectionGrid: break;
    }
    return {{HandleRole::Move, top},
            {HandleRole::MinCorner, glm::vec3(b.min.x, b.max.y, b.min.z)},
            {HandleRole::MaxCorner, glm::vec3(b.max.x, b.max.y, b.max.z)},
            {HandleRole::Height, top + glm::vec3(0.0f, lift, 0.0f)}};
}

HandleEdit dragHandle(const SceneDescription& scene, const Heightfield& hf, const VolumeBounds& b, HandleRole role,
                      const glm::vec3& delta) {
    const glm::dvec3 d(delta);
    switch (b.kind) {
        case BoundsKind::ProbeVolume: return dragProbeVolume(scene, hf, b.index, role, d);
        case BoundsKind::ReflectionGrid: {
            const ReflectionLayout L = placeReflectionProbes(scene.reflectionProbes, hf);
            const ReflectionProbeSettings& r = scene.reflectionProbes;
            HandleEdit e;
            e.label = std::string(verb(role)) + "reflection probes";
            if (role == HandleRole::Height) {
                e.values.emplace_back("reflection_probes.height_offset", tidy(r.heightOffset + d.y));
                return e;
            }
            glm::dvec2 first(L.origin), spacing(L.spacing);
            if (role == HandleRole::Move) {
                e.values.emplace_back("reflection_probes.origin", pair(first + glm::dvec2(d.x, d.z)));
                return e;
            }
            // An axis with one probe has spacing 0 in the layout; the setting must stay > 0.
            if (r.spacing) spacing = glm::max(spacing, glm::dvec2(*r.spacing));
            resizeGrid(first, spacing, {r.gridDims[0], r.gridDims[1]}, role, {d.x, d.z}, smallest(hf));
            e.values.emplace_back("reflection_probes.origin", pair(first));
            e.values.emplace_back("reflection_probes.spacing", pair(spacing));
            return e;
        }
        case BoundsKind::Water: {
            const std::optional<double> level = water::waterLevel(scene.water, hf);
            if (!level)
                throw std::invalid_argument(
                    "water.level = null: auto found no water surface on this terrain, so there is no level to move "
                    "(set water.level)");
            return {{{"water.level", tidy(*level + d.y)}}, "Set the water level"};
        }
        case BoundsKind::Sun: {
            const glm::dvec3 to = glm::normalize(d);
            if (scene.sun.mode == SunMode::DateTime) {
                // Along the day: the minute whose sun is nearest the direction, coarse then fine.
                SceneDescription at = scene;
                auto closeness = [&](double hours) {
                    at.sun.timeH = hours;
                    const SunAngles a = sunAnglesOf(at, hf);
                    return glm::dot(glm::dvec3(sunDirection(a.azimuthDeg, a.elevationDeg)), to);
                };
                double best = scene.sun.timeH, bestDot = -2.0;
                for (int m = 0; m <= 24 * 60; m += 10)
                    if (const double c = closeness(m / 60.0); c > bestDot) bestDot = c, best = m / 60.0;
                const double coarse = best;
                for (int m = -10; m <= 10; ++m) {
                    const double hours = std::clamp(coarse + m / 60.0, 0.0, 24.0);
                    if (const double c = closeness(hours); c > bestDot) bestDot = c, best = hours;
                }
                // To the hundredth of an hour the Local time slider shows.
                return {{{"sun.time_h", std::round(best * 100.0) / 100.0}}, "Set the time of day"};
            }
            // Sky.h's sunDirection inverted: azimuth clockwise from north (-z) toward east (+x).
            double azimuth = std::atan2(to.x, -to.z) * 180.0 / std::numbers::pi;
            if (azimuth < 0.0) azimuth += 360.0;
            const double elevation = std::asin(std::clamp(to.y, -1.0, 1.0)) * 180.0 / std::numbers::pi;
            auto tenth = [](double v) { return std::round(v * 10.0) / 10.0; };
            return {{{"sun.azimuth_deg", tenth(azimuth)}, {"sun.elevation_deg", tenth(elevation)}}, "Move the sun"};
        }
        case BoundsKind::LpvCascade: break;
    }
    throw std::invalid_argument(b.name + " follows the camera and has no handles");
}

}  // namespace terralux
