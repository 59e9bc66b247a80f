// Reflection `.rprobe` reader, writer and the simvx box records. The input is a subset prefix
// for encodeBoxRecords (one byte n, n % 16 signed index bytes) followed by the .rprobe bytes.
// Any .rprobe either decodes or throws ReflectionFileError; a decoded set encodes, and that
// encoding is a fixed point of decode∘encode; the box records of a decoded set are 400 bytes on
// the desktop and 52 per exported probe on the wire, or a PlacementError for a bad subset.

#include <cstdint>
#include <cstring>
#include <vector>

#include "FuzzSupport.h"
#include "ReflectionProbeFile.h"
#include "bake/ProbePlacement.h"

using namespace terralux;

namespace {

uint32_t u32(const uint8_t* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    const size_t n = data[0] % 16;
    if (size < 1 + n) return 0;
    std::vector<int> subset;
    for (size_t k = 0; k < n; ++k) subset.push_back(int(int8_t(data[1 + k])));
    const std::span<const uint8_t> bytes(data + 1 + n, size - 1 - n);

    ReflectionProbeSet set;
    try {
        set = decodeReflectionProbes(bytes, "fuzz.rprobe");
    } catch (const ReflectionFileError&) {
        return 0;
    }
    FUZZ_CHECK(set.probes.size() == size_t(set.dims[0]) * size_t(set.dims[1]));

    // Per-probe intensity is not kept (the writer stores the set's strength), so the first
    // encoding may differ from the input; after that decode and encode must agree exactly.
    const std::vector<uint8_t> first = encodeReflectionProbes(set);
    FUZZ_CHECK(first.size() == bytes.size());
    const ReflectionProbeSet again = decodeReflectionProbes(first, "re-encoded");
    FUZZ_CHECK(encodeReflectionProbes(again) == first);

    ReflectionBoxRecords r;
    try {
        r = encodeBoxRecords(set, subset);
    } catch (const PlacementError&) {
        FUZZ_CHECK(!subset.empty());
        return 0;
    }
    const size_t expected = subset.empty() ? std::min<size_t>(set.probes.size(), kSimvxMaxProbes)
                                           : subset.size();
    FUZZ_CHECK(r.total == set.probes.size());
    FUZZ_CHECK(r.exported.size() == expected);
    FUZZ_CHECK(r.desktop.size() == kSimvxDesktopBytes && kSimvxDesktopBytes == 400);
    FUZZ_CHECK(r.wire.size() == 52 * r.exported.size());
    FUZZ_CHECK(u32(r.desktop.data()) == r.exported.size());
    for (size_t slot = 0; slot < r.exported.size(); ++slot) {
        const uint8_t* wire = r.wire.data() + 52 * slot;
        const uint8_t* desk = r.desktop.data() + 16 + 48 * slot;
        FUZZ_CHECK(u32(wire) == r.exported[slot]);
        // Same record but for the layer slot (w of the first vec4: slot·6 on the desktop, 0 on
        // the wire).
        FUZZ_CHECK(std::memcmp(wire + 4, desk, 12) == 0);
        FUZZ_CHECK(std::memcmp(wire + 4 + 16, desk + 16, 32) == 0);
        float layer;
        std::memcpy(&layer, desk + 12, 4);
        FUZZ_CHECK(layer == float(slot * 6));
    }
    for (size_t at = 16 + 48 * r.exported.size(); at < r.desktop.size(); ++at)
        FUZZ_CHECK(r.desktop[at] == 0);
    return 0;
}
