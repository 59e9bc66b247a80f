#include "vk/Handle.h"

namespace terralux::vk {

void destroyHandle(VkDevice d, VkBuffer h) { vkDestroyBuffer(d, h, nullptr); }
void destroyHandle(VkDevice d, VkDeviceMemory h) { vkFreeMemory(d, h, nullptr); }
void destroyHandle(VkDevice d, VkImage h) { vkDestroyImage(d, h, nullptr); }
void destroyHandle(VkDevice d, VkImageView h) { vkDestroyImageView(d, h, nullptr); }
void destroyHandle(VkDevice d, VkSampler h) { vkDestroySampler(d, h, nullptr); }
void destroyHandle(VkDevice d, VkRenderPass h) { vkDestroyRenderPass(d, h, nullptr); }
void destroyHandle(VkDevice d, VkFramebuffer h) { vkDestroyFramebuffer(d, h, nullptr); }
void destroyHandle(VkDevice d, VkShaderModule h) { vkDestroyShaderModule(d, h, nullptr); }
void destroyHandle(VkDevice d, VkPipeline h) { vkDestroyPipeline(d, h, nullptr); }
void destroyHandle(VkDevice d, VkPipelineLayout h) { vkDestroyPipelineLayout(d, h, nullptr); }
void destroyHandle(VkDevice d, VkDescriptorSetLayout h) { vkDestroyDescriptorSetLayout(d, h, nullptr); }
void destroyHandle(VkDevice d, VkDescriptorPool h) { vkDestroyDescriptorPool(d, h, nullptr); }
void destroyHandle(VkDevice d, VkFence h) { vkDestroyFence(d, h, nullptr); }
void destroyHandle(VkDevice d, VkSemaphore h) { vkDestroySemaphore(d, h, nullptr); }
void destroyHandle(VkDevice d, VkSwapchainKHR h) { vkDestroySwapchainKHR(d, h, nullptr); }
void destroyHandle(VkDevice d, VkQueryPool h) { vkDestroyQueryPool(d, h, nullptr); }
void freeCommandBuffer(VkDevice d, VkCommandPool pool, VkCommandBuffer cb) {
    vkFreeCommandBuffers(d, pool, 1, &cb);
}

}  // namespace terralux::vk
