#include "vk/Swapchain.h"

#include <algorithm>

namespace terralux::vk {

namespace {
UniqueSemaphore makeSemaphore(VkDevice device) {
    VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore s = VK_NULL_HANDLE;
    check(vkCreateSemaphore(device, &sci, nullptr, &s), "vkCreateSemaphore");
    return UniqueSemaphore(device, s);
}
}  // namespace

Swapchain::Swapchain(const VulkanContext& ctx, VkSurfaceKHR surface) : ctx_(ctx), surface_(surface) {
    VkBool32 supported = VK_FALSE;
    check(vkGetPhysicalDeviceSurfaceSupportKHR(ctx_.physicalDevice(), ctx_.queueFamily(), surface_, &supported),
          "vkGetPhysicalDeviceSurfaceSupportKHR");
    if (!supported) throw VulkanError("Vulkan: " + ctx_.deviceName() + " cannot present to this window");
    for (Slot& s : slots_) {
        s.acquired = makeSemaphore(ctx_.device());
        VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        fci.flags = VK_FENCE_CREATE_SIGNALED_BIT;  // a slot starts free
        VkFence f = VK_NULL_HANDLE;
        check(vkCreateFence(ctx_.device(), &fci, nullptr, &f), "vkCreateFence");
        s.done = UniqueFence(ctx_.device(), f);
        s.cb = ctx_.allocateCommandBuffer();
    }
}

Swapchain::~Swapchain() {
    waitIdle();
    destroySwapchain();
}

void Swapchain::waitIdle() {
    for (Slot& s : slots_) {
        VkFence f = s.done.get();
        if (f) vkWaitForFences(ctx_.device(), 1, &f, VK_TRUE, UINT64_MAX);
    }
}

void Swapchain::destroySwapchain() {
    presentable_.clear();
    swapchain_.reset();
    images_.clear();
}

bool Swapchain::recreate() {
    // Every frame that used the old images must be done with them.
    waitIdle();
    VkSurfaceCapabilitiesKHR caps;
    check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx_.physicalDevice(), surface_, &caps),
          "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    if (caps.currentExtent.width == 0 || caps.currentExtent.height == 0) return false;
    uint32_t n = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(ctx_.physicalDevice(), surface_, &n, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(n);
    vkGetPhysicalDeviceSurfaceFormatsKHR(ctx_.physicalDevice(), surface_, &n, formats.data());
    // The rendered image is already display-encoded: a UNORM target keeps its values.
    format_ = formats.empty() ? VK_FORMAT_B8G8R8A8_UNORM : formats[0].format;
    VkColorSpaceKHR space = formats.empty() ? VK_COLOR_SPACE_SRGB_NONLINEAR_KHR : formats[0].colorSpace;
    for (const auto& f : formats)
        if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
            format_ = f.format;
            space = f.colorSpace;
            break;
        }
    extent_ = caps.currentExtent;
    VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    ci.surface = surface_;
    ci.minImageCount = std::max(kFramesInFlight + 1, caps.minImageCount);
    if (caps.maxImageCount) ci.minImageCount = std::min(ci.minImageCount, caps.maxImageCount);
    ci.imageFormat = format_;
    ci.imageColorSpace = space;
    ci.imageExtent = extent_;
    ci.imageArrayLayers = 1;
    ci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    ci.preTransform = caps.currentTransform;
    ci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    if (!(caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR))
        ci.compositeAlpha = VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR;
    ci.presentMode = VK_PRESENT_MODE_FIFO_KHR;
    ci.clipped = VK_TRUE;
    ci.oldSwapchain = swapchain_.get();
    VkSwapchainKHR created = VK_NULL_HANDLE;
    check(vkCreateSwapchainKHR(ctx_.device(), &ci, nullptr, &created), "vkCreateSwapchainKHR");
    destroySwapchain();
    swapchain_ = UniqueSwapchain(ctx_.device(), created);
    vkGetSwapchainImagesKHR(ctx_.device(), created, &n, nullptr);
    images_.resize(n);
    vkGetSwapchainImagesKHR(ctx_.device(), created, &n, images_.data());
    for (uint32_t i = 0; i < n; ++i) presentable_.push_back(makeSemaphore(ctx_.device()));
    return true;
}

