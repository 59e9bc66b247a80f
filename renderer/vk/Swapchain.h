#pragma once
// Presents rendered frames in a window with up to kFramesInFlight frames queued: each frame slot
// has its own command buffer, fence and acquire semaphore, so the CPU records the next frame
// while the GPU draws the last and waits only when every slot is still busy.

#include <cstdint>
#include <optional>
#include <vector>

#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

inline constexpr uint32_t kFramesInFlight = 2;

// One frame being recorded: the slot's command buffer (begun) and the acquired image.
struct SwapchainFrame {
    VkCommandBuffer cb = VK_NULL_HANDLE;
    uint32_t slot = 0;        // 0 .. kFramesInFlight-1: which per-frame resources to use
    uint32_t imageIndex = 0;
    VkImage image = VK_NULL_HANDLE;
    VkExtent2D extent{0, 0};
};

class Swapchain {
public:
    // Throws VulkanError when the device's queue cannot present to `surface`.
    Swapchain(const VulkanContext& ctx, VkSurfaceKHR surface);
    ~Swapchain();
    Swapchain(const Swapchain&) = delete;
    Swapchain& operator=(const Swapchain&) = delete;

    // Presents the frame submitted last if it is still held (waiting for it), waits until the
    // next slot is free (its frame of kFramesInFlight ago has finished), acquires an image
    // (recreating the swapchain when the window size changed) and begins the slot's command
    // buffer. nullopt when nothing can be shown (a zero-sized window). The image is in an
    // undefined layout; the frame leaves it in PRESENT_SRC_KHR, having waited for the acquire at
    // the transfer stage.
    std::optional<SwapchainFrame> begin();
    // Ends the command buffer and submits it, then queues the image for presentation, or, when
    // the swapchain holds frames, keeps it until presentIfDone() finds the frame finished. Some
    // presentation engines (Mesa's software WSI under X11, what a CPU device such as lavapipe
    // presents through) wait inside vkQueuePresentKHR for the frame's commands: presenting only
    // finished frames keeps that wait off the caller's thread. A GPU's engine queues the image
    // and returns, and presenting at once keeps its next frame recorded while it draws. No wait.
    void submit(const SwapchainFrame& frame);
    void setHoldsFrames(bool holds) { holdsFrames_ = holds; }
    // Whether a submitted frame is held for presentation.
    bool pending() const { return pending_.has_value(); }
    // Presents the held frame if its commands have finished. True when nothing is held any more.
    bool presentIfDone();
    // Waits until the held frame's commands have finished (none held: returns at once).
    void waitForHeld();
    // Waits for every slot (before resources the frames use are destroyed).
    void waitIdle();

private:
    bool recreate();
    void destroySwapchain();
    void present(uint32_t imageIndex);
    struct Held {
        uint32_t slot = 0, imageIndex = 0;
    };
    std::optional<Held> pending_;
    bool holdsFrames_ = true;
    struct Slot {
        UniqueCommandBuffer cb;
        UniqueFence done;
        UniqueSemaphore acquired;
    };
    const VulkanContext& ctx_;
    VkSurfaceKHR surface_;
    UniqueSwapchain swapchain_;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
    VkExtent2D extent_{0, 0};
    std::vector<VkImage> images_;
    std::vector<UniqueSemaphore> presentable_;  // per image: its frame's commands finished
    Slot slots_[kFramesInFlight];
    uint32_t next_ = 0;
};

}  // namespace terralux::vk
