#include "ShProbeFile.h"
#include "FaultInjection.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <ios>
#include <limits>
#include <optional>
#include <random>
#include <system_error>

#include "LittleEndian.h"

#include <unistd.h>

namespace terralux {

namespace {

namespace fs = std::filesystem;

constexpr uint32_t kMagic = 0x52485053u;  // bytes 53 50 48 52 on disk
constexpr uint32_t kVersion = 1;
constexpr uint64_t kHeaderBytes = 48;
constexpr uint64_t kRecordBytes = 160;
constexpr uint64_t kOccupancyBytes = 4;
constexpr size_t kCoeffs = 9;
constexpr char kAxis[3] = {'X', 'Y', 'Z'};
constexpr char kChannel[3] = {'R', 'G', 'B'};

[[noreturn]] void fail(const std::string& name, const std::string& what) {
    throw ShProbeError(name + ": " + what);
}

// Shortest round-trip text, so a message shows the exact offending value (nan, inf, -1, 0.5).
std::string num(float v) {
    char buf[48];
    const auto res = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, res.ptr);
}

std::string num(uint64_t v) {
    return std::to_string(v);
}

std::string hex32(uint32_t v) {
    static constexpr char kDigits[] = "0123456789abcdef";
    std::string s = "0x";
    for (int shift = 28; shift >= 0; shift -= 4)
        s += kDigits[(v >> shift) & 0xFu];
    return s;
}

std::optional<uint64_t> checkedMul(uint64_t a, uint64_t b) {
    if (b != 0 && a > std::numeric_limits<uint64_t>::max() / b)
        return std::nullopt;
    return a * b;
}

std::optional<uint64_t> checkedAdd(uint64_t a, uint64_t b) {
    if (a > std::numeric_limits<uint64_t>::max() - b)
        return std::nullopt;
    return a + b;
}

std::optional<uint64_t> cellCount(const glm::uvec3& dims) {
    const auto xy = checkedMul(dims.x, dims.y);
    return xy ? checkedMul(*xy, dims.z) : std::nullopt;
}

// 48 + 160*count + 4*cells, or nullopt if any step leaves 64 bits.
std::optional<uint64_t> expectedSize(uint64_t count, const glm::uvec3& dims) {
    const auto cells = cellCount(dims);
    if (!cells)
        return std::nullopt;
    const auto occ = checkedMul(*cells, kOccupancyBytes);
    const auto recs = checkedMul(count, kRecordBytes);
    if (!occ || !recs)
        return std::nullopt;
    const auto partial = checkedAdd(kHeaderBytes, *recs);
    return partial ? checkedAdd(*partial, *occ) : std::nullopt;
}

std::string dimsText(const glm::uvec3& d) {
    return num(uint64_t{d.x}) + " x " + num(uint64_t{d.y}) + " x " + num(uint64_t{d.z});
}

// Field rules shared by the encoder (checking a grid) and the decoder (checking the file).

void checkDims(const std::string& name, const glm::uvec3& dims) {
    for (int a = 0; a < 3; ++a) {
        if (dims[a] == 0)
            fail(name, std::string("grid dim ") + kAxis[a] + " = 0 must be >= 1");
    }
}

void checkScalars(const std::string& name, const glm::vec3& origin, float spacing,
                  float defaultScale, float defaultAmbient) {
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(origin[a])) {
            fail(name, std::string("grid origin ") + kAxis[a] + " = " + num(origin[a]) +
                           " must be finite");
        }
    }
    if (!std::isfinite(spacing) || !(spacing > 0.0f)) {
        fail(name, "grid spacing = " + num(spacing) + " must be finite and > 0");
    }
    if (!std::isfinite(defaultScale)) {
        fail(name, "default SH scale = " + num(defaultScale) + " must be finite");
    }
    if (!std::isfinite(defaultAmbient)) {
        fail(name, "default ambient = " + num(defaultAmbient) + " must be finite");
    }
}

