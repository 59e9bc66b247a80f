#include "ReflectionProbeFile.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "LittleEndian.h"

namespace terralux {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& what) {
    throw ReflectionFileError(name + ": " + what);
}

std::string num(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

void storeVec3(std::vector<uint8_t>& out, const glm::vec3& v) {
    le::storeF32(out, v.x);
    le::storeF32(out, v.y);
    le::storeF32(out, v.z);
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool radiance(const glm::vec3& v) { return finite(v) && v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f; }

// The header's shape, checked the same way by the writer and the reader.
void checkShape(const std::string& name, uint32_t encoding, uint64_t count, uint64_t nx, uint64_t nz,
                uint32_t faceSize, uint32_t mips) {
    if (encoding > 1) fail(name, "encoding " + std::to_string(encoding) + ": must be 0 (faces) or 1 (cubemap)");
    if (nx < 1 || nz < 1 || nx * nz != count || count > uint64_t(kMaxReflectionProbes))
        fail(name, "grid " + std::to_string(nx) + " x " + std::to_string(nz) + " with " + std::to_string(count) +
                       " probes: must be >= 1 each, their product the probe count, at most " +
                       std::to_string(kMaxReflectionProbes));
    if (encoding == 0 && (faceSize != 0 || mips != 1))
        fail(name, "faces encoding with face size " + std::to_string(faceSize) + " and " + std::to_string(mips) +
                       " mips: must be 0 and 1");
    if (encoding == 1 && (faceSize < 8 || faceSize > 1024 || !std::has_single_bit(faceSize) ||
                          mips != uint32_t(cubeMipCount(int(faceSize)))))
        fail(name, "cubemap face size " + std::to_string(faceSize) + " with " + std::to_string(mips) +
                       " mips: must be a power of two in [8, 1024] with log2(size) - 1 mips (down to 4 x 4)");
}

}  // namespace

std::vector<uint8_t> encodeReflectionProbes(const ReflectionProbeSet& set) {
    const std::string name = "reflection probes";
    const uint32_t encoding = set.encoding == ReflectionEncoding::Cubemap ? 1 : 0;
    checkShape(name, encoding, set.probes.size(), uint64_t(std::max(set.dims[0], 0)),
               uint64_t(std::max(set.dims[1], 0)), uint32_t(std::max(set.faceSize, 0)), uint32_t(set.mipCount));
    const size_t texels = set.texelsPerProbe();
    std::vector<uint8_t> out;
    out.reserve(kRprobeHeaderBytes + set.probes.size() * (kRprobeProbeBytes + 12 * texels));
    le::storeU32(out, kRprobeMagic);
    le::storeU32(out, 1);
    le::storeU32(out, encoding);
    le::storeU32(out, uint32_t(set.probes.size()));
    le::storeU32(out, uint32_t(set.dims[0]));
    le::storeU32(out, uint32_t(set.dims[1]));
    le::storeU32(out, uint32_t(set.faceSize));
    le::storeU32(out, uint32_t(set.mipCount));
    for (float v : {set.origin.x, set.origin.y, set.spacing.x, set.spacing.y, set.cellSize.x, set.cellSize.y,
                    set.blendDistance, set.strength})
        le::storeF32(out, v);
    for (size_t i = 0; i < set.probes.size(); ++i) {
        const ReflectionProbe& p = set.probes[i];
        if (!finite(p.position) || !finite(p.halfExtent))
            fail(name, "probe " + std::to_string(i) + ": position and box must be finite");
        if (encoding == 1 && p.texels.size() != texels)
            fail(name, "probe " + std::to_string(i) + ": " + std::to_string(p.texels.size()) + " texels, the chain has " +
                           std::to_string(texels));
        le::storeU32(out, p.id);
        storeVec3(out, p.position);
        storeVec3(out, p.halfExtent);
        le::storeF32(out, set.strength);
        for (const auto& f : p.faces) storeVec3(out, f);
        if (encoding == 1)
            for (const auto& t : p.texels) storeVec3(out, t);
    }
    return out;
}

ReflectionProbeSet decodeReflectionProbes(std::span<const uint8_t> b, const std::string& name) {
    if (b.size() < kRprobeHeaderBytes)
        fail(name, std::to_string(b.size()) + " bytes: shorter than the " + std::to_string(kRprobeHeaderBytes) +
                       "-byte header");
    if (le::loadU32(b.data()) != kRprobeMagic) fail(name, "not a .rprobe file (bad magic)");
    const uint32_t version = le::loadU32(b.data() + 4);
    if (version != 1) fail(name, "version " + std::to_string(version) + ": this reader knows version 1");
    const uint32_t encoding = le::loadU32(b.data() + 8);
    const uint32_t count = le::loadU32(b.data() + 12);
    const uint32_t nx = le::loadU32(b.data() + 16), nz = le::loadU32(b.data() + 20);
    const uint32_t faceSize = le::loadU32(b.data() + 24), mips = le::loadU32(b.data() + 28);
    checkShape(name, encoding, count, nx, nz, faceSize, mips);

    ReflectionProbeSet set;
    set.encoding = encoding == 1 ? ReflectionEncoding::Cubemap : ReflectionEncoding::Faces;
    set.faceSize = int(faceSize);
    set.mipCount = int(mips);
    set.dims = {int(nx), int(nz)};
    auto f32 = [&](size_t at) { return le::loadF32(b.data() + at); };
    set.origin = {f32(32), f32(36)};
    set.spacing = {f32(40), f32(44)};
    set.cellSize = {f32(48), f32(52)};
    set.blendDistance = f32(56);
    set.strength = f32(60);
    for (float v : {set.origin.x, set.origin.y, set.spacing.x, set.spacing.y, set.cellSize.x, set.cellSize.y})
        if (!std::isfinite(v)) fail(name, "grid origin, spacing and cell size must be finite");
    if (!(set.blendDistance >= 0.0f) || !std::isfinite(set.blendDistance))
        fail(name, "blend distance " + num(set.blendDistance) + ": must be finite and >= 0");
    if (!(set.strength >= 0.0f && set.strength <= 1.0f))
        fail(name, "strength " + num(set.strength) + ": must be in [0, 1]");

    const size_t texels = set.texelsPerProbe();
    const uint64_t record = kRprobeProbeBytes + 12 * uint64_t(texels);
    const uint64_t expected = kRprobeHeaderBytes + uint64_t(count) * record;
    if (b.size() != expected)
        fail(name, std::to_string(b.size()) + " bytes: the header describes " + std::to_string(expected));
    set.probes.resize(count);
    for (uint32_t i = 0; i < count; ++i) {
        const size_t at = kRprobeHeaderBytes + size_t(i) * size_t(record);
        ReflectionProbe& p = set.probes[i];
        p.id = le::loadU32(b.data() + at);
        auto vec = [&](size_t o) { return glm::vec3(f32(o), f32(o + 4), f32(o + 8)); };
        p.position = vec(at + 4);
        p.halfExtent = vec(at + 16);
        const float intensity = f32(at + 28);
        const std::string where = "probe " + std::to_string(i) + ": ";
        if (!finite(p.position)) fail(name, where + "position must be finite");
        if (!finite(p.halfExtent) || p.halfExtent.x < 0 || p.halfExtent.y < 0 || p.halfExtent.z < 0)
            fail(name, where + "box half extents must be finite and >= 0");
        if (!(intensity >= 0.0f && intensity <= 1.0f))
            fail(name, where + "intensity " + num(intensity) + ": must be in [0, 1]");
        for (int f = 0; f < 6; ++f) {
            p.faces[size_t(f)] = vec(at + 32 + 12 * size_t(f));
            if (!radiance(p.faces[size_t(f)])) fail(name, where + "face " + std::to_string(f) + ": radiance must be finite and >= 0");
        }
        p.texels.resize(texels);
        for (size_t t = 0; t < texels; ++t) {
            p.texels[t] = vec(at + kRprobeProbeBytes + 12 * t);
            if (!radiance(p.texels[t])) fail(name, where + "texel " + std::to_string(t) + ": radiance must be finite and >= 0");
        }
    }
    return set;
}

ReflectionProbeSet readReflectionProbeFile(const std::filesystem::path& path) {
    const std::string name = path.string();
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) fail(name, "is a directory, not a .rprobe file");
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(name, "cannot open for reading");
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) fail(name, "cannot determine the file size (" + ec.message() + ")");
    // The largest file a valid header can describe: 256 probes of a 1024² chain.
    if (size > uint64_t(1) << 34) fail(name, std::to_string(size) + " bytes: too large for a .rprobe file");
    std::vector<uint8_t> bytes(size);
    in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size));
    if (uint64_t(in.gcount()) != size) fail(name, "read failed");
    return decodeReflectionProbes(bytes, name);
}

