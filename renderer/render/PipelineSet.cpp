#include "render/PipelineSet.h"

#include <chrono>

namespace terralux {

PipelineSet::~PipelineSet() {
    for (auto& [key, build] : building_)
        if (build.valid()) build.wait();
}

bool PipelineSet::land(int key) {
    auto it = building_.find(key);
    if (it == building_.end()) return false;
    std::future<vk::UniquePipeline> build = std::move(it->second);
    building_.erase(it);
    built_[key] = build.get();
    ++builtOnWorkers_;
    return true;
}

VkPipeline PipelineSet::get(int key, const Build& build) {
    if (auto it = built_.find(key); it != built_.end()) return it->second.get();
    if (!land(key)) {
        built_[key] = build();
        ++builtHere_;
    }
    return built_[key].get();
}

bool PipelineSet::ready(int key, Build build) {
    if (built_.count(key)) return true;
    auto it = building_.find(key);
    if (it == building_.end()) {
        building_.emplace(key, std::async(std::launch::async, std::move(build)));
        return false;
    }
    if (it->second.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
    land(key);
    return true;
}

bool PipelineSet::building() const {
    for (const auto& [key, build] : building_)
        if (build.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return true;
    return false;
}

}  // namespace terralux
