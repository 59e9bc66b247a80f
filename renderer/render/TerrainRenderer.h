#pragma once
// Draws the terrain offscreen the way the engine will light it, or one of the debug views. The
// same path serves `terralux --render`, the render tests and the UI viewport (which presents
// the image).

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "bake/ProbeDiagnostics.h"
#include "bake/Sky.h"
#include "bake/SphericalHarmonics.h"
#include "render/OrbitCamera.h"
#include "terrain/Heightfield.h"
#include "vk/VulkanContext.h"

namespace terralux {

// One baked volume as the GPU reads it: the .shprobe grid (occupancy + coefficients).
struct GpuProbeVolume {
    std::string name;  // the volume's, for overlays and messages
    glm::uvec3 dims{1};
    glm::vec3 origin{0.0f};
    float spacing = 1.0f;
    std::vector<std::array<glm::vec3, 9>> coeffs;  // per probe
    std::vector<int32_t> occupancy;                // dims.x * dims.y * dims.z
    float fallbackBlendDistance = 0.0f;
    bool irradianceEncoded = false;                // coefficients hold Â_l L_k
    float scale = 1.0f;                            // the file's default SH scale
    // What the bake wrote beside the file (moved probes for view 54, the error map for view 56);
    // unset for bakes without it.
    std::optional<ProbeDiagnostics> diagnostics;
};

struct RenderSettings {
    uint32_t width = 640, height = 360;
    int debugView = 0;
    bool probes = true;           // false: exactly the image without probe lighting
    bool linearOutput = false;    // scene-linear values for EXR instead of the display encoding
    OrbitCamera camera;
    glm::vec3 albedo{0.3f};
    SunLight sun;
    sh::ShRgb skySh;
    float exposure = 1.0f;
    float roughness = 0.8f;
    bool showProbePositions = false;  // the overlay of setProbePositions (view 54 always marks
                                      // moved and rejected probes)
    bool showLeaves = false;          // the overlay of setProbeLeaves
};

struct RenderedImage {
    uint32_t width = 0, height = 0;
    std::vector<float> rgba;      // row 0 at the top
    double milliseconds = 0.0;    // draw + readback, wall clock
};

class TerrainRenderer {
public:
    // Large DEMs are drawn from every k-th row and column (always including the last), the
    // smallest k that keeps the mesh within `vertexBudget`: a uniform grid, so no cracks.
    TerrainRenderer(vk::VulkanContext& ctx, const Heightfield& hf,
                    size_t vertexBudget = size_t(1) << 20);
    ~TerrainRenderer();

    void setProbeVolumes(const std::vector<GpuProbeVolume>& volumes);
    // Probe positions for the overlay: xyz, w = 1 valid, 2 moved up, 0 inside the terrain.
    void setProbePositions(const std::vector<glm::vec4>& positions);
    // Octree leaves for the leaf overlay: min corner xyz, w edge (metres).
    void setProbeLeaves(const std::vector<glm::vec4>& leaves);
    RenderedImage render(const RenderSettings& settings);
    // The colour image of the last render (TRANSFER_SRC_OPTIMAL), for a presenter.
    VkImage lastImage() const;

    int meshStride() const { return stride_; }
    size_t vertexCount() const { return vertexCount_; }
    size_t triangleCount() const { return indexCount_ / 3; }
    size_t probeBytes() const { return probeBytes_; }

private:
    struct Gpu;
    vk::VulkanContext& ctx_;
    const Heightfield& hf_;
    std::unique_ptr<Gpu> gpu_;
    int stride_ = 1;
    size_t vertexCount_ = 0, indexCount_ = 0, probeBytes_ = 0;
    int volumeCount_ = 0;
    uint32_t markerCount_ = 0, leafCount_ = 0;
    float smallestLeaf_ = 1.0f;
};

}  // namespace terralux