void checkProbe(const std::string& name, size_t index, const ShProbeRecord& rec) {
    const std::string probe = "probe " + std::to_string(index);
    for (size_t k = 0; k < kCoeffs; ++k) {
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(rec.coeffs[k][c])) {
                fail(name, probe + " coefficient " + std::to_string(k) + " (" + kChannel[c] +
                               ") is not finite (" + num(rec.coeffs[k][c]) + ")");
            }
        }
    }
    if (!std::isfinite(rec.scale))
        fail(name, probe + " scale = " + num(rec.scale) + " must be finite");
    if (!std::isfinite(rec.ambient)) {
        fail(name, probe + " ambient = " + num(rec.ambient) + " must be finite");
    }
}

void checkOccupancy(const std::string& name, size_t cell, int32_t value, uint64_t count) {
    if (value < -1 || (value >= 0 && static_cast<uint64_t>(value) >= count)) {
        fail(name, "occupancy[" + std::to_string(cell) + "] = " + std::to_string(value) +
                       " is outside [-1, " + num(count) + ")");
    }
}

using le::loadF32;
using le::loadI32;
using le::loadU32;
using le::storeF32;
using le::storeI32;
using le::storeU32;

struct Header {
    uint32_t count = 0;
    glm::uvec3 dims{1, 1, 1};
    glm::vec3 origin{0};
    float spacing = 1.0f;
    float defaultScale = 1.0f;
    float defaultAmbient = 0.1f;
};

// Validates the header against the total file size before anything is allocated, so a forged
// header with huge counts in a tiny file is rejected cheaply. `head` holds >= 48 bytes whenever
// fileBytes >= 48.
Header parseHeader(std::span<const uint8_t> head, uint64_t fileBytes, const std::string& name) {
    if (fileBytes < kHeaderBytes || head.size() < kHeaderBytes) {
        fail(name, "file is " + num(fileBytes) + " bytes, shorter than the 48-byte header");
    }
    const uint8_t* p = head.data();
    const uint32_t magic = loadU32(p);
    if (magic != kMagic)
        fail(name, "magic " + hex32(magic) + ", expected 0x52485053 ('SPHR' on disk)");
    const uint32_t version = loadU32(p + 4);
    if (version != kVersion) {
        fail(name, "version = " + num(uint64_t{version}) + " is not supported, expected 1");
    }

    Header h;
    h.count = loadU32(p + 8);
    h.dims = {loadU32(p + 12), loadU32(p + 16), loadU32(p + 20)};
    h.origin = {loadF32(p + 24), loadF32(p + 28), loadF32(p + 32)};
    h.spacing = loadF32(p + 36);
    h.defaultScale = loadF32(p + 40);
    h.defaultAmbient = loadF32(p + 44);

    checkDims(name, h.dims);
    const auto expected = expectedSize(h.count, h.dims);
    if (!expected) {
        fail(name, "grid dims " + dimsText(h.dims) + " with probe count " + num(uint64_t{h.count}) +
                       " need a file size beyond 64 bits; file is " + num(fileBytes) + " bytes");
    }
    if (*expected != fileBytes) {
        fail(name, "file is " + num(fileBytes) + " bytes, header needs 48 + 160*" +
                       num(uint64_t{h.count}) + " + 4*" + num(*cellCount(h.dims)) + " = " +
                       num(*expected));
    }
    checkScalars(name, h.origin, h.spacing, h.defaultScale, h.defaultAmbient);
    return h;
}

