#pragma once
// Device images with their memory and views: sampled colour render targets (2D, layered 2D
// arrays, cubes) and depth targets that shaders can sample (shadow maps). Every target is also a
// transfer source, so any of them can be read back or presented.

#include <cstdint>
#include <vector>

#include "vk/Buffer.h"
#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

inline constexpr VkFormat kColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

enum class ImageShape { Plane, Layers, Cube, CubeArray };

struct ImageDesc {
    ImageShape shape = ImageShape::Plane;
    VkFormat format = kColorFormat;
    uint32_t width = 1, height = 1;
    uint32_t layers = 1;  // Layers: the array size; Cube: 6; CubeArray: 6 × cubes
    VkImageUsageFlags usage = 0;
    uint32_t mipLevels = 1;
    uint32_t samples = 1;  // > 1: a multisampled Plane, drawn into and resolved, never sampled
};

// One mip level's texels, tightly packed rows (level 0 first).
struct MipLevel {
    uint32_t width = 1, height = 1;
    std::vector<uint8_t> bytes;
};

struct StagedTexture;

class Image {
public:
    Image() = default;
    Image(const VulkanContext& ctx, const ImageDesc& desc);

    // A colour target shaders can sample, read back or blit from.
    static Image colorTarget(const VulkanContext& ctx, uint32_t width, uint32_t height,
                             VkFormat format = kColorFormat);
    // A multisampled colour or depth target of `samples` (a count the device supports for both,
    // VulkanContext::framebufferSampleCounts): drawn into, then resolved (a colour target's
    // transfer source), never sampled.
    static Image multisampledTarget(const VulkanContext& ctx, uint32_t width, uint32_t height, uint32_t samples,
                                    VkFormat format);
    // A colour target a multisampled one can also be resolved into (a transfer destination).
    static Image resolveTarget(const VulkanContext& ctx, uint32_t width, uint32_t height, VkFormat format = kColorFormat);
    // A 2D array colour target, one layer per slice (cascades, volume slices).
    static Image layeredTarget(const VulkanContext& ctx, uint32_t width, uint32_t height,
                               uint32_t layers, VkFormat format = kColorFormat);
    // A cube colour target, one layer per face (reflection probes).
    static Image cubeTarget(const VulkanContext& ctx, uint32_t size, VkFormat format = kColorFormat);
    // A depth target shaders can sample, e.g. with a depth-compare sampler (shadow maps); `layers`
    // > 1 makes a 2D array (one layer per cascade).
    static Image depthTarget(const VulkanContext& ctx, uint32_t width, uint32_t height,
                             uint32_t layers = 1, VkFormat format = kDepthFormat);

    // A depth 2D array shaders sample as one (a 2D-array view even for one layer): shadow cascades.
    static Image depthLayers(const VulkanContext& ctx, uint32_t width, uint32_t height, uint32_t layers);

    // A sampled 2D texture holding `levels` (a full or partial mip chain), uploaded through a
    // staging buffer and left in the shader-read layout.
    static Image texture(const VulkanContext& ctx, VkFormat format, const std::vector<MipLevel>& levels);
    // The same for an array of `cubes` cube maps (layer 6·cube + face, faces in Vulkan's order),
    // sampled as one cube-map array with the hardware's seamless filtering across face edges:
    // each level's bytes hold its layers one after another. Needs VulkanContext::cubeArrays().
    static Image cubeArrayTexture(const VulkanContext& ctx, VkFormat format, uint32_t cubes,
                                  const std::vector<MipLevel>& levels);
    // A texture as texture() makes it, its levels still in the staging buffer: the caller records
    // their copy into a command buffer it submits anyway (a frame's), rather than waiting for a
    // submission of its own behind every frame already queued.
    static StagedTexture stagedTexture(const VulkanContext& ctx, VkFormat format, const std::vector<MipLevel>& levels);

    VkImage handle() const { return image_.get(); }
    // The whole image as shaders see it: 2D, 2D array or cube.
    VkImageView view() const { return view_.get(); }
    // One layer as a 2D view, for a framebuffer attachment (attachment images only).
    VkImageView layerView(uint32_t layer) const { return layerViews_[layer].get(); }
    const ImageDesc& desc() const { return desc_; }
    uint32_t width() const { return desc_.width; }
    uint32_t height() const { return desc_.height; }
    uint32_t mipLevels() const { return desc_.mipLevels; }
    VkImageAspectFlags aspect() const { return aspect_; }

private:
    static Image upload(const VulkanContext& ctx, ImageShape shape, VkFormat format, uint32_t layers,
                        const std::vector<MipLevel>& levels);
    static StagedTexture stage(const VulkanContext& ctx, ImageShape shape, VkFormat format, uint32_t layers,
                               const std::vector<MipLevel>& levels);
    ImageDesc desc_;
    VkImageAspectFlags aspect_ = VK_IMAGE_ASPECT_COLOR_BIT;
    // Declared in destruction order: views, image, then its memory.
    UniqueMemory memory_;
    UniqueImage image_;
    UniqueImageView view_;
    std::vector<UniqueImageView> layerViews_;
};

// A texture and the staging buffer its levels wait in (Image::stagedTexture).
struct StagedTexture {
    Image image;            // the caller may take it: record() needs only `target`
    VkImage target = VK_NULL_HANDLE;
    Buffer staging;
    std::vector<VkBufferImageCopy> copies;
    uint32_t layers = 1;
    // Copies the levels in and leaves the image in the shader-read layout for every stage after
    // it; the staging buffer must outlive the command buffer's execution.
    void record(VkCommandBuffer cb) const;
};

bool isDepthFormat(VkFormat format);

}  // namespace terralux::vk
