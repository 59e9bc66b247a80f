#pragma once
// A SPIR-V module, alive while pipelines are made from it.

#include <cstdint>
#include <span>

#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

UniqueShaderModule createShaderModule(const VulkanContext& ctx, std::span<const uint32_t> spirv);

}  // namespace terralux::vk