std::vector<uint8_t> encodeNamed(const ShProbeGrid& grid, const std::string& name) {
    checkDims(name, grid.dims);
    checkScalars(name, grid.origin, grid.spacing, grid.defaultScale, grid.defaultAmbient);
    if (grid.probes.size() > std::numeric_limits<uint32_t>::max()) {
        fail(name, "probe count = " + num(uint64_t{grid.probes.size()}) +
                       " does not fit the uint32 count field");
    }
    const auto cells = cellCount(grid.dims);
    const auto total = expectedSize(grid.probes.size(), grid.dims);
    if (!cells || !total || *total > std::numeric_limits<size_t>::max()) {
        fail(name, "grid dims " + dimsText(grid.dims) + " are too large to encode");
    }
    if (grid.occupancy.size() != *cells) {
        fail(name, "occupancy has " + num(uint64_t{grid.occupancy.size()}) +
                       " entries, grid dims " + dimsText(grid.dims) + " need " + num(*cells));
    }
    for (size_t i = 0; i < grid.probes.size(); ++i)
        checkProbe(name, i, grid.probes[i]);
    for (size_t i = 0; i < grid.occupancy.size(); ++i) {
        checkOccupancy(name, i, grid.occupancy[i], grid.probes.size());
    }

    std::vector<uint8_t> out;
    out.reserve(static_cast<size_t>(*total));
    storeU32(out, kMagic);
    storeU32(out, kVersion);
    storeU32(out, static_cast<uint32_t>(grid.probes.size()));
    for (int a = 0; a < 3; ++a)
        storeU32(out, grid.dims[a]);
    for (int a = 0; a < 3; ++a)
        storeF32(out, grid.origin[a]);
    storeF32(out, grid.spacing);
    storeF32(out, grid.defaultScale);
    storeF32(out, grid.defaultAmbient);
    for (const ShProbeRecord& rec : grid.probes) {
        for (const glm::vec3& c : rec.coeffs) {
            storeF32(out, c.r);
            storeF32(out, c.g);
            storeF32(out, c.b);
            storeF32(out, 0.0f);
        }
        storeF32(out, rec.scale);
        storeF32(out, rec.ambient);
        storeU32(out, 0);
        storeU32(out, 0);
    }
    for (int32_t v : grid.occupancy)
        storeI32(out, v);
    return out;
}

std::string errnoText(int err) {
    return std::generic_category().message(err);
}

// Unique per call even if random_device is deterministic on some platform. The pid tells a later
// bake whether the writer of a leftover temporary is still alive.
std::string tempSuffix() {
    static std::atomic<uint64_t> counter{0};
    std::random_device rd;
    const uint64_t r =
        (uint64_t{rd()} << 32) ^ rd() ^ (counter.fetch_add(1) * 0x9E3779B97F4A7C15ull);
    static constexpr char kDigits[] = "0123456789abcdef";
    std::string s = ".tmp-" + std::to_string(::getpid()) + "-";
    for (int shift = 60; shift >= 0; shift -= 4)
        s += kDigits[(r >> shift) & 0xFu];
    return s;
}

// Removes the temporary on every exit path that did not complete the rename.
struct TempFileGuard {
    fs::path path;
    bool armed = true;
    ~TempFileGuard() {
        if (armed) {
            std::error_code ec;
            fs::remove(path, ec);
        }
    }
};

}  // namespace

size_t ShProbeGrid::cellIndex(uint32_t x, uint32_t y, uint32_t z) const {
    const size_t dx = dims.x;
    const size_t dy = dims.y;
    return size_t{x} + size_t{y} * dx + size_t{z} * dx * dy;
}

uint64_t ShProbeGrid::fileSize() const {
    return expectedSize(probes.size(), dims).value_or(std::numeric_limits<uint64_t>::max());
}

std::vector<uint8_t> encodeShProbe(const ShProbeGrid& grid) {
    return encodeNamed(grid, "shprobe grid");
}

ShProbeGrid decodeShProbe(std::span<const uint8_t> bytes, const std::string& name) {
    const Header h = parseHeader(bytes, bytes.size(), name);

    ShProbeGrid grid;
    grid.dims = h.dims;
    grid.origin = h.origin;
    grid.spacing = h.spacing;
    grid.defaultScale = h.defaultScale;
    grid.defaultAmbient = h.defaultAmbient;

    // The size check above guarantees every offset below is in range. The .w lanes and the
    // trailing padding are written as zero but not checked, leaving room for later versions.
    const uint8_t* p = bytes.data() + kHeaderBytes;
    grid.probes.resize(h.count);
    for (uint32_t i = 0; i < h.count; ++i, p += kRecordBytes) {
        ShProbeRecord& rec = grid.probes[i];
        for (size_t k = 0; k < kCoeffs; ++k) {
            rec.coeffs[k] = {loadF32(p + 16 * k), loadF32(p + 16 * k + 4), loadF32(p + 16 * k + 8)};
        }
        rec.scale = loadF32(p + 144);
        rec.ambient = loadF32(p + 148);
        checkProbe(name, i, rec);
    }

    const size_t cells = static_cast<size_t>(*cellCount(h.dims));
    grid.occupancy.resize(cells);
    for (size_t i = 0; i < cells; ++i, p += kOccupancyBytes) {
        grid.occupancy[i] = loadI32(p);
        checkOccupancy(name, i, grid.occupancy[i], h.count);
    }
    return grid;
}

