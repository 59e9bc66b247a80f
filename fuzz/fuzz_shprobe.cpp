// `.shprobe` reader: any bytes either decode or throw ShProbeError; a decoded grid encodes again
// to the same bytes (the w lanes and record padding aside, which the reader ignores) and
// decodes to the same grid.

#include <cstdint>
#include <cstring>
#include <vector>

#include "FuzzSupport.h"
#include "ShProbeFile.h"

using namespace terralux;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::span<const uint8_t> bytes(data, size);
    ShProbeGrid grid;
    try {
        grid = decodeShProbe(bytes, "fuzz.shprobe");
    } catch (const ShProbeError&) {
        return 0;
    }
    FUZZ_CHECK(grid.occupancy.size() == size_t(grid.dims.x) * grid.dims.y * grid.dims.z);
    FUZZ_CHECK(grid.fileSize() == size);
    for (int32_t o : grid.occupancy) FUZZ_CHECK(o >= -1 && (o < 0 || size_t(o) < grid.probes.size()));

    const std::vector<uint8_t> again = encodeShProbe(grid);  // a decoded grid must encode
    FUZZ_CHECK(again.size() == size);
    std::vector<uint8_t> canonical(data, data + size);
    constexpr size_t kHeader = 48, kRecord = 160;
    for (size_t p = 0; p < grid.probes.size(); ++p) {
        uint8_t* rec = canonical.data() + kHeader + p * kRecord;
        for (size_t k = 0; k < 9; ++k) std::memset(rec + 16 * k + 12, 0, 4);
        std::memset(rec + 152, 0, 8);
    }
    FUZZ_CHECK(again == canonical);
    FUZZ_CHECK(decodeShProbe(again, "re-encoded") == grid);
    return 0;
}
