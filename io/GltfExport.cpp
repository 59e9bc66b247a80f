#include "GltfExport.h"
#include "FaultInjection.h"
#include "ImageFile.h"
#include "ProbeDiagnosticsFile.h"
#include "bake/PhysicalSky.h"
#include "water/Water.h"

#include <algorithm>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec4.hpp>
#include <numbers>
#include <atomic>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <span>
#include <stdexcept>
#include <system_error>
#include <utility>

#include <fcntl.h>
#include <unistd.h>

#include <tbb/parallel_for.h>
#include <tiny_gltf.h>

namespace terralux {

namespace {

namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;

constexpr const char* kEngineExtension = "VULKAN_SCHNEE_engine_properties";
constexpr const char* kGeoExtension = "TERRALUX_geo";
constexpr const char* kBakeExtension = "TERRALUX_bake";
constexpr const char* kLightingExtension = "TERRALUX_lighting";
constexpr const char* kLightsExtension = "KHR_lights_punctual";
constexpr const char* kTransmissionExtension = "KHR_materials_transmission";
constexpr const char* kIorExtension = "KHR_materials_ior";
constexpr const char* kGltfName = "scene.gltf";
constexpr const char* kBinName = "scene.bin";
constexpr const char* kProbeDir = "sh_coeffs";
constexpr const char* kProbeExt = ".shprobe";
constexpr const char* kReflectionDir = "reflection";
constexpr const char* kScenarioDir = "scenarios";
constexpr const char* kDefaultScenarioName = "default";
constexpr size_t kMaxVolumeName = 64;

// glTF enumerations (glTF 2.0 specification, section 5).
constexpr int kFloat = 5126;
constexpr int kUnsignedShort = 5123;
constexpr int kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;
constexpr int kTriangles = 4;
constexpr int kLinear = 9729;
constexpr int kLinearMipmapLinear = 9987;
constexpr int kClampToEdge = 33071;

class BinStream;

// One file of the layout: where it goes below outDir and what it holds, either as bytes or, for
// scene.bin, as a writer that produces its streamBytes bytes when the file is written.
struct PendingFile {
    fs::path relative;
    std::vector<uint8_t> bytes;
    std::function<void(BinStream&)> stream = {};
    size_t streamBytes = 0;
    size_t size() const { return stream ? streamBytes : bytes.size(); }
};

std::string errnoText(int err) {
    return std::generic_category().message(err);
}

// Little-endian appends, independent of the host.
// scene.bin's bytes: only counted (to lay out the glTF document) or written to a file in 1 MiB
// chunks, so a large DEM's mesh never exists whole in memory (it would be 14x the raster).
class BinStream {
public:
    BinStream() = default;
    explicit BinStream(std::FILE* file) : file_(file) { chunk_.reserve(kChunk); }
    // Counting only: the caller may skip producing bytes and say how many there would be.
    bool counting() const { return !file_; }
    void skip(size_t n) {
        if (!counting()) throw std::logic_error("BinStream::skip while writing");
        size_ += n;
    }
    void push_back(uint8_t b) { write(&b, 1); }
    void append(std::span<const uint8_t> bytes) { write(bytes.data(), bytes.size()); }
    void write(const uint8_t* bytes, size_t n) {
        size_ += n;
        if (!file_) return;
        while (n > 0) {
            const size_t take = std::min(n, kChunk - chunk_.size());
            chunk_.insert(chunk_.end(), bytes, bytes + take);
            bytes += take;
            n -= take;
            if (chunk_.size() == kChunk) flush();
        }
    }
    size_t size() const { return size_; }
    // False once a write has failed; errno then says why.
    bool flush() {
        if (file_ && !chunk_.empty() && ok_)
            ok_ = std::fwrite(chunk_.data(), 1, chunk_.size(), file_) == chunk_.size();
        chunk_.clear();
        return ok_;
    }

private:
    static constexpr size_t kChunk = size_t(1) << 20;
    std::FILE* file_ = nullptr;
    std::vector<uint8_t> chunk_;
    size_t size_ = 0;
    bool ok_ = true;
};

// Little-endian words into a BinStream, a word at a time (the mesh is most of a scene.bin).
void putU16(BinStream& out, uint16_t v) {
    const uint8_t b[2] = {uint8_t(v), uint8_t(v >> 8)};
    out.write(b, 2);
}
void putU32(BinStream& out, uint32_t v) {
    const uint8_t b[4] = {uint8_t(v), uint8_t(v >> 8), uint8_t(v >> 16), uint8_t(v >> 24)};
    out.write(b, 4);
}
void putF32(BinStream& out, float v) { putU32(out, std::bit_cast<uint32_t>(v)); }

// The same words stored into a buffer, for the mesh's rows (writeRows).
uint8_t* storeU16(uint8_t* p, uint16_t v) {
    p[0] = uint8_t(v);
    p[1] = uint8_t(v >> 8);
    return p + 2;
}
uint8_t* storeU32(uint8_t* p, uint32_t v) {
    p[0] = uint8_t(v);
    p[1] = uint8_t(v >> 8);
    p[2] = uint8_t(v >> 16);
    p[3] = uint8_t(v >> 24);
    return p + 4;
}
uint8_t* storeF32(uint8_t* p, float v) { return storeU32(p, std::bit_cast<uint32_t>(v)); }

// `rows` rows of `rowBytes` bytes each into `bin`, in order: fill(row, out) stores row's bytes
// at out. The rows of a window of some 16 MiB are filled in parallel, then written: the same bytes
// as writing them one by one, at bounded memory (a 4800² mesh is 1.3 GB). Counting, only skipped.
template <class Fill>
void writeRows(BinStream& bin, size_t rows, size_t rowBytes, const Fill& fill) {
    if (bin.counting()) return bin.skip(rows * rowBytes);
    constexpr size_t kWindowBytes = size_t(16) << 20;
    const size_t window = std::max<size_t>(1, kWindowBytes / std::max<size_t>(rowBytes, 1));
    std::vector<uint8_t> buffer;
    for (size_t first = 0; first < rows; first += window) {
        const size_t n = std::min(window, rows - first);
        buffer.resize(n * rowBytes);
        tbb::parallel_for(size_t(0), n, [&](size_t i) { fill(first + i, buffer.data() + i * rowBytes); });
        bin.write(buffer.data(), buffer.size());
    }
}

void padTo4(BinStream& out) {
    while (out.size() % 4 != 0)
        out.push_back(0);
}

bool validVolumeName(const std::string& name) {
    if (name.empty() || name.size() > kMaxVolumeName)
        return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
               c == '_' || c == '-';
    });
}

