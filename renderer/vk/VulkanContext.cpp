#include "vk/VulkanContext.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace terralux::vk {

void check(VkResult result, const char* what) {
    if (result != VK_SUCCESS)
        throw VulkanError(std::string("Vulkan: ") + what + " failed (VkResult " +
                          std::to_string(int(result)) + ")");
}

VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                   void* user) {
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        auto* self = static_cast<VulkanContext*>(user);
        const std::lock_guard lock(self->messagesMutex_);
        self->messages_.push_back(data && data->pMessage ? data->pMessage : "(no message)");
    }
    return VK_FALSE;
}

namespace {

// The WorkerCommands of this thread, if it holds one.
thread_local WorkerCommands* threadCommands = nullptr;

bool layerAvailable(const char* name) {
    uint32_t n = 0;
    vkEnumerateInstanceLayerProperties(&n, nullptr);
    std::vector<VkLayerProperties> layers(n);
    vkEnumerateInstanceLayerProperties(&n, layers.data());
    return std::any_of(layers.begin(), layers.end(),
                       [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

int typeRank(VkPhysicalDeviceType t) {
    switch (t) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
        default: return 4;
    }
}

}  // namespace

VulkanContext::VulkanContext(const ContextOptions& options) {
    try {
        create(options);
    } catch (...) {
        destroy();
        throw;
    }
}

void VulkanContext::create(const ContextOptions& options) {
    std::string choice = options.device;
    if (choice.empty())
        if (const char* env = std::getenv("TERRALUX_VK_DEVICE")) choice = env;
    bool validation = options.validation;
    if (const char* env = std::getenv("TERRALUX_VK_VALIDATION"); env && std::string(env) == "1")
        validation = true;
    const char* kValidation = "VK_LAYER_KHRONOS_validation";
    if (validation && !layerAvailable(kValidation))
        throw VulkanUnavailable("Vulkan validation was requested but " + std::string(kValidation) +
                                " is not installed (Debian: vulkan-validationlayers)");

    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "Terralux";
    app.apiVersion = VK_API_VERSION_1_1;
    std::vector<const char*> layers, extensions;
    for (const auto& e : options.instanceExtensions) extensions.push_back(e.c_str());
    if (validation) {
        layers.push_back(kValidation);
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    }
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    ici.enabledLayerCount = uint32_t(layers.size());
    ici.ppEnabledLayerNames = layers.data();
    ici.enabledExtensionCount = uint32_t(extensions.size());
    ici.ppEnabledExtensionNames = extensions.data();
    if (VkResult r = vkCreateInstance(&ici, nullptr, &instance_); r != VK_SUCCESS)
        throw VulkanUnavailable("no Vulkan instance (VkResult " + std::to_string(int(r)) +
                                "); install a Vulkan driver (Debian: mesa-vulkan-drivers)");

    if (validation) {
        VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
        mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
        mci.pfnUserCallback = onValidationMessage;
        mci.pUserData = this;
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
        if (create) check(create(instance_, &mci, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
    }

    uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance_, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(instance_, &count, devices.data());
    int bestRank = 99;
    std::string names;
    for (VkPhysicalDevice d : devices) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(d, &p);
        names += (names.empty() ? "" : ", ") + std::string(p.deviceName);
        uint32_t qn = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(d, &qn, nullptr);
        std::vector<VkQueueFamilyProperties> qf(qn);
        vkGetPhysicalDeviceQueueFamilyProperties(d, &qn, qf.data());
        int family = -1;
        for (uint32_t i = 0; i < qn; ++i)
            if (qf[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
                family = int(i);
                break;
            }
        if (family < 0) continue;
        const bool isCpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
        if (choice == "cpu" && !isCpu) continue;
        if (choice == "gpu" && isCpu) continue;
        if (!choice.empty() && choice != "cpu" && choice != "gpu" &&
            std::string(p.deviceName).find(choice) == std::string::npos)
            continue;
        const int rank = typeRank(p.deviceType);
        if (rank < bestRank) {
            bestRank = rank;
            physical_ = d;
            queueFamily_ = uint32_t(family);
            deviceName_ = p.deviceName;
            deviceType_ = p.deviceType;
            timestampBits_ = qf[size_t(family)].timestampValidBits;
            timestampPeriod_ = timestampBits_ > 0 ? double(p.limits.timestampPeriod) : 0.0;
            sampleCounts_ = uint32_t(p.limits.framebufferColorSampleCounts & p.limits.framebufferDepthSampleCounts);
        }
    }
    if (physical_ == VK_NULL_HANDLE) {
        const std::string found = names.empty() ? "none" : names;
        throw VulkanUnavailable("no Vulkan device with graphics" +
                                (choice.empty() ? std::string() : " matching '" + choice + "'") +
                                " (devices: " + found + ")");
    }
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = queueFamily_;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkPhysicalDeviceFeatures available{}, features{};
    vkGetPhysicalDeviceFeatures(physical_, &available);
    features.imageCubeArray = available.imageCubeArray;
    cubeArrays_ = available.imageCubeArray == VK_TRUE;
    features.depthClamp = available.depthClamp;
    depthClamp_ = available.depthClamp == VK_TRUE;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.pEnabledFeatures = &features;
    const char* swapchainExtension = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
    if (options.swapchain) {
        dci.enabledExtensionCount = 1;
        dci.ppEnabledExtensionNames = &swapchainExtension;
    }
    check(vkCreateDevice(physical_, &dci, nullptr, &device_), "vkCreateDevice");
    vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = queueFamily_;
    check(vkCreateCommandPool(device_, &pci, nullptr, &pool_), "vkCreateCommandPool");
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    check(vkCreateFence(device_, &fci, nullptr, &fence_), "vkCreateFence");
}

VulkanContext::~VulkanContext() { destroy(); }

void VulkanContext::destroy() {
    if (device_) {
        vkDeviceWaitIdle(device_);
        if (fence_) vkDestroyFence(device_, fence_, nullptr);
        if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
        vkDestroyDevice(device_, nullptr);
    }
    fence_ = VK_NULL_HANDLE;
    pool_ = VK_NULL_HANDLE;
    device_ = VK_NULL_HANDLE;
    if (messenger_) {
        auto destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroyMessenger) destroyMessenger(instance_, messenger_, nullptr);
    }
    messenger_ = VK_NULL_HANDLE;
    if (instance_) vkDestroyInstance(instance_, nullptr);
    instance_ = VK_NULL_HANDLE;
}

uint32_t VulkanContext::memoryType(uint32_t typeBits, VkMemoryPropertyFlags required) const {
    for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & required) == required)
            return i;
    throw VulkanError("Vulkan: no memory type with the required properties");
}

UniqueMemory VulkanContext::allocateMemory(const VkMemoryRequirements& requirements,
                                           VkMemoryPropertyFlags properties, const char* what) const {
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = requirements.size;
    ai.memoryTypeIndex = memoryType(requirements.memoryTypeBits, properties);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    check(vkAllocateMemory(device_, &ai, nullptr, &memory), (std::string("vkAllocateMemory (") + what + ")").c_str());
    return UniqueMemory(device_, memory);
}

UniqueCommandBuffer VulkanContext::allocateCommandBuffer() const {
    const VkCommandPool pool = threadCommands && &threadCommands->ctx_ == this ? threadCommands->pool_ : pool_;
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    check(vkAllocateCommandBuffers(device_, &ai, &cb), "vkAllocateCommandBuffers");
    return UniqueCommandBuffer(device_, pool, cb);
}

void VulkanContext::waitIdle() const {
    hostWaits_.fetch_add(1, std::memory_order_relaxed);
    const auto lock = lockQueue();
    check(vkQueueWaitIdle(queue_), "vkQueueWaitIdle");
}

WorkerCommands::WorkerCommands(const VulkanContext& ctx) : ctx_(ctx), outer_(threadCommands) {
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    pci.queueFamilyIndex = ctx.queueFamily_;
    check(vkCreateCommandPool(ctx.device_, &pci, nullptr, &pool_), "vkCreateCommandPool (worker)");
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    if (const VkResult r = vkCreateFence(ctx.device_, &fci, nullptr, &fence_); r != VK_SUCCESS) {
        vkDestroyCommandPool(ctx.device_, pool_, nullptr);
        check(r, "vkCreateFence (worker)");
    }
    threadCommands = this;
}

WorkerCommands::~WorkerCommands() {
    threadCommands = outer_;
    vkDestroyFence(ctx_.device_, fence_, nullptr);
    vkDestroyCommandPool(ctx_.device_, pool_, nullptr);
}

namespace {

// Records `record` into `cb` as a one-time command buffer and submits it to `ctx`'s queue,
// signalling `fence` (unsignalled) when the device has finished it.
void recordAndSubmit(const VulkanContext& ctx, VkCommandBuffer cb, VkFence fence,
                     const std::function<void(VkCommandBuffer)>& record) {
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cb, &bi), "vkBeginCommandBuffer");
    record(cb);
    check(vkEndCommandBuffer(cb), "vkEndCommandBuffer");
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    const auto lock = ctx.lockQueue();
    check(vkQueueSubmit(ctx.queue(), 1, &si, fence), "vkQueueSubmit");
}

}  // namespace

