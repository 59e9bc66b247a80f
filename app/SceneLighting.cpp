#include "SceneLighting.h"

#include <atomic>
#include <filesystem>
#include <list>
#include <mutex>
#include <numbers>

#include <glm/common.hpp>

#include "EnvironmentImage.h"
#include "bake/PhysicalSky.h"

namespace terralux {

namespace {

// An edit of the sun, the sky's tint or intensity, or a camera move must not read and filter the
// HDR again: the last few environments are kept, keyed by file and rotation, and scaled by tint ×
// intensity on the way out. A file rewritten on disk (new time or size) is a new key.
struct SkyKey {
    std::string path;
    std::filesystem::file_time_type time;
    std::uintmax_t size = 0;
    float rotation = 0.0f;
    bool operator==(const SkyKey&) const = default;
};

std::mutex skyMutex;
std::list<std::pair<SkyKey, Sky>> skyCache;  // most recent first
std::atomic<size_t> skyReads{0};
constexpr size_t kSkyCacheEntries = 4;

// Sampling and filtering the physical sky takes tens of milliseconds: it is kept too, keyed by
// what shapes it (the sun's direction and the turbidity); intensity scales it on the way out.
struct PhysicalKey {
    glm::vec3 sun{0.0f};
    double turbidity = 0.0;
    bool operator==(const PhysicalKey&) const = default;
};
std::list<std::pair<PhysicalKey, Sky>> physicalCache;  // most recent first, under skyMutex
std::atomic<size_t> physicalBuilds{0};

glm::vec3 sunDirectionOf(const SceneDescription& scene) {
    return sunDirection(scene.sun.azimuthDeg, scene.sun.elevationDeg);
}

Sky physicalSkyOf(const SceneDescription& scene) {
    const PhysicalKey key{sunDirectionOf(scene), scene.sky.turbidity};
    {
        std::lock_guard lock(skyMutex);
        for (auto it = physicalCache.begin(); it != physicalCache.end(); ++it)
            if (it->first == key) {
                physicalCache.splice(physicalCache.begin(), physicalCache, it);
                return it->second;
            }
    }
    Sky sky = Sky::physical(PhysicalSky(key.sun, key.turbidity));
    ++physicalBuilds;
    std::lock_guard lock(skyMutex);
    physicalCache.emplace_front(key, sky);
    if (physicalCache.size() > kSkyCacheEntries) physicalCache.pop_back();
    return sky;
}

}  // namespace

size_t hdrSkyReads() { return skyReads.load(); }
size_t physicalSkyBuilds() { return physicalBuilds.load(); }

Sky skyOf(const Project& p) {
    const SkySettings& s = p.scene.sky;
    if (s.mode == SkyMode::Uniform) return Sky::uniform(s.color * float(s.intensity));
    // sky.color is not read: the model gives the colour; intensity exposes sky and sun alike.
    if (s.mode == SkyMode::Physical) return physicalSkyOf(p.scene).scaled(glm::vec3(float(s.intensity)));
    const std::string path = p.hdrPath().string();
    SkyKey key{path, {}, 0, float(s.rotationDeg)};
    // The image's colour is the sky; sky.color tints it (white leaves it as it is).
    const glm::vec3 scale = s.color * float(s.intensity);
    std::error_code ec;
    key.time = std::filesystem::last_write_time(path, ec);
    key.size = ec ? 0 : std::filesystem::file_size(path, ec);
    {
        std::lock_guard lock(skyMutex);
        for (auto it = skyCache.begin(); it != skyCache.end(); ++it)
            if (it->first == key) {
                skyCache.splice(skyCache.begin(), skyCache, it);
                return it->second.scaled(scale);  // levels are shared: no copy of the image
            }
    }
    RgbImage img = readEquirectImage(path);
    ++skyReads;
    Sky sky = Sky::equirect(std::move(img.rgb), img.width, img.height, 1.0f, float(s.rotationDeg));
    if (!ec) {
        std::lock_guard lock(skyMutex);
        skyCache.emplace_front(key, sky);
        if (skyCache.size() > kSkyCacheEntries) skyCache.pop_back();
    }
    return sky.scaled(scale);
}

FogSettings resolvedFog(const FogSettings& fog, const Sky& sky, const Heightfield& terrain) {
    FogSettings f = fog;
    if (!f.baseHeight) f.baseHeight = double(terrain.minHeight());
    // The mean radiance over the sphere is the SH DC term times Y_00 = 1 / (2√π).
    if (!f.color) f.color = glm::max(sky.sh().c[0] * 0.28209479f, glm::vec3(0.0f));
    return f;
}

BakeLighting lightingOf(const Project& p) {
    const SceneDescription& scene = p.scene;
    BakeLighting l;
    l.sky = skyOf(p);
    l.sun.direction = sunDirectionOf(scene);
    if (scene.sky.mode == SkyMode::Physical && scene.sun.followSky)
        l.sun.illuminance = PhysicalSky(l.sun.direction, scene.sky.turbidity).sunIlluminance() *
                            float(scene.sky.intensity);
    else
        l.sun.illuminance = scene.sun.color * float(scene.sun.illuminance);
    l.sun.angularRadius = float(scene.sun.angularRadiusDeg * std::numbers::pi / 180.0);
    l.albedo = scene.terrain.albedo;
    return l;
}

}  // namespace terralux
