#include "render/FrameGraph.h"

#include <algorithm>
#include <stdexcept>

namespace terralux {

namespace {

struct AccessInfo {
    VkPipelineStageFlags stage;
    VkAccessFlags access;
    VkImageLayout layout;  // images only
    bool write;
    bool discard;          // earlier contents are not needed
};

AccessInfo infoOf(Access a) {
    switch (a) {
        case Access::VertexAttributeRead:
            return {VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT,
                    VK_IMAGE_LAYOUT_UNDEFINED, false, false};
        case Access::IndexRead:
            return {VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, VK_ACCESS_INDEX_READ_BIT,
                    VK_IMAGE_LAYOUT_UNDEFINED, false, false};
        case Access::ComputeStorageRead:
            return {VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT,
                    VK_IMAGE_LAYOUT_GENERAL, false, false};
        case Access::ComputeStorageWrite:
            return {VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                    VK_IMAGE_LAYOUT_GENERAL, true, false};
        case Access::ComputeStorageReadWrite:
            return {VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                    VK_IMAGE_LAYOUT_GENERAL, true, false};
        case Access::FragmentSampledRead:
            return {VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT,
                    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, false, false};
        case Access::FragmentStorageRead:
            return {VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT, VK_IMAGE_LAYOUT_GENERAL,
                    false, false};
        case Access::ColorAttachmentClear:
            return {VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                    VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, true, true};
        case Access::ColorAttachmentDraw:
            return {VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                    VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                    VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, true, false};
        case Access::DepthAttachmentClear:
            return {VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                    VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                    VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, true, true};
        case Access::DepthAttachmentDraw:
            return {VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                    VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                    VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, true, false};
        case Access::TransferRead:
            return {VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT,
                    VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, false, false};
        case Access::TransferWrite:
            return {VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                    VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, true, true};
        case Access::HostRead:
            return {VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT, VK_IMAGE_LAYOUT_GENERAL, false, false};
        case Access::Present:
            return {VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, false, false};
    }
    throw std::logic_error("unknown access");
}

}  // namespace

const char* accessName(Access a) {
    switch (a) {
        case Access::VertexAttributeRead: return "vertex-attribute-read";
        case Access::IndexRead: return "index-read";
        case Access::ComputeStorageRead: return "compute-read";
        case Access::ComputeStorageWrite: return "compute-write";
        case Access::ComputeStorageReadWrite: return "compute-read-write";
        case Access::FragmentSampledRead: return "fragment-sampled-read";
        case Access::FragmentStorageRead: return "fragment-storage-read";
        case Access::ColorAttachmentClear: return "color-clear";
        case Access::ColorAttachmentDraw: return "color-draw";
        case Access::DepthAttachmentClear: return "depth-clear";
        case Access::DepthAttachmentDraw: return "depth-draw";
        case Access::TransferRead: return "transfer-read";
        case Access::TransferWrite: return "transfer-write";
        case Access::HostRead: return "host-read";
        case Access::Present: return "present";
    }
    return "?";
}

// Takes back into `r` the state parked under `name` for the handle `same` picks, where
// `resumable` (else that parked state is dropped): whether it did.
template <class Same>
bool FrameGraph::resume(const std::string& name, Resource& r, Same same, bool resumable) {
    const auto list = parked_.find(name);
    if (list == parked_.end()) return false;
    const auto found = std::find_if(list->second.begin(), list->second.end(), same);
    if (found == list->second.end()) return false;
    if (resumable) r = *found;
    list->second.erase(found);
    return resumable;
}

void FrameGraph::importBuffer(const std::string& name, VkBuffer buffer, bool uploaded) {
    Resource& r = resources_[name];
    if (r.buffer == buffer && !r.image) return;
    if (resume(name, r, [&](const Resource& p) { return !p.image && p.buffer == buffer; }, !uploaded)) return;
    r = Resource{};
    r.buffer = buffer;
    if (uploaded) {
        r.stages = r.writeStages = VK_PIPELINE_STAGE_TRANSFER_BIT;
        r.writes = r.writeAccess = VK_ACCESS_TRANSFER_WRITE_BIT;
    }
}

void FrameGraph::importImage(const std::string& name, VkImage image, VkImageAspectFlags aspect,
                             uint32_t layers, VkPipelineStageFlags waitStage) {
    Resource& r = resources_[name];
    if (r.image && r.imageHandle == image && waitStage == 0) return;
    if (resume(name, r, [&](const Resource& p) { return p.image && p.imageHandle == image; }, waitStage == 0)) return;
    r = Resource{};
    r.image = true;
    r.imageHandle = image;
    r.aspect = aspect;
    r.layers = layers;
    r.stages = waitStage;
}

void FrameGraph::park(const std::string& name) {
    const auto r = resources_.find(name);
    if (r == resources_.end()) return;
    std::vector<Resource>& list = parked_[name];
    std::erase_if(list, [&](const Resource& p) {
        return p.image == r->second.image && p.buffer == r->second.buffer && p.imageHandle == r->second.imageHandle;
    });
    list.push_back(r->second);
}

void FrameGraph::forget(const std::string& name) {
    resources_.erase(name);
    parked_.erase(name);
}

void FrameGraph::addPass(PassInfo info, std::function<void(VkCommandBuffer)> record) {
    for (const auto& u : info.uses)
        if (!resources_.count(u.resource))
            throw std::logic_error("frame graph: pass " + info.name + " uses unknown resource " + u.resource);
    passes_.push_back({std::move(info), std::move(record)});
}

void FrameGraph::addFinalUse(ResourceUse use) {
    if (!resources_.count(use.resource))
        throw std::logic_error("frame graph: final use of unknown resource " + use.resource);
    finals_.push_back(std::move(use));
}

void FrameGraph::barrier(VkCommandBuffer cb, const ResourceUse& use) {
    Resource& r = resources_.at(use.resource);
    const AccessInfo a = infoOf(use.access);
    const bool layoutChange = r.image && r.layout != a.layout;
    // Read after write, write after write, write after read; a read after a read of the same
    // layout needs nothing unless it reads in a stage or way the last write was not yet made
    // visible to.
    const bool unseen = !a.write && r.writeAccess != 0 &&
                        ((a.stage & ~r.visibleStages) != 0 || (a.access & ~r.visibleAccess) != 0);
    const bool hazard = r.writes != 0 || (a.write && r.readSinceWrite) || layoutChange || unseen;
    if (hazard) {
        const VkPipelineStageFlags stages = r.stages | (unseen ? r.writeStages : 0);
        const VkPipelineStageFlags src = stages ? stages : VkPipelineStageFlags(VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
        // A host read waits for the submission's fence; the barrier makes the writes available.
        if (r.image) {
            VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
            b.srcAccessMask = r.writes | (unseen ? r.writeAccess : 0);
            b.dstAccessMask = a.access;
            b.oldLayout = a.discard ? VK_IMAGE_LAYOUT_UNDEFINED : r.layout;
            b.newLayout = a.layout;
            b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            b.image = r.imageHandle;
            b.subresourceRange = {r.aspect, 0, 1, 0, r.layers};
            vkCmdPipelineBarrier(cb, src, a.stage, 0, 0, nullptr, 0, nullptr, 1, &b);
        } else {
            VkBufferMemoryBarrier b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
            b.srcAccessMask = r.writes | (unseen ? r.writeAccess : 0);
            b.dstAccessMask = a.access;
            b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            b.buffer = r.buffer;
            b.size = VK_WHOLE_SIZE;
            vkCmdPipelineBarrier(cb, src, a.stage, 0, 0, nullptr, 1, &b, 0, nullptr);
        }
        r.stages = 0;
        r.writes = 0;
        r.readSinceWrite = false;
    }
    if (r.image) r.layout = a.layout;
    r.stages |= a.stage;
    if (a.write) {
        const VkAccessFlags written =
            a.access & (VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                        VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
        r.writes |= written;
        r.writeStages = a.stage;
        r.writeAccess = written;
        r.visibleStages = 0;
        r.visibleAccess = 0;
    } else {
        r.readSinceWrite = true;
        if (hazard) {
            r.visibleStages |= a.stage;
            r.visibleAccess |= a.access;
        }
    }
}

uint32_t FrameGraph::execute(VkCommandBuffer cb, VkQueryPool timestamps, uint32_t capacity) {
    last_.clear();
    const uint32_t queries = timestamps && passes_.size() + 1 <= capacity ? uint32_t(passes_.size()) + 1 : 0;
    if (queries > 0) {
        vkCmdResetQueryPool(cb, timestamps, 0, queries);
        // The start once everything submitted before has finished, so no earlier work is counted.
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, timestamps, 0);
    }
    uint32_t query = 1;
    for (Pass& p : passes_) {
        for (const ResourceUse& u : p.info.uses) barrier(cb, u);
        if (p.record) p.record(cb);
        // Bottom of the pipe: when every command recorded so far has completed.
        if (queries > 0) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps, query++);
        last_.push_back(std::move(p.info));
    }
    passes_.clear();
    for (const ResourceUse& u : finals_) barrier(cb, u);
    finals_.clear();
    return queries;
}

}  // namespace terralux