// Vertex rows or columns kept with stride k: 0, k, 2k, ... and always the last one.
std::vector<int> sampledLines(int n, size_t k) {
    std::vector<int> lines;
    for (size_t i = 0; i + 1 < size_t(n); i += k)
        lines.push_back(int(i));
    lines.push_back(n - 1);
    return lines;
}

size_t sampledCount(int n, size_t k) {
    return n <= 1 ? 1 : (size_t(n - 1) + k - 1) / k + 1;
}

// The smallest stride whose mesh fits the vertex budget.
size_t chooseStride(const Heightfield& hf, size_t budget, const fs::path& gltfPath) {
    const size_t longest = size_t(std::max(hf.width(), hf.depth()));
    size_t k = 1;
    while (sampledCount(hf.width(), k) * sampledCount(hf.depth(), k) > budget) {
        if (k + 1 >= longest) {
            throw std::runtime_error(gltfPath.string() + ": meshMaxVertices = " +
                                     std::to_string(budget) +
                                     " is below the 4 vertices of the coarsest terrain mesh");
        }
        ++k;
    }
    return k;
}

ojson floats(std::initializer_list<float> values) {
    ojson a = ojson::array();
    for (float v : values)
        a.push_back(double(v));
    return a;
}

// The water plane: the footprint's rectangle at the level, appended to scene.bin (positions,
// normals, indices) as node, mesh and material 1, all named `water`. Its material transmits
// (KHR_materials_transmission) with water's index of refraction (KHR_materials_ior), tinted by
// the deep-water scatter colour, with the waves' highlight roughness.
void addWaterPlane(const Heightfield& hf, const GltfWater& w, BinStream& bin, ojson& doc) {
    const float x0 = hf.minX(), x1 = hf.maxX(), z0 = hf.minZ(), z1 = hf.maxZ();
    const size_t positionOffset = bin.size();
    // Corners north-west, south-west, south-east, north-east.
    for (const auto& [x, z] : {std::pair{x0, z0}, std::pair{x0, z1}, std::pair{x1, z1}, std::pair{x1, z0}}) {
        putF32(bin, x);
        putF32(bin, w.level);
        putF32(bin, z);
    }
    const size_t normalOffset = bin.size();
    for (int i = 0; i < 4; ++i) {
        putF32(bin, 0.0f);
        putF32(bin, 1.0f);
        putF32(bin, 0.0f);
    }
    const size_t indexOffset = bin.size();
    // Counter-clockwise seen from +Y (X east, Z south), as the terrain's triangles.
    for (uint16_t i : {0, 1, 2, 0, 2, 3})
        putU16(bin, i);
    const size_t indexBytes = bin.size() - indexOffset;
    padTo4(bin);

    const size_t firstView = doc["bufferViews"].size(), firstAccessor = doc["accessors"].size();
    auto view = [](size_t offset, size_t length, int target) {
        return ojson{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}, {"target", target}};
    };
    doc["bufferViews"].push_back(view(positionOffset, normalOffset - positionOffset, kArrayBuffer));
    doc["bufferViews"].push_back(view(normalOffset, indexOffset - normalOffset, kArrayBuffer));
    doc["bufferViews"].push_back(view(indexOffset, indexBytes, kElementArrayBuffer));
    doc["accessors"].push_back(ojson{{"name", "water POSITION"}, {"bufferView", firstView}, {"componentType", kFloat},
                                     {"count", 4}, {"type", "VEC3"},
                                     {"min", floats({x0, w.level, z0})}, {"max", floats({x1, w.level, z1})}});
    doc["accessors"].push_back(ojson{{"name", "water NORMAL"}, {"bufferView", firstView + 1},
                                     {"componentType", kFloat}, {"count", 4}, {"type", "VEC3"}});
    doc["accessors"].push_back(ojson{{"name", "water indices"}, {"bufferView", firstView + 2},
                                     {"componentType", kUnsignedShort}, {"count", 6}, {"type", "SCALAR"}});
    const size_t material = doc["materials"].size(), mesh = doc["meshes"].size(), node = doc["nodes"].size();
    doc["materials"].push_back(ojson{
        {"name", "water"},
        {"pbrMetallicRoughness",
         {{"baseColorFactor", floats({w.color.r, w.color.g, w.color.b, 1.0f})},
          {"metallicFactor", 0.0},
          {"roughnessFactor", double(w.roughness)}}},
        {"extensions",
         {{kTransmissionExtension, {{"transmissionFactor", 1.0}}}, {kIorExtension, {{"ior", water::kWaterIor}}}}}});
    doc["meshes"].push_back(ojson{
        {"name", "water"},
        {"primitives", ojson::array({ojson{{"attributes", {{"POSITION", firstAccessor}, {"NORMAL", firstAccessor + 1}}},
                                           {"indices", firstAccessor + 2},
                                           {"material", material},
                                           {"mode", kTriangles}}})}});
    doc["nodes"].push_back(ojson{{"name", "water"}, {"mesh", mesh}});
    doc["scenes"][0]["nodes"].push_back(node);
    doc["extensionsUsed"].push_back(kTransmissionExtension);
    doc["extensionsUsed"].push_back(kIorExtension);
}