std::vector<int> simvxProbes(const std::vector<int>& subset, size_t count) {
    std::vector<int> chosen = subset;
    if (chosen.empty()) {
        for (int i = 0; i < int(std::min<size_t>(count, kSimvxMaxProbes)); ++i) chosen.push_back(i);
        return chosen;
    }
    const std::string at = "reflection_probes.simvx_subset";
    if (chosen.size() > size_t(kSimvxMaxProbes))
        throw PlacementError(at + ": " + std::to_string(chosen.size()) + " indices: at most " +
                             std::to_string(kSimvxMaxProbes));
    for (size_t k = 0; k < chosen.size(); ++k)
        if (chosen[k] < 0 || size_t(chosen[k]) >= count)
            throw PlacementError(at + "[" + std::to_string(k) + "] = " + std::to_string(chosen[k]) +
                                 ": must be a probe index below " + std::to_string(count) + ", the grid's probe count");
    std::sort(chosen.begin(), chosen.end());
    if (const auto d = std::adjacent_find(chosen.begin(), chosen.end()); d != chosen.end())
        throw PlacementError(at + ": index " + std::to_string(*d) + " appears twice: each probe at most once");
    return chosen;
}

ReflectionBoxRecords encodeBoxRecords(const ReflectionProbeSet& set, const std::vector<int>& subset) {
    ReflectionBoxRecords r;
    r.total = set.probes.size();
    const std::vector<int> chosen = simvxProbes(subset, r.total);
    auto record = [&](std::vector<uint8_t>& out, const ReflectionProbe& p, float layer) {
        storeVec3(out, p.position);
        le::storeF32(out, layer);
        storeVec3(out, p.halfExtent);
        le::storeF32(out, set.strength);
        le::storeF32(out, 1.0f);
        le::storeF32(out, set.blendDistance);
        le::storeF32(out, float(kSimvxSchedUpdateRequested));
        le::storeF32(out, 0.0f);
    };
    le::storeU32(r.desktop, uint32_t(chosen.size()));
    for (int k = 0; k < 3; ++k) le::storeU32(r.desktop, 0);
    for (size_t slot = 0; slot < chosen.size(); ++slot) {
        const ReflectionProbe& p = set.probes[size_t(chosen[slot])];
        record(r.desktop, p, float(slot * 6));
        le::storeU32(r.wire, p.id);
        record(r.wire, p, 0.0f);
        r.exported.push_back(p.id);
    }
    r.desktop.resize(kSimvxDesktopBytes, 0);
    return r;
}

}  // namespace terralux
