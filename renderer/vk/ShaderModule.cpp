#include "vk/ShaderModule.h"

namespace terralux::vk {

UniqueShaderModule createShaderModule(const VulkanContext& ctx, std::span<const uint32_t> spirv) {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = spirv.size_bytes();
    ci.pCode = spirv.data();
    VkShaderModule m = VK_NULL_HANDLE;
    check(vkCreateShaderModule(ctx.device(), &ci, nullptr, &m), "vkCreateShaderModule");
    return UniqueShaderModule(ctx.device(), m);
}

}  // namespace terralux::vk