// The local lights as KHR_lights_punctual: one light and one node each. The spec's lights shine
// along the node's −Z; the node's rotation is the shortest arc from −Z to the spot's direction.
void addLights(ojson& doc, const std::vector<LocalLight>& lights) {
    if (!doc.contains("scenes")) {
        doc["scene"] = 0;
        doc["scenes"] = ojson::array({ojson{{"name", "terrain"}, {"nodes", ojson::array()}}});
    }
    if (!doc.contains("nodes")) doc["nodes"] = ojson::array();
    ojson list = ojson::array();
    constexpr double kDeg = std::numbers::pi / 180.0;
    for (size_t i = 0; i < lights.size(); ++i) {
        const LocalLight& l = lights[i];
        const bool spot = l.type == LocalLightType::Spot;
        ojson light = {{"name", "light " + std::to_string(i)},
                       {"type", spot ? "spot" : "point"},
                       {"color", floats({l.color.r, l.color.g, l.color.b})},
                       {"intensity", l.intensity},  // candela, as authored
                       {"range", l.range}};
        if (spot)
            light["spot"] = {{"innerConeAngle", l.innerConeDeg * kDeg}, {"outerConeAngle", l.outerConeDeg * kDeg}};
        list.push_back(std::move(light));
        ojson node = {{"name", "light " + std::to_string(i)},
                      {"translation", floats({l.position.x, l.position.y, l.position.z})},
                      {"extensions", {{kLightsExtension, {{"light", i}}}}}};
        if (spot) {
            const glm::dvec3 d = glm::normalize(glm::dvec3(l.direction)), from(0.0, 0.0, -1.0);
            const double c = glm::dot(from, d);
            glm::dvec4 q;  // x, y, z, w
            if (c < -1.0 + 1e-12) {
                q = glm::dvec4(0.0, 1.0, 0.0, 0.0);  // +Z: half a turn about +Y
            } else {
                const glm::dvec3 axis = glm::cross(from, d);
                q = glm::normalize(glm::dvec4(axis, 1.0 + c));
            }
            if (q != glm::dvec4(0.0, 0.0, 0.0, 1.0)) node["rotation"] = {q.x, q.y, q.z, q.w};
        }
        const size_t index = doc["nodes"].size();
        doc["nodes"].push_back(std::move(node));
        doc["scenes"][0]["nodes"].push_back(index);
    }
    doc["extensions"][kLightsExtension] = {{"lights", std::move(list)}};
    doc["extensionsUsed"].push_back(kLightsExtension);
}

// scene.bin's layout: the mesh stride, its size, and the albedo texture's PNG, encoded once.
struct MeshBuild {
    size_t stride = 1;
    size_t bytes = 0;
    std::vector<uint8_t> png;
};

// Emits scene.bin into bin and the mesh part of the glTF document into doc. Run once counting,
// to lay out the document, and again when the file is written, with the same bytes.
void buildMesh(const Heightfield& hf, const GltfSceneInput& input, const fs::path& gltfPath,
               ojson& doc, BinStream& bin, MeshBuild& mesh) {
    mesh.stride = checkTerrainMesh(hf, input.meshMaxVertices, gltfPath);
    const std::vector<int> cols = sampledLines(hf.width(), mesh.stride);
    const std::vector<int> rows = sampledLines(hf.depth(), mesh.stride);
    const size_t nc = cols.size(), nr = rows.size();
    const size_t vertexCount = nc * nr;
    const size_t indexCount = 6 * (nc - 1) * (nr - 1);
    // 65535 is the primitive-restart value of 16-bit indices, so it may not be used as an index.
    const bool wideIndices = vertexCount > 65535;

    const size_t positionOffset = bin.size();
    glm::vec3 lo(std::numeric_limits<float>::infinity());
    glm::vec3 hi(-std::numeric_limits<float>::infinity());
    for (int r : rows)
        for (int c : cols) {
            const glm::vec3 p = hf.vertex(c, r);
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
    // The layout pass (counting) needs the bounds but none of the bytes: writeRows skips them.
    writeRows(bin, nr, nc * 12, [&](size_t ri, uint8_t* out) {
        for (int c : cols) {
            const glm::vec3 p = hf.vertex(c, rows[ri]);
            out = storeF32(storeF32(storeF32(out, p.x), p.y), p.z);
        }
    });
    const size_t normalOffset = bin.size();
    // Vertex (c, r) of hf is (c + dc, r + dr) of its surroundings: window origins are exact.
    const Heightfield& around = input.surroundings ? *input.surroundings : hf;
    const int dc = int(std::lround(around.originCol() - hf.originCol()));
    const int dr = int(std::lround(around.originRow() - hf.originRow()));
    if (dc < 0 || dr < 0 || dc + hf.width() > around.width() || dr + hf.depth() > around.depth())
        throw std::invalid_argument("glTF export: the surroundings do not hold the heightfield's window");
    writeRows(bin, nr, nc * 12, [&](size_t ri, uint8_t* out) {
        for (int c : cols) {
            const glm::vec3 n = around.vertexNormal(c + dc, rows[ri] + dr);
            out = storeF32(storeF32(storeF32(out, n.x), n.y), n.z);
        }
    });
    const SurfaceAlbedo* texture =
        input.albedoTexture && !input.albedoTexture->empty() ? input.albedoTexture : nullptr;
    const size_t uvOffset = bin.size();
    writeRows(bin, nr, nc * 8, [&](size_t ri, uint8_t* out) {
        const int r = rows[ri];
        for (int c : cols) {
            const double u = double(c + dc) / double(std::max(around.width() - 1, 1));
            const double v = double(r + dr) / double(std::max(around.depth() - 1, 1));
            if (texture) {
                // Texel centres span the footprint corner to corner (SurfaceAlbedo.h), and glTF
                // addresses texel i's centre at (i + 0.5) / size: corners land on corner texels.
                out = storeF32(out, float((u * (texture->width - 1) + 0.5) / texture->width));
                out = storeF32(out, float((v * (texture->height - 1) + 0.5) / texture->height));
            } else {
                out = storeF32(storeF32(out, float(u)), float(v));
            }
        }
    });
    const size_t indexOffset = bin.size();
    // Per cell, the bake's two triangles along the (c, r)-(c+1, r+1) diagonal. With X east and
    // Z south, (c, r) -> (c, r+1) -> (c+1, r+1) turns counter-clockwise seen from +Y.
    writeRows(bin, nr - 1, (nc - 1) * 6 * (wideIndices ? 4 : 2), [&](size_t ri, uint8_t* out) {
        auto put = [&](size_t ci, size_t row) {
            const size_t v = row * nc + ci;
            out = wideIndices ? storeU32(out, uint32_t(v)) : storeU16(out, uint16_t(v));
        };
        for (size_t ci = 0; ci + 1 < nc; ++ci) {
            put(ci, ri);
            put(ci, ri + 1);
            put(ci + 1, ri + 1);
            put(ci, ri);
            put(ci + 1, ri + 1);
            put(ci + 1, ri);
        }
    });
    const size_t indexBytes = bin.size() - indexOffset;
    padTo4(bin);
    const size_t imageOffset = bin.size();
    if (texture) {
        if (mesh.png.empty()) {
            try {
                mesh.png = encodePng(uint32_t(texture->width), uint32_t(texture->height), 3,
                                     texture->srgb);
            } catch (const std::exception& e) {
                throw std::runtime_error(gltfPath.string() + ": albedo texture: " + e.what());
            }
        }
        bin.append(mesh.png);
    }
    const size_t imageBytes = bin.size() - imageOffset;
    padTo4(bin);

    auto view = [](size_t offset, size_t length, int target) {
        return ojson{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}, {"target", target}};
    };
    doc["scene"] = 0;
    doc["scenes"] = ojson::array({ojson{{"name", "terrain"}, {"nodes", {0}}}});
    doc["nodes"] = ojson::array({ojson{{"name", "terrain"}, {"mesh", 0}}});
    doc["meshes"] = ojson::array({ojson{
        {"name", "terrain"},
        {"primitives",
         ojson::array({ojson{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}},
                             {"indices", 3},
                             {"material", 0},
                             {"mode", kTriangles}}})}}});
    if (texture) {
        doc["materials"] = ojson::array({ojson{
            {"name", "terrain"},
            {"pbrMetallicRoughness",
             {{"baseColorTexture", {{"index", 0}, {"texCoord", 0}}},
              {"baseColorFactor", floats({1.0f, 1.0f, 1.0f, 1.0f})},
              {"metallicFactor", 0.0},
              {"roughnessFactor", double(input.roughness)}}}}});
        doc["samplers"] = ojson::array({ojson{{"magFilter", kLinear}, {"minFilter", kLinearMipmapLinear},
                                              {"wrapS", kClampToEdge}, {"wrapT", kClampToEdge}}});
        doc["images"] = ojson::array({ojson{{"name", "terrain albedo"}, {"bufferView", 4}, {"mimeType", "image/png"}}});
        doc["textures"] = ojson::array({ojson{{"sampler", 0}, {"source", 0}}});
    } else {
        doc["materials"] = ojson::array({ojson{
            {"name", "terrain"},
            {"pbrMetallicRoughness",
             {{"baseColorFactor", floats({input.albedo.r, input.albedo.g, input.albedo.b, 1.0f})},
              {"metallicFactor", 0.0},
              {"roughnessFactor", double(input.roughness)}}}}});
    }
    doc["accessors"] = ojson::array({
        ojson{{"name", "POSITION"}, {"bufferView", 0}, {"componentType", kFloat},
              {"count", vertexCount}, {"type", "VEC3"},
              {"min", floats({lo.x, lo.y, lo.z})}, {"max", floats({hi.x, hi.y, hi.z})}},
        ojson{{"name", "NORMAL"}, {"bufferView", 1}, {"componentType", kFloat},
              {"count", vertexCount}, {"type", "VEC3"}},
        ojson{{"name", "TEXCOORD_0"}, {"bufferView", 2}, {"componentType", kFloat},
              {"count", vertexCount}, {"type", "VEC2"}},
        ojson{{"name", "indices"}, {"bufferView", 3},
              {"componentType", wideIndices ? kUnsignedInt : kUnsignedShort},
              {"count", indexCount}, {"type", "SCALAR"}},
    });
    doc["bufferViews"] = ojson::array({
        view(positionOffset, normalOffset - positionOffset, kArrayBuffer),
        view(normalOffset, uvOffset - normalOffset, kArrayBuffer),
        view(uvOffset, indexOffset - uvOffset, kArrayBuffer),
        view(indexOffset, indexBytes, kElementArrayBuffer),
    });
    // An image's view has no target (glTF 2.0, 3.6.2.4: only vertex and index data have one).
    if (texture)
        doc["bufferViews"].push_back(ojson{{"buffer", 0}, {"byteOffset", imageOffset}, {"byteLength", imageBytes}});
    if (input.water)
        addWaterPlane(hf, *input.water, bin, doc);
    doc["buffers"] = ojson::array({ojson{{"uri", kBinName}, {"byteLength", bin.size()}}});
    mesh.bytes = bin.size();
}

