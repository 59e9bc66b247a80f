#include "ProbeDiagnosticsFile.h"

#include <cfloat>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace terralux {

namespace {

using json = nlohmann::json;
constexpr const char* kFormat = "terralux-probe-diagnostics";
constexpr int kVersion = 1;

// Millimetres for positions and sizes, 1e-6 for errors; dividing by the whole reciprocal keeps the
// shortest decimal form short (0.012345, not 0.012345000000000001).
double rounded(double v, double unit) { return std::round(v / unit) / std::round(1.0 / unit); }

std::string hex64(uint64_t v) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
    return buf;
}

json flat(const std::vector<glm::vec3>& v) {
    json a = json::array();
    for (const auto& p : v)
        for (int k = 0; k < 3; ++k) a.push_back(rounded(p[k], 1e-3));
    return a;
}

[[noreturn]] void fail(const std::string& name, const std::string& what) {
    throw ProbeDiagnosticsError(name + ": " + what);
}

const json& member(const json& j, const char* key, const std::string& name) {
    if (!j.is_object() || !j.contains(key)) fail(name, std::string("missing '") + key + "'");
    return j.at(key);
}

std::vector<float> numbers(const json& j, const char* key, const std::string& name, size_t multiple,
                           bool nulls = false) {
    const json& a = member(j, key, name);
    if (!a.is_array()) fail(name, std::string("'") + key + "' must be an array");
    if (a.size() % multiple != 0)
        fail(name, std::string("'") + key + "' must hold a multiple of " + std::to_string(multiple) +
                       " numbers (holds " + std::to_string(a.size()) + ")");
    std::vector<float> out;
    out.reserve(a.size());
    for (const json& x : a) {
        if (nulls && x.is_null()) {
            out.push_back(NAN);
            continue;
        }
        // Finite as the float it becomes, not only as the double it was written as.
        if (!x.is_number() || !std::isfinite(x.get<double>()) || std::abs(x.get<double>()) > FLT_MAX)
            fail(name, std::string("'") + key + "' holds " + x.dump() + ", not a finite number");
        out.push_back(x.get<float>());
    }
    return out;
}

std::vector<glm::vec3> points(const std::vector<float>& f) {
    std::vector<glm::vec3> out;
    for (size_t i = 0; i + 2 < f.size(); i += 3) out.emplace_back(f[i], f[i + 1], f[i + 2]);
    return out;
}

}  // namespace

std::string probeDiagnosticsFileName(const std::string& volumeName) {
    return volumeName + ".probes.json";
}

uint64_t shProbeDigest(std::span<const uint8_t> bytes) {
    // FNV-1a, 64-bit (Fowler, Noll, Vo): offset basis and prime from the published parameters.
    uint64_t h = 0xcbf29ce484222325ull;
    for (uint8_t b : bytes) {
        h ^= b;
        h *= 0x100000001b3ull;
    }
    return h;
}

std::string encodeProbeDiagnostics(const ProbeDiagnostics& d, const std::string& volumeName,
                                   const ShProbeGrid& grid) {
    const glm::uvec3 gridDims = grid.dims;
    json moved = json::array();
    for (size_t i = 0; i < d.moved.size(); ++i)
        if (d.moved[i]) moved.push_back(i);
    json leaves = json::array();
    for (const auto& l : d.leaves)
        for (int k = 0; k < 4; ++k) leaves.push_back(rounded(l[k], 1e-3));
    json error = json::array();
    for (float e : d.errorMap.error)
        error.push_back(std::isfinite(e) ? json(rounded(e, 1e-6)) : json(nullptr));
    const ErrorMap& m = d.errorMap;
    json doc = {
        {"format", kFormat},
        {"version", kVersion},
        {"volume", volumeName},
        {"probe_count", d.positions.size()},
        {"grid_dims", {gridDims.x, gridDims.y, gridDims.z}},
        {"shprobe_fnv1a64", hex64(shProbeDigest(encodeShProbe(grid)))},
        {"positions", flat(d.positions)},
        {"moved", moved},
        {"rejected", flat(d.rejected)},
        {"leaves", leaves},
        {"error_map",
         {{"size", {m.nx, m.nz}},
          {"origin", {rounded(m.x0, 1e-3), rounded(m.z0, 1e-3)}},
          {"step", m.step},
          {"height", m.height},
          {"error", error}}},
    };
    if (!d.standardError.empty()) {
        json se = json::array();
        for (float e : d.standardError) se.push_back(rounded(e, 1e-6));
        doc["standard_error"] = std::move(se);
    }
    return doc.dump() + "\n";
}

