#include "SceneLighting.h"

#include <numbers>

#include "EnvironmentImage.h"

namespace terralux {

Sky skyOf(const Project& p) {
    const SkySettings& s = p.scene.sky;
    if (s.mode == SkyMode::Uniform) return Sky::uniform(s.color * float(s.intensity));
    RgbImage img = readEquirectImage(p.hdrPath().string());
    // The image's colour is the sky; sky.color tints it (white leaves it as it is).
    for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] *= s.color[int(i % 3)];
    return Sky::equirect(std::move(img.rgb), img.width, img.height, float(s.intensity),
                         float(s.rotationDeg));
}

BakeLighting lightingOf(const Project& p) {
    const SceneDescription& scene = p.scene;
    BakeLighting l;
    l.sky = skyOf(p);
    l.sun.direction = sunDirection(scene.sun.azimuthDeg, scene.sun.elevationDeg);
    l.sun.illuminance = scene.sun.color * float(scene.sun.illuminance);
    l.sun.angularRadius = float(scene.sun.angularRadiusDeg * std::numbers::pi / 180.0);
    l.albedo = scene.terrain.albedo;
    return l;
}

}  // namespace terralux
