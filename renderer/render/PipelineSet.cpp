#include "render/PipelineSet.h"

#include <chrono>

#include "system/BackgroundPriority.h"

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

VkPipeline PipelineSet::buildHere(int key, const Build& build) {
    if (!land(key)) {
        built_[key] = build();
        ++builtHere_;
    }
    return built_[key].get();
}

void PipelineSet::start(int key, Build build) {
    building_.emplace(key, std::async(std::launch::async, [build = std::move(build)] {
                          const BackgroundThread background;
                          return build();
                      }));
}

bool PipelineSet::poll(int key) {
    auto it = building_.find(key);
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
