// `<volume>.probes.json` sidecar reader. The .shprobe it is checked against is built from the
// document's own probe_count, grid_dims and digest where they are plausible, so that the fuzzer
// gets past the staleness checks to the arrays behind them. Any text either decodes or throws
// ProbeDiagnosticsError; what decodes is written again and read back, and that text is a fixed
// point of the writer and reader.

#include <cstdint>
#include <cstdlib>
#include <string>

#include <nlohmann/json.hpp>

#include "FuzzSupport.h"
#include "ProbeDiagnosticsFile.h"
#include "ShProbeFile.h"

using namespace terralux;
using json = nlohmann::json;

namespace {

// A grid with `count` probes in a dims box: each cell points at a probe while there are probes.
ShProbeGrid gridFor(uint32_t count, glm::uvec3 dims) {
    ShProbeGrid g;
    g.dims = dims;
    g.probes.resize(count);
    g.occupancy.assign(size_t(dims.x) * dims.y * dims.z, -1);
    for (size_t i = 0; i < g.occupancy.size() && i < count; ++i) g.occupancy[i] = int32_t(i);
    return g;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    ShProbeGrid grid = gridFor(4, {2, 1, 2});
    uint64_t digest = shProbeDigest(encodeShProbe(grid));
    const json j = json::parse(text, nullptr, false);
    if (j.is_object()) {
        const json count = j.value("probe_count", json());
        const json dims = j.value("grid_dims", json());
        if (count.is_number_unsigned() && count.get<uint64_t>() <= 4096 && dims.is_array() &&
            dims.size() == 3 && dims[0].is_number_unsigned() && dims[1].is_number_unsigned() &&
            dims[2].is_number_unsigned()) {
            const uint64_t x = dims[0].get<uint64_t>(), y = dims[1].get<uint64_t>(), z = dims[2].get<uint64_t>();
            if (x >= 1 && y >= 1 && z >= 1 && x <= 4096 && y <= 4096 && z <= 4096 && x * y * z <= 65536)
                grid = gridFor(uint32_t(count.get<uint64_t>()), {uint32_t(x), uint32_t(y), uint32_t(z)});
        }
        const json hex = j.value("shprobe_fnv1a64", json());
        if (hex.is_string() && hex.get<std::string>().size() == 16)
            digest = std::strtoull(hex.get<std::string>().c_str(), nullptr, 16);
    }

    ProbeDiagnostics d;
    try {
        d = decodeProbeDiagnostics(text, "fuzz.probes.json", grid, digest);
    } catch (const ProbeDiagnosticsError&) {
        return 0;
    }
    FUZZ_CHECK(d.positions.size() == grid.probes.size());
    FUZZ_CHECK(d.moved.size() == grid.probes.size());
    FUZZ_CHECK(d.errorMap.error.size() == size_t(d.errorMap.nx) * d.errorMap.nz);

    // The writer's output must be readable, and reading it back must not change it.
    const uint64_t own = shProbeDigest(encodeShProbe(grid));
    const std::string first = encodeProbeDiagnostics(d, "fuzz", grid);
    const ProbeDiagnostics back = decodeProbeDiagnostics(first, "re-encoded", grid, own);
    FUZZ_CHECK(encodeProbeDiagnostics(back, "fuzz", grid) == first);
    return 0;
}