// scenarios/<volume>.<scenario>.shprobe: names hold no '.', so the two parts stay apart.
fs::path scenarioFileName(const std::string& volume, const std::string& scenario) {
    return fs::path(kScenarioDir) / (volume + "." + scenario + kProbeExt);
}

ojson probeGridEntry(const GltfProbeVolume& v) {
    const ShProbeGrid& g = v.grid;
    return ojson{
        {"shProbePath", std::string(kProbeDir) + "/" + v.name + kProbeExt},
        {"volumeName", v.name},
        {"probeCount", uint64_t(g.probes.size())},
        {"gridDimensions", {g.dims.x, g.dims.y, g.dims.z}},
        {"gridOrigin", floats({g.origin.x, g.origin.y, g.origin.z})},
        {"gridSpacing", double(g.spacing)},
        {"defaultScale", double(g.defaultScale)},
        {"defaultAmbient", double(g.defaultAmbient)},
    };
}

// Encodes the grid; ShProbeError messages are re-prefixed with the file they were meant for.
std::vector<uint8_t> encodeVolume(const GltfProbeVolume& v, const fs::path& target) {
    try {
        return encodeShProbe(v.grid);
    } catch (const ShProbeError& e) {
        static constexpr std::string_view kPrefix = "shprobe grid: ";
        std::string_view what = e.what();
        if (what.starts_with(kPrefix))
            what.remove_prefix(kPrefix.size());
        throw ShProbeError(target.string() + ": " + std::string(what));
    }
}