void Swapchain::waitForHeld() {
    if (!pending_) return;
    VkFence held = slots_[pending_->slot].done.get();
    check(vkWaitForFences(ctx_.device(), 1, &held, VK_TRUE, UINT64_MAX), "vkWaitForFences (held frame)");
}

std::optional<SwapchainFrame> Swapchain::begin() {
    waitForHeld();
    presentIfDone();
    Slot& slot = slots_[next_];
    VkFence fence = slot.done.get();
    check(vkWaitForFences(ctx_.device(), 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences (frame slot)");

    VkSurfaceCapabilitiesKHR caps;
    check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx_.physicalDevice(), surface_, &caps),
          "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    if (!swapchain_ || caps.currentExtent.width != extent_.width || caps.currentExtent.height != extent_.height)
        if (!recreate()) return std::nullopt;
    uint32_t index = 0;
    VkResult r = vkAcquireNextImageKHR(ctx_.device(), swapchain_.get(), UINT64_MAX, slot.acquired.get(),
                                       VK_NULL_HANDLE, &index);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) {
        if (!recreate()) return std::nullopt;
        r = vkAcquireNextImageKHR(ctx_.device(), swapchain_.get(), UINT64_MAX, slot.acquired.get(),
                                  VK_NULL_HANDLE, &index);
    }
    if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR) check(r, "vkAcquireNextImageKHR");

    check(vkResetCommandBuffer(slot.cb.get(), 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(slot.cb.get(), &bi), "vkBeginCommandBuffer");
    SwapchainFrame f;
    f.cb = slot.cb.get();
    f.slot = next_;
    f.imageIndex = index;
    f.image = images_[index];
    f.extent = extent_;
    return f;
}

void Swapchain::submit(const SwapchainFrame& f) {
    Slot& slot = slots_[f.slot];
    next_ = (f.slot + 1) % kFramesInFlight;
    check(vkEndCommandBuffer(f.cb), "vkEndCommandBuffer");
    const VkPipelineStageFlags wait = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSemaphore acquired = slot.acquired.get(), presentable = presentable_[f.imageIndex].get();
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.waitSemaphoreCount = 1;
    si.pWaitSemaphores = &acquired;
    si.pWaitDstStageMask = &wait;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &f.cb;
    si.signalSemaphoreCount = 1;
    si.pSignalSemaphores = &presentable;
    VkFence fence = slot.done.get();
    check(vkResetFences(ctx_.device(), 1, &fence), "vkResetFences");
    {
        const auto lock = ctx_.lockQueue();
        check(vkQueueSubmit(ctx_.queue(), 1, &si, fence), "vkQueueSubmit (frame)");
    }
    if (holdsFrames_) pending_ = Held{f.slot, f.imageIndex};
    else present(f.imageIndex);
}

bool Swapchain::presentIfDone() {
    if (!pending_) return true;
    const VkResult status = vkGetFenceStatus(ctx_.device(), slots_[pending_->slot].done.get());
    if (status == VK_NOT_READY) return false;
    check(status, "vkGetFenceStatus (held frame)");
    const uint32_t imageIndex = pending_->imageIndex;
    pending_.reset();
    present(imageIndex);
    return true;
}

void Swapchain::present(uint32_t imageIndex) {
    VkSemaphore presentable = presentable_[imageIndex].get();
    VkSwapchainKHR sc = swapchain_.get();
    VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    pi.waitSemaphoreCount = 1;
    pi.pWaitSemaphores = &presentable;
    pi.swapchainCount = 1;
    pi.pSwapchains = &sc;
    pi.pImageIndices = &imageIndex;
    VkResult r;
    {
        const auto lock = ctx_.lockQueue();
        r = vkQueuePresentKHR(ctx_.queue(), &pi);
    }
    // The next begin() recreates it for the new size.
    if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) extent_ = {0, 0};
    else check(r, "vkQueuePresentKHR");
}

}  // namespace terralux::vk
