#pragma once
// A frame as an ordered list of passes. Each pass declares the named resources it reads and
// writes and how (vertex input, storage, attachment, transfer, ...); executing the list records
// the passes in order with the barriers and layout changes those declarations imply, and nothing
// else. Resource state carries over from frame to frame (one queue, submission order), so the
// first pass of a frame waits for the last use of the frame before it. A subsystem that adds no
// pass adds no barrier and binds nothing.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace terralux {

enum class Access {
    VertexAttributeRead,   // a vertex buffer
    IndexRead,             // an index buffer
    ComputeStorageRead,
    ComputeStorageWrite,
    ComputeStorageReadWrite,  // reads what it or an earlier pass wrote, and writes
    FragmentSampledRead,   // a sampled image in a fragment shader
    FragmentStorageRead,   // a storage buffer a fragment shader reads
    ColorAttachmentClear,  // the pass clears it: earlier contents are discarded
    ColorAttachmentDraw,   // the pass draws on top of what is there
    DepthAttachmentClear,
    DepthAttachmentDraw,
    TransferRead,
    TransferWrite,
    HostRead,              // read by the CPU after the submission finished
    Present,               // handed to the presentation engine
};

const char* accessName(Access access);

struct ResourceUse {
    std::string resource;
    Access access;
};

// What a pass is: its name, what it touches and what it binds (descriptor bindings, vertex and
// index buffers), for the frame's description and its tests.
struct PassInfo {
    std::string name;
    std::vector<ResourceUse> uses;
    std::vector<std::string> bindings;
};

class FrameGraph {
public:
    // Resources by name; their state persists across frames for as long as the handle stays the
    // same (a new handle starts with undefined contents; a parked one resumes where it was).
    // `waitStage`: the stage a semaphore wait guards (a freshly acquired swapchain image), 0 for
    // none.
    // `uploaded`: filled by a transfer (a staging copy) that the first use must wait for.
    void importBuffer(const std::string& name, VkBuffer buffer, bool uploaded = false);
    void importImage(const std::string& name, VkImage image, VkImageAspectFlags aspect,
                     uint32_t layers = 1, VkPipelineStageFlags waitStage = 0);
    // Keeps the state of the handle `name` holds now, to resume when that handle is imported
    // under the name again: a renderer that alternates between two targets (a small frame and a
    // large one) keeps the barriers of both right without waiting for either.
    void park(const std::string& name);
    // Forgets a resource and every handle parked under its name (they are about to be destroyed).
    void forget(const std::string& name);

    // Drops passes added but never executed (a frame whose recording failed).
    void beginFrame() {
        passes_.clear();
        finals_.clear();
    }
    void addPass(PassInfo info, std::function<void(VkCommandBuffer)> record);
    // A use after the last pass: the host reading a buffer back, the presentation engine taking
    // an image.
    void addFinalUse(ResourceUse use);
    // Records every pass added since the last execute, with its barriers, then clears the list.
    // With a timestamp query pool of at least passes + 1 queries (`capacity`), it also resets
    // them and writes query 0 before the first pass's barriers and query k + 1 once pass k's
    // commands are done, so pass k took the ticks between queries k and k + 1 (its barriers
    // included). Returns the queries written: 0 without a pool, or when it is too small.
    uint32_t execute(VkCommandBuffer cb, VkQueryPool timestamps = VK_NULL_HANDLE, uint32_t capacity = 0);
    // The passes of the last executed frame, in order.
    const std::vector<PassInfo>& lastFrame() const { return last_; }

private:
    struct Resource {
        bool image = false;
        VkBuffer buffer = VK_NULL_HANDLE;
        VkImage imageHandle = VK_NULL_HANDLE;
        VkImageAspectFlags aspect = 0;
        uint32_t layers = 1;
        VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
        VkPipelineStageFlags stages = 0;   // stages of the accesses since the last barrier
        VkAccessFlags writes = 0;          // unflushed writes
        bool readSinceWrite = false;
        // The last write, and the stages and accesses a barrier has made it visible to since: a
        // read from another stage (a buffer a compute pass read and a fragment shader reads next)
        // needs its own dependency on that write.
        VkPipelineStageFlags writeStages = 0;
        VkAccessFlags writeAccess = 0;
        VkPipelineStageFlags visibleStages = 0;
        VkAccessFlags visibleAccess = 0;
    };
    struct Pass {
        PassInfo info;
        std::function<void(VkCommandBuffer)> record;
    };
    void barrier(VkCommandBuffer cb, const ResourceUse& use);
    template <class Same>
    bool resume(const std::string& name, Resource& r, Same same, bool resumable);

    std::map<std::string, Resource> resources_;
    std::map<std::string, std::vector<Resource>> parked_;  // by name: the handles it held before
    std::vector<Pass> passes_;
    std::vector<ResourceUse> finals_;
    std::vector<PassInfo> last_;
};

}  // namespace terralux