void checkInput(const fs::path& outDir, const GltfSceneInput& input,
                const std::vector<const GltfProbeVolume*>& sorted) {
    const fs::path gltfPath = outDir / kGltfName;
    const Heightfield* hf = input.heightfield;
    if (!hf || hf->width() < 1 || hf->depth() < 1)
        throw std::runtime_error(gltfPath.string() + ": no terrain to export (empty heightfield)");
    for (int c = 0; c < 3; ++c) {
        const float a = input.albedo[c];
        if (!std::isfinite(a) || a < 0.0f || a > 1.0f) {
            throw std::runtime_error(gltfPath.string() + ": albedo channel " + std::to_string(c) +
                                     " = " + std::to_string(a) + " must be in [0, 1]");
        }
    }
    if (!std::isfinite(input.roughness) || input.roughness < 0.0f || input.roughness > 1.0f)
        throw std::runtime_error(gltfPath.string() + ": roughness = " + std::to_string(input.roughness) +
                                 " must be in [0, 1]");
    if (const SurfaceAlbedo* t = input.albedoTexture; t && !t->empty() &&
        t->texels() != size_t(t->width) * size_t(t->height))
        throw std::runtime_error(gltfPath.string() + ": albedo texture of " + std::to_string(t->width) + " x " +
                                 std::to_string(t->height) + " texels holds " + std::to_string(t->texels()));
    const GeoOrigin& geo = hf->geo;
    if (!std::isfinite(input.verticalScale) || !std::isfinite(geo.easting) ||
        !std::isfinite(geo.northing) || !std::isfinite(geo.height)) {
        throw std::runtime_error(gltfPath.string() +
                                 ": the vertical scale and the geo origin must be finite");
    }
    if (!input.bake.is_object()) {
        throw std::runtime_error(gltfPath.string() + ": the " + kBakeExtension +
                                 " metadata must be a JSON object, not " + input.bake.type_name());
    }
    if (const auto& w = input.water) {
        if (!std::isfinite(w->level))
            throw std::runtime_error(gltfPath.string() + ": water level = " + std::to_string(w->level) +
                                     " must be finite");
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(w->color[c]) || w->color[c] < 0.0f || w->color[c] > 1.0f)
                throw std::runtime_error(gltfPath.string() + ": water colour channel " + std::to_string(c) +
                                         " = " + std::to_string(w->color[c]) + " must be in [0, 1]");
        if (!std::isfinite(w->roughness) || w->roughness < 0.0f || w->roughness > 1.0f)
            throw std::runtime_error(gltfPath.string() + ": water roughness = " + std::to_string(w->roughness) +
                                     " must be in [0, 1]");
    }
    if (!input.lighting.is_null() && !input.lighting.is_object()) {
        throw std::runtime_error(gltfPath.string() + ": the " + kLightingExtension +
                                 " metadata must be a JSON object or null, not " +
                                 input.lighting.type_name());
    }
    if (!input.scenarios.empty() && !input.lighting.is_object())
        throw std::runtime_error(gltfPath.string() + ": lighting scenarios need the " + kLightingExtension +
                                 " object that lists them");
    std::set<std::string> scenarioNames{kDefaultScenarioName};
    for (const GltfScenario& sc : input.scenarios) {
        const fs::path dir = outDir / kScenarioDir;
        if (!validVolumeName(sc.name) || !scenarioNames.insert(sc.name).second)
            throw std::runtime_error(dir.string() + ": scenario name '" + sc.name +
                                     "' must be 1 to 64 of A-Z a-z 0-9 _ -, unique and not \"default\"");
        if (!sc.lighting.is_object())
            throw std::runtime_error(dir.string() + ": scenario '" + sc.name + "': its lighting must be a JSON object");
        // The same layout as the default's: an engine blends two scenarios probe by probe.
        bool same = sc.volumes.size() == input.volumes.size();
        for (size_t i = 0; same && i < sc.volumes.size(); ++i) {
            const ShProbeGrid &a = sc.volumes[i].grid, &b = input.volumes[i].grid;
            same = sc.volumes[i].name == input.volumes[i].name && a.dims == b.dims && a.origin == b.origin &&
                   a.spacing == b.spacing && a.occupancy == b.occupancy;
        }
        if (!same)
            throw std::runtime_error(dir.string() + ": scenario '" + sc.name +
                                     "' must hold the default's volumes with their layout (names, grids and occupancy)");
    }
    for (size_t i = 0; i < sorted.size(); ++i) {
        const std::string& name = sorted[i]->name;
        if (!validVolumeName(name)) {
            throw std::runtime_error((outDir / kProbeDir).string() + ": probe volume name '" +
                                     name + "' must be 1 to 64 of A-Z a-z 0-9 _ -");
        }
        if (i > 0 && sorted[i - 1]->name == name) {
            throw std::runtime_error((outDir / kProbeDir / (name + kProbeExt)).string() +
                                     ": two probe volumes are named '" + name + "'");
        }
    }
}

// The volumes by file name, which is not always the order of the stems ("a-b.shprobe" < "a.shprobe").
std::vector<const GltfProbeVolume*> sortedVolumes(const GltfSceneInput& input) {
    std::vector<const GltfProbeVolume*> sorted;
    for (const GltfProbeVolume& v : input.volumes)
        sorted.push_back(&v);
    std::sort(sorted.begin(), sorted.end(), [](const GltfProbeVolume* a, const GltfProbeVolume* b) {
        return a->name + kProbeExt < b->name + kProbeExt;
    });
    return sorted;
}