ProbeDiagnostics decodeProbeDiagnostics(const std::string& text, const std::string& name,
                                        const ShProbeGrid& grid, uint64_t shprobeDigest) {
    const size_t probeCount = grid.probes.size();
    const glm::uvec3 gridDims = grid.dims;
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) {
        fail(name, std::string("not JSON (") + e.what() + ")");
    }
    if (member(j, "format", name) != kFormat)
        fail(name, "format is " + j.at("format").dump() + ", expected \"" + kFormat + "\"");
    if (member(j, "version", name) != kVersion)
        fail(name, "version " + j.at("version").dump() + " is not supported (this build reads " +
                       std::to_string(kVersion) + ")");
    const json& count = member(j, "probe_count", name);
    if (!count.is_number_unsigned() || count.get<size_t>() != probeCount)
        fail(name, "probe_count " + count.dump() + " does not match the .shprobe's " +
                       std::to_string(probeCount) + " probes (a sidecar of another bake)");
    const json& dims = member(j, "grid_dims", name);
    if (dims != json{gridDims.x, gridDims.y, gridDims.z})
        fail(name, "grid_dims " + dims.dump() + " do not match the .shprobe's [" +
                       std::to_string(gridDims.x) + "," + std::to_string(gridDims.y) + "," +
                       std::to_string(gridDims.z) + "] (a sidecar of another bake)");
    const json& digest = member(j, "shprobe_fnv1a64", name);
    if (digest != hex64(shprobeDigest))
        fail(name, "shprobe_fnv1a64 " + digest.dump() + " does not match the .shprobe's \"" +
                       hex64(shprobeDigest) + "\" (a sidecar of another bake)");

    ProbeDiagnostics d;
    d.positions = points(numbers(j, "positions", name, 3));
    if (d.positions.size() != probeCount)
        fail(name, "positions hold " + std::to_string(d.positions.size()) + " probes, expected " +
                       std::to_string(probeCount));
    d.moved.assign(probeCount, 0);
    const json& moved = member(j, "moved", name);
    if (!moved.is_array()) fail(name, "'moved' must be an array");
    for (const json& i : moved) {
        if (!i.is_number_unsigned() || i.get<size_t>() >= probeCount)
            fail(name, "'moved' holds " + i.dump() + ", not a probe index below " +
                           std::to_string(probeCount));
        d.moved[i.get<size_t>()] = 1;
    }
    if (j.contains("standard_error")) {
        d.standardError = numbers(j, "standard_error", name, 1);
        if (d.standardError.size() != probeCount)
            fail(name, "standard_error holds " + std::to_string(d.standardError.size()) + " values, expected " +
                           std::to_string(probeCount));
        for (float e : d.standardError)
            if (!(e >= 0.0f)) fail(name, "standard_error holds " + std::to_string(e) + ", must be >= 0");
    }
    d.rejected = points(numbers(j, "rejected", name, 3));
    const std::vector<float> leaves = numbers(j, "leaves", name, 4);
    for (size_t i = 0; i < leaves.size(); i += 4) {
        if (!(leaves[i + 3] > 0.0f))
            fail(name, "leaf " + std::to_string(i / 4) + " has edge " + std::to_string(leaves[i + 3]) +
                           ", must be > 0");
        d.leaves.emplace_back(leaves[i], leaves[i + 1], leaves[i + 2], leaves[i + 3]);
    }

    const json& em = member(j, "error_map", name);
    if (!em.is_object()) fail(name, "'error_map' must be an object, not " + em.dump());
    const std::vector<float> size = numbers(em, "size", name + ": error_map", 2);
    const std::vector<float> origin = numbers(em, "origin", name + ": error_map", 2);
    if (size.size() != 2 || origin.size() != 2)
        fail(name, "error_map: size " + em.at("size").dump() + " and origin " + em.at("origin").dump() +
                       " must be 2 numbers each");
    if (size[0] < 0 || size[1] < 0 || size[0] > kMaxErrorMapResolution ||
        size[1] > kMaxErrorMapResolution || size[0] != std::floor(size[0]) || size[1] != std::floor(size[1]))
        fail(name, "error_map: size " + em.at("size").dump() + " must be whole numbers in [0, " +
                       std::to_string(kMaxErrorMapResolution) + "]");
    ErrorMap& m = d.errorMap;
    m.nx = uint32_t(size[0]);
    m.nz = uint32_t(size[1]);
    m.x0 = origin[0];
    m.z0 = origin[1];
    const json& step = member(em, "step", name + ": error_map");
    const json& height = member(em, "height", name + ": error_map");
    // The file holds millimetres: a step below that cannot come from a bake.
    if (!step.is_number() || !(step.get<double>() >= 1e-3) || !(step.get<double>() <= FLT_MAX))
        fail(name, "error_map: step " + step.dump() + " must be a number >= 0.001 (m)");
    if (!height.is_number() || !std::isfinite(height.get<double>()) || std::abs(height.get<double>()) > FLT_MAX)
        fail(name, "error_map: height " + height.dump() + " must be a finite number");
    m.step = step.get<float>();
    m.height = height.get<float>();
    m.error = numbers(em, "error", name + ": error_map", 1, true);
    if (m.error.size() != size_t(m.nx) * m.nz)
        fail(name, "error_map: error holds " + std::to_string(m.error.size()) + " values, size " +
                       em.at("size").dump() + " needs " + std::to_string(size_t(m.nx) * m.nz));
    for (float e : m.error)
        if (e < 0.0f) fail(name, "error_map: error holds " + std::to_string(e) + ", must be >= 0");
    return d;
}

ProbeDiagnostics readProbeDiagnosticsFile(const std::filesystem::path& path, const ShProbeGrid& grid,
                                          uint64_t shprobeDigest) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ProbeDiagnosticsError(path.string() + ": cannot open (" + std::strerror(errno) + ")");
    std::stringstream ss;
    ss << in.rdbuf();
    return decodeProbeDiagnostics(ss.str(), path.string(), grid, shprobeDigest);
}

}  // namespace terralux