void VulkanContext::submitAndWait(const std::function<void(VkCommandBuffer)>& record) const {
    const UniqueCommandBuffer owned = allocateCommandBuffer();
    const VkFence fence = threadCommands && &threadCommands->ctx_ == this ? threadCommands->fence_ : fence_;
    check(vkResetFences(device_, 1, &fence), "vkResetFences");
    recordAndSubmit(*this, owned.get(), fence, record);
    hostWaits_.fetch_add(1, std::memory_order_relaxed);
    check(vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
}

Submission VulkanContext::submit(const std::function<void(VkCommandBuffer)>& record) const {
    Submission sub;
    sub.device_ = device_;
    sub.cb_ = allocateCommandBuffer();
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    check(vkCreateFence(device_, &fi, nullptr, &fence), "vkCreateFence");
    UniqueFence ownedFence(device_, fence);
    recordAndSubmit(*this, sub.cb_.get(), fence, record);
    sub.fence_ = std::move(ownedFence);  // only submitted work has a fence to wait for
    return sub;
}

bool Submission::done() const {
    if (!fence_) return true;
    const VkResult r = vkGetFenceStatus(device_, fence_.get());
    if (r == VK_NOT_READY) return false;
    check(r, "vkGetFenceStatus");
    return true;
}

void Submission::wait() const {
    if (!fence_) return;
    const VkFence f = fence_.get();
    check(vkWaitForFences(device_, 1, &f, VK_TRUE, UINT64_MAX), "vkWaitForFences");
}

}  // namespace terralux::vk
