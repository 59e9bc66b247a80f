#pragma once
// Pipelines of one kind by key, built on first use. A CPU device compiles a pipeline when it is
// created (the terrain's takes 120-170 ms on lavapipe, and its pipeline cache saves nothing), so
// a viewport that must not wait asks whether a frame's pipelines are there (`ready`) and, where
// one is not, has it built on a worker and draws the frame once it has landed; every other frame
// builds what it lacks where it is recorded (`get`), waiting for a build under way rather than
// starting a second. Creating a pipeline needs no lock on the device (Vulkan's threading rules),
// and a build reads only handles and shader words that outlive it.

#include <functional>
#include <future>
#include <map>

#include "vk/Handle.h"

namespace terralux {

class PipelineSet {
public:
    using Build = std::function<vk::UniquePipeline()>;

    PipelineSet() = default;
    PipelineSet(const PipelineSet&) = delete;
    PipelineSet& operator=(const PipelineSet&) = delete;
    ~PipelineSet();  // waits for the builds under way: they read handles the owner frees next

    // key's pipeline, built here when missing (after the build under way, if one is). `make`
    // returns the Build; it is called only when one is needed, so a frame that finds its
    // pipelines built assembles no pipeline description.
    template <class Make>
    VkPipeline get(int key, Make&& make) {
        if (auto it = built_.find(key); it != built_.end()) return it->second.get();
        return buildHere(key, make());
    }
    // Whether key's pipeline is built; when not, its build starts on a worker (once).
    template <class Make>
    bool ready(int key, Make&& make) {
        if (built_.count(key)) return true;
        if (!building_.count(key)) {
            start(key, make());
            return false;
        }
        return poll(key);
    }
    // Some build under way has not finished.
    bool building() const;
    // Pipelines built on the recording thread, and on workers, since the set was made.
    size_t builtHere() const { return builtHere_; }
    size_t builtOnWorkers() const { return builtOnWorkers_; }

private:
    bool land(int key);  // a finished build's pipeline taken in (its error thrown here)
    VkPipeline buildHere(int key, const Build& build);  // lands the build under way, else builds
    void start(int key, Build build);                   // on a worker
    bool poll(int key);                                 // whether the build under way landed

    std::map<int, vk::UniquePipeline> built_;
    std::map<int, std::future<vk::UniquePipeline>> building_;
    size_t builtHere_ = 0, builtOnWorkers_ = 0;
};

}  // namespace terralux