std::vector<PendingFile> buildFiles(const fs::path& outDir, const GltfSceneInput& input) {
    const fs::path gltfPath = outDir / kGltfName;
    const std::vector<const GltfProbeVolume*> sorted = sortedVolumes(input);
    checkInput(outDir, input, sorted);
    const Heightfield& hf = *input.heightfield;

    std::vector<PendingFile> files;
    ojson grids = ojson::array();
    for (const GltfProbeVolume* v : sorted) {
        const fs::path relative = fs::path(kProbeDir) / (v->name + kProbeExt);
        files.push_back({relative, encodeVolume(*v, outDir / relative)});
        if (!v->diagnostics.empty())
            files.push_back({fs::path(kProbeDir) / probeDiagnosticsFileName(v->name),
                             std::vector<uint8_t>(v->diagnostics.begin(), v->diagnostics.end())});
        grids.push_back(probeGridEntry(*v));
    }
    // Each scenario's files in the default's order; TERRALUX_lighting.scenarios names them.
    ojson scenarioEntries = ojson::array();
    if (!input.scenarios.empty()) {
        ojson defaults = {{"name", kDefaultScenarioName}};
        for (const auto& [k, v] : input.defaultLighting.items()) defaults[k] = ojson(v);
        defaults["shProbePaths"] = ojson::array();
        for (const GltfProbeVolume* v : sorted)
            defaults["shProbePaths"].push_back(std::string(kProbeDir) + "/" + v->name + kProbeExt);
        scenarioEntries.push_back(std::move(defaults));
    }
    for (const GltfScenario& sc : input.scenarios) {
        ojson entry = {{"name", sc.name}};
        for (const auto& [k, v] : sc.lighting.items()) entry[k] = ojson(v);
        entry["shProbePaths"] = ojson::array();
        for (const GltfProbeVolume* d : sorted) {
            const auto v = std::find_if(sc.volumes.begin(), sc.volumes.end(),
                                        [&](const GltfProbeVolume& x) { return x.name == d->name; });
            const fs::path relative = scenarioFileName(v->name, sc.name);
            files.push_back({relative, encodeVolume(*v, outDir / relative)});
            entry["shProbePaths"].push_back(relative.generic_string());
        }
        scenarioEntries.push_back(std::move(entry));
    }
    for (const auto& [name, bytes] : input.reflectionFiles) {
        if (name.empty() || fs::path(name).has_parent_path())
            throw std::runtime_error(name + ": not a name for a file of " + kReflectionDir + "/");
        files.push_back({fs::path(kReflectionDir) / name, bytes});
    }
    for (const auto& [name, text] : input.extraFiles) {
        if (name.empty() || fs::path(name).has_parent_path() || name == kGltfName || name == kBinName)
            throw std::runtime_error(name + ": not a name for an extra top-level file");
    }
    auto addExtras = [&] {
        for (const auto& [name, text] : input.extraFiles)
            files.push_back({name, std::vector<uint8_t>(text.begin(), text.end())});
    };
    if (!input.scene) {
        addExtras();
        return files;
    }

    try {
        ojson doc;
        doc["asset"] = {{"version", "2.0"},
                        {"generator", input.generatorVersion.empty()
                                          ? std::string("Terralux")
                                          : "Terralux " + input.generatorVersion}};
        doc["extensionsUsed"] = {kEngineExtension, kGeoExtension, kBakeExtension};
        if (input.lighting.is_object())
            doc["extensionsUsed"].push_back(kLightingExtension);
        auto mesh = std::make_shared<MeshBuild>();
        const bool hasMesh = hf.width() >= 2 && hf.depth() >= 2;
        if (hasMesh) {
            BinStream counted;
            buildMesh(hf, input, gltfPath, doc, counted, *mesh);
        }
        // Seed 001's extension and ours are scene-level: an engine reads them from the scene it
        // loads (scenes[0].extensions), not from the asset's root.
        if (!doc.contains("scenes")) {
            doc["scene"] = 0;
            doc["scenes"] = ojson::array({ojson{{"name", "terrain"}}});
        }
        ojson& sceneExtensions = doc["scenes"][0]["extensions"];
        sceneExtensions = {
            {kEngineExtension, {{"shProbeGrids", std::move(grids)}}},
            {kGeoExtension,
             {{"crs", hf.geo.crsWkt},
              {"crsName", hf.geo.crsName},
              {"epsg", hf.geo.epsg},
              {"originEasting", hf.geo.easting},
              {"originNorthing", hf.geo.northing},
              {"originHeight", hf.geo.height},
              {"verticalScale", input.verticalScale},
              {"cellSize", {hf.cellSizeX(), hf.cellSizeZ()}},
              {"gridSize", {hf.width(), hf.depth()}},
              {"meshStride", mesh->stride}}},
            {kBakeExtension, ojson(input.bake)},
        };
        if (input.lighting.is_object()) {
            sceneExtensions[kLightingExtension] = ojson(input.lighting);
            if (!scenarioEntries.empty()) sceneExtensions[kLightingExtension]["scenarios"] = scenarioEntries;
        }
        if (!input.lights.empty()) addLights(doc, input.lights);
        if (hasMesh) {
            auto write = [&hf, &input, gltfPath, mesh](BinStream& bin) {
                ojson scratch;
                buildMesh(hf, input, gltfPath, scratch, bin, *mesh);
            };
            files.push_back({kBinName, {}, write, mesh->bytes});
        }
        const std::string text = doc.dump(2) + "\n";
        files.push_back({kGltfName, std::vector<uint8_t>(text.begin(), text.end())});
    } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(gltfPath.string() + ": cannot encode the glTF JSON (" +
                                 e.what() + ")");
    }
    addExtras();
    return files;
}

// Writes, flushes and syncs one staged file; errors name the final target.
void writeStaged(const fs::path& staged, const fs::path& target, const PendingFile& file) {
    if (injectedFailure("write", staged))
        throw FileWriteError(target.string() + ": cannot write (" + errnoText(EIO) + ")");
    std::FILE* f = std::fopen(staged.c_str(), "wb");
    if (!f)
        throw FileWriteError(target.string() + ": cannot write (" + errnoText(errno) + ")");
    errno = 0;
    bool written = true;
    if (file.stream) {
        BinStream out(f);
        try {
            file.stream(out);
        } catch (...) {
            std::fclose(f);
            throw;
        }
        written = out.flush() && out.size() == file.streamBytes;
    } else {
        written = file.bytes.empty() || std::fwrite(file.bytes.data(), 1, file.bytes.size(), f) == file.bytes.size();
    }
    const int writeErr = errno;
    errno = 0;
    const bool flushed = std::fflush(f) == 0 && !injectedFailure("fsync", staged) && ::fsync(::fileno(f)) == 0;
    const int flushErr = flushed ? 0 : errno ? errno : EIO;
    const bool closed = std::fclose(f) == 0;
    if (!written || !flushed || !closed) {
        const int err = !written ? writeErr : !flushed ? flushErr : errno;
        throw FileWriteError(target.string() + ": write failed (" + errnoText(err ? err : EIO) + ")");
    }
}

void syncDirectory(const fs::path& dir) {
    int err = 0;
    if (injectedFailure("fsync", dir)) {
        err = EIO;
    } else {
        const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        // A file system that cannot open or sync a directory (EINVAL) gives no such guarantee.
        if (fd >= 0) {
            if (::fsync(fd) != 0 && errno != EINVAL) err = errno;
            ::close(fd);
        }
    }
    if (err) throw FileWriteError(dir.string() + ": cannot sync the folder (" + errnoText(err) + ")");
}

