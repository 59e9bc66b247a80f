#include "vk/Image.h"

namespace terralux::vk {

bool isDepthFormat(VkFormat f) {
    return f == VK_FORMAT_D16_UNORM || f == VK_FORMAT_D32_SFLOAT || f == VK_FORMAT_D24_UNORM_S8_UINT ||
           f == VK_FORMAT_D32_SFLOAT_S8_UINT || f == VK_FORMAT_X8_D24_UNORM_PACK32;
}

namespace {
UniqueImageView makeView(VkDevice device, VkImage image, VkImageViewType type, VkFormat format,
                         VkImageAspectFlags aspect, uint32_t firstLayer, uint32_t layers) {
    VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vci.image = image;
    vci.viewType = type;
    vci.format = format;
    vci.subresourceRange = {aspect, 0, 1, firstLayer, layers};
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
    ici.flags = desc_.shape == ImageShape::Cube ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0;
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = desc_.format;
    ici.extent = {desc_.width, desc_.height, 1};
    ici.mipLevels = 1;
    ici.arrayLayers = desc_.layers;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
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

    const VkImageViewType type = desc_.shape == ImageShape::Cube     ? VK_IMAGE_VIEW_TYPE_CUBE
                                 : desc_.shape == ImageShape::Layers ? VK_IMAGE_VIEW_TYPE_2D_ARRAY
                                                                     : VK_IMAGE_VIEW_TYPE_2D;
    view_ = makeView(device, image, type, desc_.format, aspect_, 0, desc_.layers);
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

}  // namespace terralux::vk
