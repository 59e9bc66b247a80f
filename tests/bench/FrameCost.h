#pragma once
// What a benchmark's frames cost on the device and the host (TerrainRenderer::lastFrameTimings).

#include <algorithm>
#include <map>
#include <string>

#include <benchmark/benchmark.h>

#include "render/TerrainRenderer.h"

namespace terralux {

// GPU time (timestamps) and host recording time summed over a benchmark's frames, reported beside
// the wall time as gpu_ms and host_ms, and each pass's GPU time as gpu_<pass>_ms, its mean over
// the frames that ran it (gpu_ms and the passes absent where the device writes no timestamps);
// and the terrain's level of detail: its mean triangles (lod_triangles) and the largest screen
// error of a frame's levels (lod_px), and the detail patches' vertices (MeshLod.h) where the
// DEM is past the mesh's budget (lod_detail_vertices, their mean).
struct FrameCost {
    double gpu = 0.0, host = 0.0, triangles = 0.0, lodPixels = 0.0, detailVertices = 0.0;
    int frames = 0, timed = 0;
    std::map<std::string, std::pair<double, int>> passes;
    void add(const TerrainRenderer& r) {
        const FrameTimings& t = r.lastFrameTimings();
        host += t.recordMilliseconds;
        triangles += double(r.lastLod().triangles);
        detailVertices += double(r.lastLod().detailVertices);
        lodPixels = std::max(lodPixels, r.lastLod().screenErrorPixels);
        ++frames;
        if (t.gpuTimed()) gpu += t.gpuMilliseconds, ++timed;
        for (const auto& p : t.passes) {
            auto& [ms, n] = passes[p.name];
            ms += p.gpuMilliseconds;
            ++n;
        }
    }
    void report(benchmark::State& state) const {
        if (frames > 0) state.counters["host_ms"] = host / frames;
        if (frames > 0) state.counters["lod_triangles"] = triangles / frames;
        if (frames > 0) state.counters["lod_px"] = lodPixels;
        if (frames > 0 && detailVertices > 0.0) state.counters["lod_detail_vertices"] = detailVertices / frames;
        if (timed > 0) state.counters["gpu_ms"] = gpu / timed;
        for (const auto& [name, sum] : passes) state.counters["gpu_" + name + "_ms"] = sum.first / sum.second;
    }
};

}  // namespace terralux