// A fresh ".staging-<unique>" directory inside outDir, removed with everything in it on scope exit.
class StagingDirectory {
public:
    explicit StagingDirectory(const fs::path& outDir) {
        static std::atomic<uint64_t> counter{0};
        std::random_device rd;
        for (int attempt = 0; attempt < 16; ++attempt) {
            const uint64_t r = (uint64_t{rd()} << 32) ^ rd();
            char suffix[17];
            std::snprintf(suffix, sizeof suffix, "%016llx", static_cast<unsigned long long>(r));
            const fs::path candidate = outDir / (".staging-" + std::to_string(::getpid()) + "-" +
                                                 std::to_string(counter.fetch_add(1)) + "-" + suffix);
            std::error_code ec;
            if (fs::create_directory(candidate, ec)) {
                path_ = candidate;
                return;
            }
            if (ec && ec != std::errc::file_exists) {
                throw FileWriteError(outDir.string() + ": cannot create a staging directory (" +
                                     ec.message() + ")");
            }
        }
        throw FileWriteError(outDir.string() + ": cannot create a unique staging directory");
    }
    ~StagingDirectory() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    StagingDirectory(const StagingDirectory&) = delete;
    StagingDirectory& operator=(const StagingDirectory&) = delete;
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

struct Replaced {
    fs::path target;
    fs::path backup;  // empty: there was no file before
};

// Moves every staged file into place. Before a target is replaced, its current file is hard-linked
// (or copied) into the staging directory, so that a later failure can put every replaced file
// back. Throws after the rollback.
// What an earlier export left that this one owns but does not write: every regular file in
// sh_coeffs/ and the owned top-level names, less the files being written now.
// The subdirectories (sh_coeffs/, reflection/) the files go into.
std::vector<fs::path> subdirectories(const std::vector<PendingFile>& files) {
    std::set<fs::path> dirs;
    for (const auto& f : files)
        if (f.relative.has_parent_path()) dirs.insert(f.relative.parent_path());
    return {dirs.begin(), dirs.end()};
}

std::vector<fs::path> staleOwnedFiles(const fs::path& outDir, const std::vector<PendingFile>& files,
                                      const std::vector<std::string>& ownedNames) {
    std::set<fs::path> writing;
    for (const auto& f : files) writing.insert(f.relative);
    std::vector<fs::path> stale;
    std::error_code ec;
    for (const char* dir : {kProbeDir, kScenarioDir, kReflectionDir})
        for (const auto& e : fs::directory_iterator(outDir / dir, ec)) {
            const fs::path relative = fs::path(dir) / e.path().filename();
            if (e.is_regular_file(ec) && !writing.count(relative)) stale.push_back(relative);
        }
    for (const auto& name : ownedNames)
        if (!writing.count(name) && fs::is_regular_file(outDir / name, ec)) stale.push_back(name);
    std::sort(stale.begin(), stale.end());
    return stale;
}

void commit(const fs::path& outDir, const fs::path& staging, const std::vector<PendingFile>& files,
            const std::vector<fs::path>& stale) {
    std::vector<Replaced> done;
    std::vector<fs::path> createdDirs;
    try {
        for (const fs::path& dir : subdirectories(files)) {
            if (fs::is_directory(outDir / dir)) continue;
            std::error_code ec;
            if (!fs::create_directory(outDir / dir, ec)) {
                throw FileWriteError((outDir / dir).string() + ": cannot create directory (" +
                                     (ec ? ec.message() : std::string("exists, not a directory")) + ")");
            }
            createdDirs.push_back(outDir / dir);
        }
        // Owned files this export does not write go into the staging directory (removed with
        // it), so that engines loading every file of sh_coeffs/ see only this bake.
        for (size_t i = 0; i < stale.size(); ++i) {
            const fs::path target = outDir / stale[i], kept = staging / ("stale-" + std::to_string(i));
            std::error_code ec;
            if (injectedFailure("rename", target))
                ec = std::make_error_code(std::errc::io_error);
            else
                fs::rename(target, kept, ec);
            if (ec)
                throw FileWriteError(target.string() + ": cannot remove the earlier bake's file (" +
                                     ec.message() + ")");
            // Rolled back like a replaced file: the earlier file goes back, nothing new is removed.
            done.push_back({target, kept});
        }
        for (size_t i = 0; i < files.size(); ++i) {
            const fs::path target = outDir / files[i].relative;
            const fs::path staged = staging / files[i].relative;
            Replaced step{target, {}};
            std::error_code ec;
            const fs::file_status st = fs::symlink_status(target, ec);
            if (fs::exists(st)) {
                if (fs::is_directory(st))
                    throw FileWriteError(target.string() + ": cannot replace (is a directory)");
                step.backup = staging / ("previous-" + std::to_string(i));
                if (injectedFailure("link", target)) {
                    // Fails the link and its copy fallback alike.
                    throw FileWriteError(target.string() + ": cannot keep the previous file (" +
                                         errnoText(EIO) + ")");
                }
                fs::create_hard_link(target, step.backup, ec);
                if (ec) {
                    ec.clear();
                    fs::copy_file(target, step.backup, ec);
                }
                if (ec) {
                    throw FileWriteError(target.string() + ": cannot keep the previous file (" +
                                         ec.message() + ")");
                }
            }
            if (injectedFailure("rename", target))
                ec = std::make_error_code(std::errc::io_error);
            else
                fs::rename(staged, target, ec);
            if (ec)
                throw FileWriteError(target.string() + ": cannot replace (" + ec.message() + ")");
            done.push_back(std::move(step));
        }
        for (const char* dir : {kProbeDir, kScenarioDir, kReflectionDir})
            if (fs::is_directory(outDir / dir)) syncDirectory(outDir / dir);
        syncDirectory(outDir);
    } catch (...) {
        // Rollback undoes the renames above with plain calls (no fault injection): each puts a
        // file back where this commit moved it from, in the same folder.
        for (auto it = done.rbegin(); it != done.rend(); ++it) {
            std::error_code ec;
            if (it->backup.empty())
                fs::remove(it->target, ec);
            else
                fs::rename(it->backup, it->target, ec);
        }
        for (const fs::path& dir : createdDirs) {
            std::error_code ec;
            fs::remove(dir, ec);
        }
        throw;
    }
}

}  // namespace

