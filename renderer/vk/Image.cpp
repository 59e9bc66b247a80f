#include "vk/Image.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "vk/Buffer.h"

namespace terralux::vk {

bool isDepthFormat(VkFormat f) {
    return f == VK_FORMAT_D16_UNORM || f == VK_FORMAT_D32_SFLOAT || f == VK_FORMAT_D24_UNORM_S8_UINT ||
           f == VK_FORMAT_D32_SFLOAT_S8_UINT || f == VK_FORMAT_X8_D24_UNORM_PACK32;
}

namespace {
UniqueImageView makeView(VkDevice device, VkImage image, VkImageViewType type, VkFormat format,
                         VkImageAspectFlags aspect, uint32_t firstLayer, uint32_t layers,
                         uint32_t mipLevels = 1) {
    VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vci.image = image;
    vci.viewType = type;
    vci.format = format;
    vci.subresourceRange = {aspect, 0, mipLevels, firstLayer, layers};
    VkImageView view = VK_NULL_HANDLE;
    check(vkCreateImageView(device, &vci, nullptr, &view), "vkCreateImageView");
    return UniqueImageView(device, view);
}
}  // namespace

Image::Image(const VulkanContext& ctx, const ImageDesc& desc) : desc_(desc) {
    if (desc_.shape == ImageShape::Cube) desc_.layers = 6;
    if (desc_.shape == ImageShape::Plane) desc_.layers = 1;
    aspect_ = isDepthFormat(desc_.format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    VkDevice device = ctx.device();
    VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ici.flags = desc_.shape == ImageShape::Cube || desc_.shape == ImageShape::CubeArray ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0;
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = desc_.format;
    ici.extent = {desc_.width, desc_.height, 1};
    ici.mipLevels = std::max(desc_.mipLevels, 1u);
    ici.arrayLayers = desc_.layers;
    ici.samples = VkSampleCountFlagBits(std::max(desc_.samples, 1u));
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = desc_.usage;
    ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkImage image = VK_NULL_HANDLE;
    check(vkCreateImage(device, &ici, nullptr, &image), "vkCreateImage");
    image_ = UniqueImage(device, image);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, image, &req);
    memory_ = ctx.allocateMemory(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "image");
    check(vkBindImageMemory(device, image, memory_.get(), 0), "vkBindImageMemory");

    const VkImageViewType type = desc_.shape == ImageShape::Cube        ? VK_IMAGE_VIEW_TYPE_CUBE
                                 : desc_.shape == ImageShape::CubeArray ? VK_IMAGE_VIEW_TYPE_CUBE_ARRAY
                                 : desc_.shape == ImageShape::Layers    ? VK_IMAGE_VIEW_TYPE_2D_ARRAY
                                                                        : VK_IMAGE_VIEW_TYPE_2D;
    view_ = makeView(device, image, type, desc_.format, aspect_, 0, desc_.layers, std::max(desc_.mipLevels, 1u));
    // Per-layer views are for framebuffers: a sampled array (reflection probes' faces, thousands of
    // layers) needs none.
    if (desc_.usage & (VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT))
        for (uint32_t l = 0; l < desc_.layers; ++l)
            layerViews_.push_back(makeView(device, image, VK_IMAGE_VIEW_TYPE_2D, desc_.format, aspect_, l, 1));
}

namespace {
constexpr VkImageUsageFlags kColorUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                          VK_IMAGE_USAGE_SAMPLED_BIT |
                                          VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
}

Image Image::colorTarget(const VulkanContext& ctx, uint32_t width, uint32_t height, VkFormat format) {
    return Image(ctx, {ImageShape::Plane, format, width, height, 1, kColorUsage});
}

Image Image::multisampledTarget(const VulkanContext& ctx, uint32_t width, uint32_t height, uint32_t samples,
                                VkFormat format) {
    const VkImageUsageFlags usage = isDepthFormat(format) ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT
                                                          : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    ImageDesc d{ImageShape::Plane, format, width, height, 1, usage};
    d.samples = samples;
    return Image(ctx, d);
}

Image Image::resolveTarget(const VulkanContext& ctx, uint32_t width, uint32_t height, VkFormat format) {
    return Image(ctx, {ImageShape::Plane, format, width, height, 1, kColorUsage | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
}

Image Image::layeredTarget(const VulkanContext& ctx, uint32_t width, uint32_t height, uint32_t layers,
                           VkFormat format) {
    return Image(ctx, {ImageShape::Layers, format, width, height, layers, kColorUsage});
}

Image Image::cubeTarget(const VulkanContext& ctx, uint32_t size, VkFormat format) {
    return Image(ctx, {ImageShape::Cube, format, size, size, 6, kColorUsage});
}

Image Image::depthTarget(const VulkanContext& ctx, uint32_t width, uint32_t height, uint32_t layers,
                         VkFormat format) {
    return Image(ctx, {layers > 1 ? ImageShape::Layers : ImageShape::Plane, format, width, height, layers,
                       VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                           VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
}

Image Image::depthLayers(const VulkanContext& ctx, uint32_t width, uint32_t height, uint32_t layers) {
    return Image(ctx, {ImageShape::Layers, kDepthFormat, width, height, layers,
                       VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                           VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
}

Image Image::texture(const VulkanContext& ctx, VkFormat format, const std::vector<MipLevel>& levels) {
    return upload(ctx, ImageShape::Plane, format, 1, levels);
}

Image Image::cubeArrayTexture(const VulkanContext& ctx, VkFormat format, uint32_t cubes,
                              const std::vector<MipLevel>& levels) {
    if (!ctx.cubeArrays()) throw std::runtime_error("the Vulkan device " + ctx.deviceName() + " samples no cube-map arrays");
    return upload(ctx, ImageShape::CubeArray, format, 6 * cubes, levels);
}

StagedTexture Image::stagedTexture(const VulkanContext& ctx, VkFormat format, const std::vector<MipLevel>& levels) {
    return stage(ctx, ImageShape::Plane, format, 1, levels);
}

StagedTexture Image::stage(const VulkanContext& ctx, ImageShape shape, VkFormat format, uint32_t layers,
                           const std::vector<MipLevel>& levels) {
    if (levels.empty()) throw std::invalid_argument("a texture needs at least one level");
    StagedTexture t;
    t.image = Image(ctx, {shape, format, levels[0].width, levels[0].height, layers,
                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, uint32_t(levels.size())});
    t.target = t.image.handle();
    t.layers = layers;
    size_t total = 0;
    for (const MipLevel& l : levels) total += (l.bytes.size() + 15) & ~size_t(15);
    t.staging = Buffer(ctx, std::max<size_t>(total, 16), VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                       VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    size_t offset = 0;
    for (uint32_t i = 0; i < levels.size(); ++i) {
        t.staging.write(levels[i].bytes.data(), levels[i].bytes.size(), offset);
        VkBufferImageCopy c{};
        c.bufferOffset = offset;
        c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, i, 0, layers};
        c.imageExtent = {levels[i].width, levels[i].height, 1};
        t.copies.push_back(c);
        offset += (levels[i].bytes.size() + 15) & ~size_t(15);
    }
    return t;
}

void StagedTexture::record(VkCommandBuffer cb) const {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = target;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, uint32_t(copies.size()), 0, layers};
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    vkCmdCopyBufferToImage(cb, staging.handle(), target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                           uint32_t(copies.size()), copies.data());
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    // Every later stage: a frame's uploads are recorded before any of its passes.
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
}

Image Image::upload(const VulkanContext& ctx, ImageShape shape, VkFormat format, uint32_t layers,
                    const std::vector<MipLevel>& levels) {
    StagedTexture t = stage(ctx, shape, format, layers, levels);
    ctx.submitAndWait([&](VkCommandBuffer cb) { t.record(cb); });
    return std::move(t.image);
}

}  // namespace terralux::vk
