#pragma once
// Presents rendered images in a window: the swapchain for a surface, and a blit of the offscreen
// colour image into the acquired swapchain image.

#include <vector>

#include "vk/VulkanContext.h"

namespace terralux::vk {

class Swapchain {
public:
    // Throws VulkanError when the device's queue cannot present to `surface`.
    Swapchain(const VulkanContext& ctx, VkSurfaceKHR surface);
    ~Swapchain();
    Swapchain(const Swapchain&) = delete;
    Swapchain& operator=(const Swapchain&) = delete;

    // Blits `source` (TRANSFER_SRC_OPTIMAL, `width` x `height`) to the window and presents it.
    // Recreates the swapchain when the window size changed; false when nothing could be shown
    // (a zero-sized window).
    bool present(VkImage source, uint32_t width, uint32_t height);

private:
    bool recreate();
    void destroy();
    const VulkanContext& ctx_;
    VkSurfaceKHR surface_;
    VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
    VkExtent2D extent_{0, 0};
    std::vector<VkImage> images_;
    VkSemaphore acquired_ = VK_NULL_HANDLE, blitted_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkCommandBuffer cb_ = VK_NULL_HANDLE;
};

}  // namespace terralux::vk