std::vector<std::string> exportedFileNames(const GltfSceneInput& input) {
    std::vector<std::string> names;
    for (const auto* v : sortedVolumes(input)) {
        names.push_back((fs::path(kProbeDir) / (v->name + kProbeExt)).generic_string());
        if (!v->diagnostics.empty())
            names.push_back((fs::path(kProbeDir) / probeDiagnosticsFileName(v->name)).generic_string());
    }
    for (const GltfScenario& sc : input.scenarios)
        for (const auto* d : sortedVolumes(input))
            names.push_back(scenarioFileName(d->name, sc.name).generic_string());
    for (const auto& f : input.reflectionFiles)
        names.push_back((fs::path(kReflectionDir) / f.first).generic_string());
    if (input.scene) {
        if (input.heightfield && input.heightfield->width() >= 2 && input.heightfield->depth() >= 2)
            names.push_back(kBinName);
        names.push_back(kGltfName);
    }
    for (const auto& extra : input.extraFiles) names.push_back(extra.first);
    return names;
}

namespace {
void createOutputDirectory(const fs::path& outDir) {
    std::error_code ec;
    fs::create_directories(outDir, ec);
    if (ec || !fs::is_directory(outDir)) {
        throw FileWriteError(outDir.string() + ": cannot create the output directory (" +
                             (ec ? ec.message() : std::string("exists, not a directory")) + ")");
    }
}
}  // namespace

size_t checkTerrainMesh(const Heightfield& hf, size_t meshMaxVertices, const std::filesystem::path& gltfPath) {
    const size_t stride = chooseStride(hf, meshMaxVertices, gltfPath);
    const size_t nc = sampledLines(hf.width(), stride).size(), nr = sampledLines(hf.depth(), stride).size();
    const size_t vertexCount = nc * nr;
    if (vertexCount > size_t(std::numeric_limits<uint32_t>::max())) {
        throw std::runtime_error(gltfPath.string() + ": " + std::to_string(vertexCount) +
                                 " mesh vertices do not fit 32-bit indices");
    }
    const size_t indexCount = 6 * (nc - 1) * (nr - 1);
    const bool wideIndices = vertexCount > 65535;
    // Buffer views address bytes with 32-bit offsets in most loaders.
    const double binBytes = double(vertexCount) * 32.0 + double(indexCount) * (wideIndices ? 4 : 2);
    if (binBytes > double(std::numeric_limits<uint32_t>::max())) {
        char gib[32];
        std::snprintf(gib, sizeof gib, "%.1f", binBytes / double(1 << 30));
        throw std::runtime_error(gltfPath.string() + ": the terrain mesh of " + std::to_string(nc) + " x " +
                                 std::to_string(nr) + " vertices needs " + gib +
                                 " GiB, over the 4 GiB a glTF buffer can address; lower terrain.max_resolution");
    }
    return stride;
}

GltfExportResult exportGltfScene(const std::filesystem::path& outDir, const GltfSceneInput& input) {
    // Everything is encoded before the filesystem is touched.
    const std::vector<PendingFile> files = buildFiles(outDir, input);

    std::error_code ec;
    createOutputDirectory(outDir);

    const StagingDirectory staging(outDir);
    for (const fs::path& dir : subdirectories(files)) {
        fs::create_directory(staging.path() / dir, ec);
        if (ec) {
            throw FileWriteError((outDir / dir).string() + ": cannot create a staging directory (" +
                                 ec.message() + ")");
        }
    }
    GltfExportResult result;
    for (const PendingFile& f : files) {
        writeStaged(staging.path() / f.relative, outDir / f.relative, f);
        result.files.push_back(outDir / f.relative);
        result.bytes += f.size();
    }
    std::vector<std::string> owned{kGltfName, kBinName};
    for (const auto& extra : input.extraFiles) owned.push_back(extra.first);
    for (const auto& name : input.ownedFiles) owned.push_back(name);
    commit(outDir, staging.path(), files, staleOwnedFiles(outDir, files, owned));
    return result;
}

void writeFilesTogether(const std::filesystem::path& outDir,
                        const std::vector<std::pair<std::string, std::string>>& files) {
    std::vector<PendingFile> pending;
    for (const auto& [name, text] : files)
        pending.push_back({fs::path(name), std::vector<uint8_t>(text.begin(), text.end())});
    createOutputDirectory(outDir);
    const StagingDirectory staging(outDir);
    for (const PendingFile& f : pending) writeStaged(staging.path() / f.relative, outDir / f.relative, f);
    commit(outDir, staging.path(), pending, {});
}

nlohmann::json readShProbeGridEntries(const std::filesystem::path& gltfFile) {
    const std::string name = gltfFile.string();
    tinygltf::TinyGLTF loader;
    loader.SetStoreOriginalJSONForExtrasAndExtensions(true);
    tinygltf::Model model;
    std::string err, warn;
    const bool ok = loader.LoadASCIIFromFile(&model, &err, &warn, name);
    if (!ok || !err.empty()) {
        std::string reason = err.substr(0, err.find('\n'));
        throw std::runtime_error(name + ": cannot load as glTF (" +
                                 (reason.empty() ? std::string("unknown error") : reason) + ")");
    }
    // Seed 001's extension belongs to the scene an engine loads: the default scene, else the first.
    const int scene = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (size_t(scene) >= model.scenes.size())
        throw std::runtime_error(name + ": no scene to hold " + kEngineExtension);
    nlohmann::json extensions;
    try {
        extensions = nlohmann::json::parse(model.scenes[size_t(scene)].extensions_json_string);
    } catch (const nlohmann::json::exception&) {
        extensions = nullptr;
    }
    if (!extensions.is_object() || !extensions.contains(kEngineExtension) ||
        !extensions[kEngineExtension].is_object() ||
        !extensions[kEngineExtension].contains("shProbeGrids") ||
        !extensions[kEngineExtension]["shProbeGrids"].is_array()) {
        throw std::runtime_error(name + ": no " + kEngineExtension +
                                 ".shProbeGrids array in the scene's extensions");
    }
    return extensions[kEngineExtension]["shProbeGrids"];
}

}  // namespace terralux