void writeShProbeFile(const std::filesystem::path& path, const ShProbeGrid& grid) {
    const std::string name = path.string();
    // Encode first: an invalid grid must fail before the filesystem is touched.
    const std::vector<uint8_t> bytes = encodeNamed(grid, name);

    fs::path tmp = path;
    tmp += tempSuffix();
    TempFileGuard guard{tmp};
    if (injectedFailure("write", tmp))
        fail(name, "cannot create temporary file " + tmp.string() + ": " + errnoText(EIO));
    std::FILE* out = std::fopen(tmp.c_str(), "wb");
    if (!out)
        fail(name, "cannot create temporary file " + tmp.string() + ": " + errnoText(errno));
    errno = 0;
    const bool written = std::fwrite(bytes.data(), 1, bytes.size(), out) == bytes.size();
    const int writeErr = errno ? errno : EIO;
    errno = 0;
    // Synced before the rename, so a crash leaves the old file or the whole new one.
    const bool synced = written && std::fflush(out) == 0 && !injectedFailure("fsync", tmp) &&
                        ::fsync(::fileno(out)) == 0;
    const int syncErr = errno ? errno : EIO;
    const bool closed = std::fclose(out) == 0;
    if (!written)
        fail(name, "cannot write temporary file " + tmp.string() + ": " + errnoText(writeErr));
    if (!synced)
        fail(name, "cannot write temporary file " + tmp.string() + ": " + errnoText(syncErr));
    if (!closed)
        fail(name, "cannot close temporary file " + tmp.string() + ": " + errnoText(errno));
    std::error_code ec;
    if (injectedFailure("rename", path))
        ec = std::make_error_code(std::errc::io_error);
    else
        fs::rename(tmp, path, ec);
    if (ec)
        fail(name, "cannot rename " + tmp.string() + " over the target: " + ec.message());
    guard.armed = false;
}

ShProbeGrid readShProbeFile(const std::filesystem::path& path, std::vector<uint8_t>* bytesOut) {
    const std::string name = path.string();
    std::error_code ec;
    if (fs::is_directory(path, ec))
        fail(name, "is a directory, not a .shprobe file");

    std::ifstream in(path, std::ios::binary);
    if (!in)
        fail(name, "cannot open for reading: " + errnoText(errno));
    in.seekg(0, std::ios::end);
    const std::streamoff end = in.tellg();
    if (!in || end < 0)
        fail(name, "cannot determine file size: " + errnoText(errno));
    const uint64_t fileBytes = static_cast<uint64_t>(end);
    in.seekg(0, std::ios::beg);

    // Check the header against the real size before allocating for the whole file.
    std::array<uint8_t, kHeaderBytes> head{};
    const size_t headBytes = static_cast<size_t>(std::min<uint64_t>(fileBytes, kHeaderBytes));
    in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(headBytes));
    if (static_cast<size_t>(in.gcount()) != headBytes)
        fail(name, "read failed in the header");
    parseHeader(std::span<const uint8_t>(head.data(), headBytes), fileBytes, name);

    if (fileBytes > std::numeric_limits<size_t>::max())
        fail(name, "file is too large to load");
    std::vector<uint8_t> bytes(static_cast<size_t>(fileBytes));
    in.seekg(0, std::ios::beg);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (static_cast<uint64_t>(in.gcount()) != fileBytes) {
        fail(name, "read " + num(static_cast<uint64_t>(in.gcount())) + " of " + num(fileBytes) +
                       " bytes");
    }
    ShProbeGrid grid = decodeShProbe(bytes, name);
    if (bytesOut) *bytesOut = std::move(bytes);
    return grid;
}

}  // namespace terralux
