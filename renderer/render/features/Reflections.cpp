#include "render/features/Reflections.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include <glm/gtc/packing.hpp>
#include <glm/packing.hpp>
#include <tbb/parallel_for.h>

#include "bake/ReflectionBake.h"
#include "vk/Swapchain.h"

namespace terralux::features {

using namespace frame;

std::unique_ptr<ReflectionResources> buildReflections(vk::VulkanContext& ctx, RendererGpu& g,
                                                     const ReflectionProbeSet& set) {
    const ReflectionProbeSet& s = set;
    const size_t n = s.probes.size();
    if (s.dims[0] < 1 || s.dims[1] < 1 || size_t(s.dims[0]) * size_t(s.dims[1]) != n)
        throw std::invalid_argument("reflection probes: a grid of " + std::to_string(s.dims[0]) + " x " +
                                    std::to_string(s.dims[1]) + " holds " + std::to_string(n) + " probes");
    const bool cubemap = s.encoding == ReflectionEncoding::Cubemap;
    if (cubemap) {
        if (s.faceSize < 1 || (s.faceSize & (s.faceSize - 1)) != 0 || s.mipCount != cubeMipCount(s.faceSize))
            throw std::invalid_argument("reflection probes: cube faces of " + std::to_string(s.faceSize) +
                                        " texels with " + std::to_string(s.mipCount) + " mip levels");
        for (const ReflectionProbe& p : s.probes)
            if (p.texels.size() != s.texelsPerProbe())
                throw std::invalid_argument("reflection probe " + std::to_string(p.id) + " holds " +
                                            std::to_string(p.texels.size()) + " texels, not " +
                                            std::to_string(s.texelsPerProbe()));
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(ctx.physicalDevice(), &props);
        if (6 * n > props.limits.maxImageArrayLayers)
            throw std::invalid_argument("reflection probes: " + std::to_string(n) + " cubes need " +
                                        std::to_string(6 * n) + " image layers, the device holds " +
                                        std::to_string(props.limits.maxImageArrayLayers));
    }

    auto r = std::make_unique<ReflectionResources>();
    std::vector<blocks::ReflectionProbeRecord> records(n);
    std::vector<glm::vec4> markers(n);
    for (size_t i = 0; i < n; ++i) {
        const ReflectionProbe& p = s.probes[i];
        records[i].position = p.position;
        records[i].halfExtent = p.halfExtent;
        for (int f = 0; f < 6; ++f) records[i].faces[f] = glm::vec4(p.faces[size_t(f)], 0.0f);
        markers[i] = glm::vec4(p.position, 3.0f);  // markers.vert: a reflection probe
    }
    // Level m holds every probe's six faces, layer 6·probe + face, as the probe's chain holds them
    // (rows top to bottom, x fastest: the bake's faces are Vulkan's), in half floats.
    std::vector<vk::MipLevel> levels;
    if (cubemap) {
        for (int m = 0; m < s.mipCount; ++m) {
            const uint32_t side = uint32_t(cubeMipSize(s.faceSize, m));
            const size_t faceTexels = size_t(side) * side;
            vk::MipLevel level{side, side, std::vector<uint8_t>(n * 6 * faceTexels * 8)};
            tbb::parallel_for(size_t(0), n, [&](size_t i) {
                const glm::vec3* texels = s.probes[i].texels.data();
                for (int f = 0; f < 6; ++f) {
                    const glm::vec3* face = texels + s.texelOffset(m, f);
                    uint8_t* out = level.bytes.data() + (i * 6 + size_t(f)) * faceTexels * 8;
                    for (size_t t = 0; t < faceTexels; ++t) {
                        const uint64_t packed = glm::packHalf4x16(glm::vec4(face[t], 1.0f));
                        std::memcpy(out + 8 * t, &packed, 8);
                    }
                }
            });
            r->bytes += level.bytes.size();
            levels.push_back(std::move(level));
        }
    } else {
        levels.push_back(vk::MipLevel{1, 1, std::vector<uint8_t>(6 * 8, 0)});  // nothing reads it
    }
    r->bytes += records.size() * sizeof(records[0]);
    r->cubes = vk::Image::cubeArrayTexture(ctx, VK_FORMAT_R16G16B16A16_SFLOAT, cubemap ? uint32_t(n) : 1u, levels);
    r->records = vk::Buffer::deviceLocal(ctx, records.data(), records.size() * sizeof(records[0]),
                                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    r->markers = vk::Buffer::deviceLocal(ctx, markers.data(), markers.size() * sizeof(glm::vec4),
                                         VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    r->markerCount = uint32_t(n);
    r->grid.nx = s.dims[0];
    r->grid.nz = s.dims[1];
    r->grid.encoding = cubemap ? 1 : 0;
    r->grid.mipLevels = cubemap ? s.mipCount : 1;
    r->grid.origin = s.origin;
    r->grid.spacing = s.spacing;
    r->grid.cellSize = s.cellSize;
    r->grid.blendDistance = s.blendDistance;
    for (uint32_t i = 0; i < kRenderSlots; ++i)
        r->blocks.push_back(vk::Buffer::hostVisible(ctx, sizeof(blocks::ReflectionBlock), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT));
    g.graph.importBuffer(kReflectionRecords, r->records.handle(), true);
    g.graph.importBuffer(kReflectionMarkers, r->markers.handle(), true);
    return r;
}

blocks::ReflectionBlock packReflections(const ReflectionResources& r, const RenderSettings& s) {
    blocks::ReflectionBlock block = r.grid;
    block.strength = std::clamp(s.reflectionStrength, 0.0f, 1.0f);
    return block;
}

}  // namespace terralux::features
