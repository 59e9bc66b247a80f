// glTF scene export: the docs/formats.md layout and extensions, the mesh (triangulation, winding,
// bounds, vertex budget, index width), exact probe-grid metadata, and all-or-nothing writes.

#include "GltfExport.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <gtest/gtest.h>
#include <tiny_gltf.h>
#include <unistd.h>

namespace fs = std::filesystem;
using nlohmann::json;
using namespace terralux;

namespace {

Heightfield makeHeightfield(int w, int d, double cellX = 2.0, double cellZ = 3.0) {
    std::vector<float> h(size_t(w) * size_t(d));
    for (int r = 0; r < d; ++r)
        for (int c = 0; c < w; ++c)
            h[size_t(r) * size_t(w) + size_t(c)] =
                float(100.0 + 7.0 * std::sin(0.7 * c) + 5.0 * std::cos(0.45 * r) + 0.25 * c * r);
    return Heightfield(w, d, cellX, cellZ, std::move(h));
}

// Awkward float values (not exactly representable in decimal) to catch any rounding on the way.
ShProbeGrid makeGrid(int seed) {
    ShProbeGrid g;
    g.dims = {3, 2, uint32_t(2 + seed)};
    g.origin = {-10.3f - float(seed), 0.1f, 7.7f * float(seed + 1)};
    g.spacing = 0.7f + 0.1f * float(seed);
    g.defaultScale = 1.3f;
    g.defaultAmbient = 0.1f / 3.0f;
    const size_t count = size_t(seed) + 2;
    for (size_t i = 0; i < count; ++i) {
        ShProbeRecord rec;
        for (size_t k = 0; k < 9; ++k)
            rec.coeffs[k] = glm::vec3(0.01f * float(k + i), -0.02f * float(seed), 0.3f);
        rec.scale = 1.0f + 0.1f * float(i);
        rec.ambient = 0.05f;
        g.probes.push_back(rec);
    }
    const size_t cells = size_t(g.dims.x) * g.dims.y * g.dims.z;
    for (size_t i = 0; i < cells; ++i)
        g.occupancy.push_back(int32_t(i % (count + 1)) - 1);
    return g;
}

std::string readText(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

std::vector<uint8_t> readBytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

json readJson(const fs::path& p) {
    std::ifstream in(p);
    return json::parse(in);
}

// Every regular file below `dir`, by relative path, with its bytes.
std::map<std::string, std::vector<uint8_t>> snapshot(const fs::path& dir) {
    std::map<std::string, std::vector<uint8_t>> files;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file())
            files[fs::relative(e.path(), dir).string()] = readBytes(e.path());
    return files;
}

bool hasStagingDir(const fs::path& dir) {
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().starts_with(".staging-"))
            return true;
    return false;
}

struct Loaded {
    tinygltf::Model model;
    std::string err, warn;
    bool ok = false;
};

Loaded load(const fs::path& gltf) {
    Loaded l;
    tinygltf::TinyGLTF loader;
    l.ok = loader.LoadASCIIFromFile(&l.model, &l.err, &l.warn, gltf.string());
    return l;
}

// Accessor contents as floats (FLOAT) or as indices (UNSIGNED_SHORT / UNSIGNED_INT).
std::vector<float> floatData(const tinygltf::Model& m, int accessor) {
    const tinygltf::Accessor& a = m.accessors[size_t(accessor)];
    const tinygltf::BufferView& v = m.bufferViews[size_t(a.bufferView)];
    const size_t n = a.count * size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)));
    std::vector<float> out(n);
    std::memcpy(out.data(), m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset,
                n * sizeof(float));
    return out;
}

std::vector<uint32_t> indexData(const tinygltf::Model& m, int accessor) {
    const tinygltf::Accessor& a = m.accessors[size_t(accessor)];
    const tinygltf::BufferView& v = m.bufferViews[size_t(a.bufferView)];
    const uint8_t* p = m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
    std::vector<uint32_t> out(a.count);
    for (size_t i = 0; i < a.count; ++i) {
        if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
            uint16_t s;
            std::memcpy(&s, p + 2 * i, 2);
            out[i] = s;
        } else {
            std::memcpy(&out[i], p + 4 * i, 4);
        }
    }
    return out;
}

glm::vec3 vec3At(const std::vector<float>& f, size_t i) {
    return {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
}

float asFloat(const json& j) {
    return float(j.get<double>());
}

uint32_t bits(float f) {
    return std::bit_cast<uint32_t>(f);
}

class GltfExport : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir = fs::temp_directory_path() /
              ("terralux_test_gltf_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir);
    }
    void TearDown() override { fs::remove_all(dir); }

    GltfSceneInput sampleInput(const Heightfield& hf) const {
        GltfSceneInput in;
        in.heightfield = &hf;
        in.albedo = {0.25f, 0.5f, 0.7f};
        in.roughness = 0.6f;
        in.verticalScale = 1.5;
        in.volumes.push_back({"zeta", makeGrid(1), {}});
        in.volumes.push_back({"alpha", makeGrid(0), {}});
        in.bake = {{"shEncoding", "L2 RGB"}, {"quality", "standard"}, {"rays", 256},
                   {"bounces", 2}, {"bakeSeconds", 12.625}, {"errorEstimate", 0.0123}};
        in.generatorVersion = "1.2.3";
        return in;
    }

    fs::path dir;
};

TEST_F(GltfExport, WritesTheLayoutAndTheContract) {
    Heightfield hf = makeHeightfield(5, 4);
    hf.geo.crsWkt = "PROJCS[\"WGS 84 / UTM zone 31N\"]";
    hf.geo.crsName = "WGS 84 / UTM zone 31N";
    hf.geo.epsg = 32631;
    hf.geo.easting = 431234.5;
    hf.geo.northing = 4623456.25;
    hf.geo.height = 812.5;
    const GltfSceneInput in = sampleInput(hf);
    const GltfExportResult res = exportGltfScene(dir, in);

    const std::vector<fs::path> expected = {dir / "sh_coeffs/alpha.shprobe",
                                            dir / "sh_coeffs/zeta.shprobe", dir / "scene.bin",
                                            dir / "scene.gltf"};
    EXPECT_EQ(res.files, expected);
    uint64_t total = 0;
    for (const fs::path& p : expected) {
        ASSERT_TRUE(fs::is_regular_file(p)) << p;
        total += fs::file_size(p);
    }
    EXPECT_EQ(res.bytes, total);
    EXPECT_FALSE(hasStagingDir(dir));

    Loaded l = load(dir / "scene.gltf");
    ASSERT_TRUE(l.ok) << l.err;
    EXPECT_EQ(l.err, "");
    EXPECT_EQ(l.warn, "");
    const tinygltf::Model& m = l.model;
    for (const char* ext : {"VULKAN_SCHNEE_engine_properties", "TERRALUX_geo", "TERRALUX_bake"})
        EXPECT_NE(std::find(m.extensionsUsed.begin(), m.extensionsUsed.end(), ext),
                  m.extensionsUsed.end())
            << ext;
    EXPECT_TRUE(m.extensionsRequired.empty());
    EXPECT_EQ(m.asset.version, "2.0");
    EXPECT_EQ(m.asset.generator, "Terralux 1.2.3");

    // Probe grids: sorted by file name, every field equal to the file's header, bit for bit.
    const json entries = readShProbeGridEntries(dir / "scene.gltf");
    ASSERT_EQ(entries.size(), 2u);
    EXPECT_EQ(entries[0]["volumeName"], "alpha");
    EXPECT_EQ(entries[1]["volumeName"], "zeta");
    for (const json& e : entries) {
        const std::string name = e["volumeName"];
        EXPECT_EQ(e["shProbePath"], "sh_coeffs/" + name + ".shprobe");
        const ShProbeGrid file = readShProbeFile(dir / e["shProbePath"].get<std::string>());
        EXPECT_EQ(file, name == "alpha" ? makeGrid(0) : makeGrid(1));
        EXPECT_EQ(e["probeCount"].get<uint64_t>(), file.probes.size());
        ASSERT_EQ(e["gridDimensions"].size(), 3u);
        ASSERT_EQ(e["gridOrigin"].size(), 3u);
        for (int a = 0; a < 3; ++a) {
            EXPECT_EQ(e["gridDimensions"][size_t(a)].get<uint32_t>(), file.dims[a]);
            EXPECT_EQ(bits(asFloat(e["gridOrigin"][size_t(a)])), bits(file.origin[a]));
        }
        EXPECT_EQ(bits(asFloat(e["gridSpacing"])), bits(file.spacing));
        EXPECT_EQ(bits(asFloat(e["defaultScale"])), bits(file.defaultScale));
        EXPECT_EQ(bits(asFloat(e["defaultAmbient"])), bits(file.defaultAmbient));
        EXPECT_EQ(e.size(), 8u);
    }

    // Our own extensions.
    const json doc = readJson(dir / "scene.gltf");
    EXPECT_FALSE(doc.contains("extensionsRequired"));
    // Seed 001's extension and ours are scene-level: in the default scene, none at the root.
    ASSERT_EQ(doc["scene"], 0);
    EXPECT_EQ(doc["scenes"][0]["extensions"]["VULKAN_SCHNEE_engine_properties"]["shProbeGrids"], entries);
    EXPECT_FALSE(doc.contains("extensions"));
    const json& geo = doc["scenes"][0]["extensions"]["TERRALUX_geo"];
    EXPECT_EQ(geo["crs"], hf.geo.crsWkt);
    EXPECT_EQ(geo["crsName"], "WGS 84 / UTM zone 31N");
    EXPECT_EQ(geo["epsg"], 32631);
    EXPECT_EQ(geo["originEasting"].get<double>(), 431234.5);
    EXPECT_EQ(geo["originNorthing"].get<double>(), 4623456.25);
    EXPECT_EQ(geo["originHeight"].get<double>(), 812.5);
    EXPECT_EQ(geo["verticalScale"].get<double>(), 1.5);
    EXPECT_EQ(geo["cellSize"], json({2.0, 3.0}));
    EXPECT_EQ(geo["gridSize"], json({5, 4}));
    EXPECT_EQ(geo["meshStride"], 1);
    EXPECT_EQ(doc["scenes"][0]["extensions"]["TERRALUX_bake"], in.bake);
    // No lighting given, no lighting extension.
    EXPECT_FALSE(doc["scenes"][0]["extensions"].contains("TERRALUX_lighting"));
    EXPECT_EQ(std::count(m.extensionsUsed.begin(), m.extensionsUsed.end(), "TERRALUX_lighting"), 0);

    // One node with the terrain mesh in the default scene.
    ASSERT_EQ(m.meshes.size(), 1u);
    ASSERT_EQ(m.meshes[0].primitives.size(), 1u);
    ASSERT_GE(m.defaultScene, 0);
    EXPECT_EQ(m.scenes[size_t(m.defaultScene)].nodes, std::vector<int>{0});
    EXPECT_EQ(m.nodes[0].mesh, 0);
    const tinygltf::Primitive& prim = m.meshes[0].primitives[0];
    EXPECT_EQ(prim.mode, TINYGLTF_MODE_TRIANGLES);
    const tinygltf::Accessor& pos = m.accessors[size_t(prim.attributes.at("POSITION"))];
    const tinygltf::Accessor& idx = m.accessors[size_t(prim.indices)];
    EXPECT_EQ(pos.count, 20u);
    EXPECT_EQ(idx.count, 72u);
    EXPECT_EQ(idx.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);

    // Vertices in engine space, row-major; smooth normals; UVs over the grid.
    const std::vector<float> p = floatData(m, prim.attributes.at("POSITION"));
    const std::vector<float> n = floatData(m, prim.attributes.at("NORMAL"));
    const std::vector<float> uv = floatData(m, prim.attributes.at("TEXCOORD_0"));
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 5; ++c) {
            const size_t v = size_t(r) * 5 + size_t(c);
            EXPECT_EQ(vec3At(p, v), hf.vertex(c, r)) << c << "," << r;
            EXPECT_EQ(vec3At(n, v), hf.vertexNormal(c, r)) << c << "," << r;
            EXPECT_FLOAT_EQ(uv[2 * v], float(c) / 4.0f);
            EXPECT_FLOAT_EQ(uv[2 * v + 1], float(r) / 3.0f);
        }
    }

    // The bake's diagonal: (c,r),(c,r+1),(c+1,r+1) and (c,r),(c+1,r+1),(c+1,r).
    const std::vector<uint32_t> ind = indexData(m, prim.indices);
    EXPECT_EQ(std::vector<uint32_t>(ind.begin(), ind.begin() + 6),
              (std::vector<uint32_t>{0, 5, 6, 0, 6, 1}));
    // Counter-clockwise seen from +Y: every geometric normal points up.
    for (size_t t = 0; t < ind.size(); t += 3) {
        const glm::vec3 a = vec3At(p, ind[t]), b = vec3At(p, ind[t + 1]), c = vec3At(p, ind[t + 2]);
        EXPECT_GT(glm::cross(b - a, c - a).y, 0.0f) << "triangle " << t / 3;
    }

    ASSERT_EQ(pos.minValues.size(), 3u);
    ASSERT_EQ(pos.maxValues.size(), 3u);
    EXPECT_EQ(float(pos.minValues[0]), hf.minX());
    EXPECT_EQ(float(pos.maxValues[0]), hf.maxX());
    EXPECT_EQ(float(pos.minValues[1]), hf.minHeight());
    EXPECT_EQ(float(pos.maxValues[1]), hf.maxHeight());
    EXPECT_EQ(float(pos.minValues[2]), hf.minZ());
    EXPECT_EQ(float(pos.maxValues[2]), hf.maxZ());

    ASSERT_EQ(m.materials.size(), 1u);
    EXPECT_EQ(prim.material, 0);
    const tinygltf::PbrMetallicRoughness& pbr = m.materials[0].pbrMetallicRoughness;
    EXPECT_EQ(pbr.baseColorFactor, (std::vector<double>{0.25, 0.5, double(0.7f), 1.0}));
    EXPECT_EQ(pbr.metallicFactor, 0.0);
    EXPECT_EQ(pbr.roughnessFactor, double(0.6f));  // terrain.roughness
}

TEST_F(GltfExport, LightingIsWrittenVerbatimAsAnOptionalExtension) {
    const Heightfield hf = makeHeightfield(5, 4);
    GltfSceneInput in = sampleInput(hf);
    in.lighting = {{"sun", {{"direction", {0.0, 1.0, 0.0}}, {"illuminance", 3.0}}},
                   {"exposure_ev", -0.5}};
    exportGltfScene(dir, in);
    const json doc = readJson(dir / "scene.gltf");
    EXPECT_EQ(doc["scenes"][0]["extensions"]["TERRALUX_lighting"], in.lighting);
    EXPECT_EQ(doc["extensionsUsed"], json({"VULKAN_SCHNEE_engine_properties", "TERRALUX_geo",
                                           "TERRALUX_bake", "TERRALUX_lighting"}));
    EXPECT_FALSE(doc.contains("extensionsRequired"));
    Loaded l = load(dir / "scene.gltf");
    ASSERT_TRUE(l.ok) << l.err;
    EXPECT_EQ(l.warn, "");
}

TEST_F(GltfExport, GridsAreSortedByFileNameNotByStem) {
    const Heightfield hf = makeHeightfield(3, 3);
    GltfSceneInput in;
    in.heightfield = &hf;
    for (const char* name : {"a", "a-b", "B"})
        in.volumes.push_back({name, makeGrid(0), {}});
    exportGltfScene(dir, in);
    const json entries = readShProbeGridEntries(dir / "scene.gltf");
    ASSERT_EQ(entries.size(), 3u);
    // "B.shprobe" < "a-b.shprobe" < "a.shprobe" ('-' sorts before '.').
    EXPECT_EQ(entries[0]["volumeName"], "B");
    EXPECT_EQ(entries[1]["volumeName"], "a-b");
    EXPECT_EQ(entries[2]["volumeName"], "a");
}

TEST_F(GltfExport, VertexBudgetTakesEveryKthLineAndKeepsTheLast) {
    const Heightfield hf = makeHeightfield(300, 200);
    GltfSceneInput in;
    in.heightfield = &hf;
    in.meshMaxVertices = 10000;
    exportGltfScene(dir, in);

    // Stride 2 needs 151 x 101 = 15251 vertices; stride 3 needs 101 x 68 = 6868
    // (columns 0, 3, ..., 297, 299 and rows 0, 3, ..., 198, 199).
    const json doc = readJson(dir / "scene.gltf");
    EXPECT_EQ(doc["scenes"][0]["extensions"]["TERRALUX_geo"]["meshStride"], 3);
    EXPECT_EQ(doc["scenes"][0]["extensions"]["TERRALUX_geo"]["gridSize"], json({300, 200}));
    Loaded l = load(dir / "scene.gltf");
    ASSERT_TRUE(l.ok) << l.err;
    EXPECT_EQ(l.warn, "");
    const tinygltf::Primitive& prim = l.model.meshes[0].primitives[0];
    const int posAcc = prim.attributes.at("POSITION");
    ASSERT_EQ(l.model.accessors[size_t(posAcc)].count, 6868u);
    EXPECT_EQ(l.model.accessors[size_t(prim.indices)].count, 6u * 100 * 67);

    const std::vector<float> p = floatData(l.model, posAcc);
    const std::vector<float> uv = floatData(l.model, prim.attributes.at("TEXCOORD_0"));
    const size_t nc = 101, nr = 68;
    EXPECT_EQ(vec3At(p, 1), hf.vertex(3, 0));
    EXPECT_EQ(vec3At(p, nc - 2), hf.vertex(297, 0));
    EXPECT_EQ(vec3At(p, nc - 1), hf.vertex(299, 0));
    EXPECT_EQ(vec3At(p, nc), hf.vertex(0, 3));
    EXPECT_EQ(vec3At(p, (nr - 2) * nc), hf.vertex(0, 198));
    EXPECT_EQ(vec3At(p, nr * nc - 1), hf.vertex(299, 199));
    EXPECT_EQ(uv[2 * (nr * nc - 1)], 1.0f);
    EXPECT_EQ(uv[2 * (nr * nc - 1) + 1], 1.0f);
    const tinygltf::Accessor& pos = l.model.accessors[size_t(posAcc)];
    EXPECT_EQ(float(pos.maxValues[0]), hf.maxX());
    EXPECT_EQ(float(pos.maxValues[2]), hf.maxZ());

    // Within budget: full resolution.
    in.meshMaxVertices = 60000;
    exportGltfScene(dir, in);
    EXPECT_EQ(readJson(dir / "scene.gltf")["scenes"][0]["extensions"]["TERRALUX_geo"]["meshStride"], 1);
    EXPECT_EQ(readJson(dir / "scene.gltf")["accessors"][0]["count"], 60000);
}

// A terrain whose mesh a glTF buffer cannot hold (4 GiB) is refused by the rule the export and
// the bake share, which the bake asks before it traces anything: 9 000² vertices need 4.2 GiB,
// and the same grid at every second line fits.
TEST_F(GltfExport, ATerrainMeshOverFourGibIsRefusedBeforeTheExport) {
    EXPECT_EQ(checkTerrainMesh(makeHeightfield(300, 200), 10000, dir / "scene.gltf"), 3u);  // as above
    const Heightfield big(9000, 9000, 1.0, 1.0, std::vector<float>(size_t(9000) * 9000, 0.0f));
    try {
        checkTerrainMesh(big, std::numeric_limits<size_t>::max(), dir / "scene.gltf");
        ADD_FAILURE() << "a 4.2 GiB mesh was accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), (dir / "scene.gltf").string() +
                                             ": the terrain mesh of 9000 x 9000 vertices needs 4.2 GiB, over the 4 GiB a "
                                             "glTF buffer can address; lower terrain.max_resolution");
    }
    EXPECT_EQ(checkTerrainMesh(big, size_t(4501) * 4501, dir / "scene.gltf"), 2u);  // lines 0, 2, ..., 8998, 8999
}

TEST_F(GltfExport, IndexWidthFollowsTheVertexCount) {
    // 65535 vertices: the largest index is 65534, below the 16-bit restart value.
    const Heightfield narrow = makeHeightfield(255, 257);
    // 65536 vertices need 32-bit indices.
    const Heightfield wide = makeHeightfield(256, 256);
    for (const auto& [hf, type] : {std::pair{&narrow, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                                   std::pair{&wide, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT}}) {
        GltfSceneInput in;
        in.heightfield = hf;
        exportGltfScene(dir, in);
        Loaded l = load(dir / "scene.gltf");
        ASSERT_TRUE(l.ok) << l.err;
        const tinygltf::Primitive& prim = l.model.meshes[0].primitives[0];
        const tinygltf::Accessor& idx = l.model.accessors[size_t(prim.indices)];
        EXPECT_EQ(idx.componentType, type);
        const std::vector<uint32_t> ind = indexData(l.model, prim.indices);
        EXPECT_EQ(*std::max_element(ind.begin(), ind.end()),
                  uint32_t(hf->width() * hf->depth() - 1));
    }
}

TEST_F(GltfExport, FailedEncodingLeavesThePreviousExportUntouched) {
    const Heightfield hf = makeHeightfield(5, 4);
    GltfSceneInput in = sampleInput(hf);
    exportGltfScene(dir, in);
    const auto before = snapshot(dir);

    in.volumes[1].grid = makeGrid(3);  // would change alpha.shprobe
    ShProbeGrid bad = makeGrid(0);
    bad.occupancy.pop_back();
    in.volumes.push_back({"bad", bad, {}});
    in.albedo = glm::vec3(0.9f);
    try {
        exportGltfScene(dir, in);
        FAIL() << "an invalid grid must fail the export";
    } catch (const ShProbeError& e) {
        EXPECT_NE(std::string(e.what()).find("sh_coeffs/bad.shprobe: occupancy has"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_EQ(snapshot(dir), before);
    EXPECT_FALSE(hasStagingDir(dir));
}

TEST_F(GltfExport, FailedReplaceRestoresTheFilesAlreadyMoved) {
    const Heightfield hf = makeHeightfield(5, 4);
    GltfSceneInput in = sampleInput(hf);
    exportGltfScene(dir, in);
    // zz.shprobe is committed after alpha.shprobe and zeta.shprobe, and cannot replace a directory.
    fs::create_directory(dir / "sh_coeffs/zz.shprobe");
    const auto before = snapshot(dir);
    ASSERT_EQ(before.size(), 4u);

    in.volumes[0].grid = makeGrid(2);
    in.volumes[1].grid = makeGrid(3);
    in.volumes.push_back({"zz", makeGrid(1), {}});
    try {
        exportGltfScene(dir, in);
        FAIL() << "replacing a directory must fail the export";
    } catch (const FileWriteError& e) {
        EXPECT_NE(std::string(e.what()).find("sh_coeffs/zz.shprobe: cannot replace"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_EQ(snapshot(dir), before);
    EXPECT_FALSE(hasStagingDir(dir));
    EXPECT_EQ(readShProbeFile(dir / "sh_coeffs/alpha.shprobe"), makeGrid(0));
}

TEST_F(GltfExport, FailureInAFreshDirectoryLeavesNothingBehind) {
    const Heightfield hf = makeHeightfield(5, 4);
    fs::create_directories(dir / "scene.gltf");  // the last file to be moved into place
    EXPECT_THROW(exportGltfScene(dir, sampleInput(hf)), FileWriteError);
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir))
        names.push_back(e.path().filename().string());
    EXPECT_EQ(names, std::vector<std::string>{"scene.gltf"});
    EXPECT_TRUE(fs::is_empty(dir / "scene.gltf"));
}

TEST_F(GltfExport, OwnedFilesAreReplacedAsAWholeAndNothingElseIsTouched) {
    const Heightfield hf = makeHeightfield(5, 4);
    GltfSceneInput in = sampleInput(hf);
    in.extraFiles = {{"bake_report.json", "{\"first\": true}\n"}};
    exportGltfScene(dir, in);
    ASSERT_TRUE(fs::exists(dir / "sh_coeffs/zeta.shprobe"));
    // Files the user keeps beside the bake.
    std::ofstream(dir / "notes.txt") << "mine";
    fs::create_directories(dir / "sh_coeffs/keep");

    // "zeta" renamed away, and the scene switched off: engines must not find the old files.
    in.volumes = {{"alpha", makeGrid(4), {}}};
    in.scene = false;
    in.extraFiles = {{"bake_report.json", "{\"second\": true}\n"}};
    const GltfExportResult res = exportGltfScene(dir, in);
    EXPECT_EQ(res.files, (std::vector<fs::path>{dir / "sh_coeffs/alpha.shprobe", dir / "bake_report.json"}));
    EXPECT_EQ(exportedFileNames(in), (std::vector<std::string>{"sh_coeffs/alpha.shprobe", "bake_report.json"}));
    EXPECT_FALSE(fs::exists(dir / "sh_coeffs/zeta.shprobe"));
    EXPECT_FALSE(fs::exists(dir / "scene.gltf"));
    EXPECT_FALSE(fs::exists(dir / "scene.bin"));
    EXPECT_EQ(readShProbeFile(dir / "sh_coeffs/alpha.shprobe"), makeGrid(4));
    EXPECT_EQ(readText(dir / "bake_report.json"), "{\"second\": true}\n");
    EXPECT_EQ(readText(dir / "notes.txt"), "mine");
    EXPECT_TRUE(fs::is_directory(dir / "sh_coeffs/keep"));
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".staging"), std::string::npos);
}

TEST_F(GltfExport, AFailedCommitPutsTheRemovedFilesBack) {
    const Heightfield hf = makeHeightfield(5, 4);
    GltfSceneInput in = sampleInput(hf);
    in.extraFiles = {{"bake_report.json", "old\n"}};
    exportGltfScene(dir, in);
    const auto zeta = readBytes(dir / "sh_coeffs/zeta.shprobe");
    const auto gltf = readBytes(dir / "scene.gltf");
    // The report cannot be replaced (a directory stands in its place after the first export).
    fs::remove(dir / "bake_report.json");
    fs::create_directories(dir / "bake_report.json");
    in.volumes = {{"alpha", makeGrid(4), {}}};
    EXPECT_THROW(exportGltfScene(dir, in), FileWriteError);
    EXPECT_EQ(readBytes(dir / "sh_coeffs/zeta.shprobe"), zeta);
    EXPECT_EQ(readBytes(dir / "scene.gltf"), gltf);
}

TEST_F(GltfExport, HeightfieldsWithoutTrianglesExportAMeshlessScene) {
    for (const auto& [w, d] : {std::pair{1, 1}, std::pair{1, 6}, std::pair{6, 1}}) {
        SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(d));
        fs::remove_all(dir);
        const Heightfield hf = makeHeightfield(w, d);
        GltfSceneInput in = sampleInput(hf);
        const GltfExportResult res = exportGltfScene(dir, in);
        EXPECT_EQ(res.files, (std::vector<fs::path>{dir / "sh_coeffs/alpha.shprobe",
                                                    dir / "sh_coeffs/zeta.shprobe",
                                                    dir / "scene.gltf"}));
        EXPECT_FALSE(fs::exists(dir / "scene.bin"));
        Loaded l = load(dir / "scene.gltf");
        ASSERT_TRUE(l.ok) << l.err;
        EXPECT_EQ(l.err, "");
        EXPECT_EQ(l.warn, "");
        EXPECT_TRUE(l.model.meshes.empty());
        EXPECT_TRUE(l.model.buffers.empty());
        EXPECT_TRUE(l.model.accessors.empty());
        EXPECT_EQ(readShProbeGridEntries(dir / "scene.gltf").size(), 2u);
        const json geo = readJson(dir / "scene.gltf")["scenes"][0]["extensions"]["TERRALUX_geo"];
        EXPECT_EQ(geo["gridSize"], json({w, d}));
        EXPECT_EQ(geo["meshStride"], 1);
    }
}

TEST_F(GltfExport, RejectsInvalidInputBeforeWritingAnything) {
    const Heightfield hf = makeHeightfield(5, 4);
    auto expectRejected = [&](GltfSceneInput in, const std::string& fragment) {
        try {
            exportGltfScene(dir, in);
            ADD_FAILURE() << "expected a failure mentioning " << fragment;
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        }
        EXPECT_FALSE(fs::exists(dir));
    };
    GltfSceneInput in = sampleInput(hf);
    in.heightfield = nullptr;
    expectRejected(in, "scene.gltf: no terrain");
    in = sampleInput(hf);
    in.volumes[0].name = "../evil";
    expectRejected(in, "probe volume name '../evil'");
    in = sampleInput(hf);
    in.volumes[0].name = "";
    expectRejected(in, "probe volume name ''");
    in = sampleInput(hf);
    in.volumes[0].name = "alpha";
    expectRejected(in, "alpha.shprobe: two probe volumes are named 'alpha'");
    in = sampleInput(hf);
    in.albedo.g = 1.5f;
    expectRejected(in, "albedo channel 1");
    in = sampleInput(hf);
    in.roughness = std::nanf("");
    expectRejected(in, "roughness = nan must be in [0, 1]");
    in = sampleInput(hf);
    in.bake = json::array();
    expectRejected(in, "TERRALUX_bake metadata must be a JSON object");
    in = sampleInput(hf);
    in.lighting = json::array();
    expectRejected(in, "TERRALUX_lighting metadata must be a JSON object or null");
    in = sampleInput(hf);
    in.verticalScale = std::nan("");
    expectRejected(in, "scene.gltf: the vertical scale and the geo origin must be finite");
    in = sampleInput(hf);
    in.meshMaxVertices = 3;
    expectRejected(in, "meshMaxVertices = 3");
}

}  // namespace

// export.gltf off: the probe files and their sidecars only, through the same staged commit.
TEST_F(GltfExport, SceneOffWritesOnlyTheProbeFilesAndSidecars) {
    const Heightfield hf = makeHeightfield(5, 4);
    GltfSceneInput in = sampleInput(hf);
    in.scene = false;
    in.volumes[0].diagnostics = "{\"volume\": \"zeta\"}\n";
    const GltfExportResult res = exportGltfScene(dir, in);
    const std::vector<fs::path> expected = {dir / "sh_coeffs/alpha.shprobe", dir / "sh_coeffs/zeta.shprobe",
                                            dir / "sh_coeffs/zeta.probes.json"};
    EXPECT_EQ(res.files, expected);
    EXPECT_FALSE(fs::exists(dir / "scene.gltf"));
    EXPECT_FALSE(fs::exists(dir / "scene.bin"));
    EXPECT_EQ(readShProbeFile(dir / "sh_coeffs/zeta.shprobe"), in.volumes[0].grid);
    std::ifstream sidecar(dir / "sh_coeffs/zeta.probes.json");
    std::string text((std::istreambuf_iterator<char>(sidecar)), {});
    EXPECT_EQ(text, in.volumes[0].diagnostics);
    // Nothing staged is left behind.
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        EXPECT_TRUE(name.find(".tmp") == std::string::npos && name.find(".staging") == std::string::npos)
            << e.path();
    }
}

// The bake traces every DEM sample, so the exported mesh has them all, whatever the size.
TEST_F(GltfExport, TheMeshIsTheTracedSurfaceAboveAMillionVertices) {
    Heightfield hf = makeHeightfield(1100, 1000);
    GltfSceneInput in = sampleInput(hf);
    exportGltfScene(dir, in);
    const json doc = readJson(dir / "scene.gltf");
    EXPECT_EQ(doc["scenes"][0]["extensions"]["TERRALUX_geo"]["meshStride"], 1);
    const json& prim = doc["meshes"][0]["primitives"][0];
    const json& position = doc["accessors"][prim["attributes"]["POSITION"].get<int>()];
    EXPECT_EQ(position["count"], 1100 * 1000);
    EXPECT_FLOAT_EQ(position["max"][1].get<float>(), hf.maxHeight());
    EXPECT_FLOAT_EQ(position["min"][1].get<float>(), hf.minHeight());
    const json& indices = doc["accessors"][prim["indices"].get<int>()];
    EXPECT_EQ(indices["componentType"], 5125);  // UNSIGNED_INT
    EXPECT_EQ(indices["count"], 6 * 1099 * 999);
    // Every vertex and index as read back: the writer fills windows of rows in parallel (the
    // indices here span two of them), and must put every row in its place.
    Loaded l = load(dir / "scene.gltf");
    ASSERT_TRUE(l.ok) << l.err;
    const tinygltf::Primitive& p = l.model.meshes[0].primitives[0];
    const std::vector<float> pos = floatData(l.model, p.attributes.at("POSITION"));
    const std::vector<float> nrm = floatData(l.model, p.attributes.at("NORMAL"));
    const std::vector<uint32_t> ind = indexData(l.model, p.indices);
    size_t wrong = 0;
    for (int r = 0; r < 1000; ++r)
        for (int c = 0; c < 1100; ++c) {
            const size_t v = size_t(r) * 1100 + size_t(c);
            wrong += vec3At(pos, v) != hf.vertex(c, r) || vec3At(nrm, v) != hf.vertexNormal(c, r);
        }
    EXPECT_EQ(wrong, 0u) << "vertices";
    ASSERT_EQ(ind.size(), size_t(6) * 1099 * 999);
    wrong = 0;
    for (size_t r = 0; r < 999; ++r)
        for (size_t c = 0; c < 1099; ++c) {
            const uint32_t v = uint32_t(r * 1100 + c);
            const uint32_t expected[6] = {v, v + 1100, v + 1101, v, v + 1101, v + 1};
            wrong += !std::equal(expected, expected + 6, ind.begin() + std::ptrdiff_t(6 * (r * 1099 + c)));
        }
    EXPECT_EQ(wrong, 0u) << "cells";
}

TEST_F(GltfExport, AnAlbedoFieldIsAnEmbeddedSrgbPngWithUvsOnItsTexelCentres) {
    const Heightfield hf = makeHeightfield(5, 4);
    SurfaceAlbedo field;
    field.resize(3, 2);
    const glm::vec3 linear[] = {glm::vec3(0.0f), glm::vec3(0.5f, 0.2f, 0.1f), glm::vec3(1.0f),
                                glm::vec3(0.21586050f), glm::vec3(0.8f, 0.82f, 0.85f), glm::vec3(0.0031308f)};
    for (size_t i = 0; i < 6; ++i) field.setTexel(i, linear[i]);
    GltfSceneInput in = sampleInput(hf);
    in.albedoTexture = &field;
    const GltfExportResult res = exportGltfScene(dir, in);
    // Still the two scene files: the image lives in scene.bin.
    EXPECT_EQ(res.files.size(), 4u);

    Loaded l = load(dir / "scene.gltf");
    ASSERT_TRUE(l.ok) << l.err;
    EXPECT_EQ(l.warn, "");
    const tinygltf::Model& m = l.model;
    const tinygltf::PbrMetallicRoughness& pbr = m.materials.at(0).pbrMetallicRoughness;
    EXPECT_EQ(pbr.baseColorTexture.index, 0);
    EXPECT_EQ(pbr.baseColorTexture.texCoord, 0);
    EXPECT_EQ(pbr.baseColorFactor, std::vector<double>({1.0, 1.0, 1.0, 1.0}));
    const tinygltf::Image& image = m.images.at(size_t(m.textures.at(0).source));
    EXPECT_EQ(image.mimeType, "image/png");
    ASSERT_EQ(image.width, 3);
    ASSERT_EQ(image.height, 2);
    ASSERT_GE(image.component, 3);
    // Each texel is the sRGB encoding of its linear albedo, row 0 (north) first.
    for (size_t i = 0; i < 6; ++i)
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(int(image.image.at(i * size_t(image.component) + size_t(c))),
                      int(std::lround(linearToSrgb(linear[i][c]) * 255.0f)))
                << "texel " << i << " channel " << c;
    EXPECT_EQ(int(image.image[3 * size_t(image.component)]), 128);  // 0.21586050 is sRGB 128/255

    // Vertex (col, row) samples the field where SurfaceAlbedo::at does: corners on corner texel
    // centres, the middle column on the middle texel's centre.
    const auto& prim = m.meshes.at(0).primitives.at(0);
    const std::vector<float> uv = floatData(m, prim.attributes.at("TEXCOORD_0"));
    ASSERT_EQ(uv.size(), size_t(2 * 5 * 4));
    auto at = [&](int col, int row) { return glm::vec2(uv[2 * size_t(row * 5 + col)], uv[2 * size_t(row * 5 + col) + 1]); };
    EXPECT_FLOAT_EQ(at(0, 0).x, 0.5f / 3.0f);
    EXPECT_FLOAT_EQ(at(0, 0).y, 0.5f / 2.0f);
    EXPECT_FLOAT_EQ(at(2, 0).x, 0.5f);
    EXPECT_FLOAT_EQ(at(4, 3).x, 1.0f - 0.5f / 3.0f);
    EXPECT_FLOAT_EQ(at(4, 3).y, 1.0f - 0.5f / 2.0f);

    // An empty field is the constant material, as before.
    SurfaceAlbedo empty;
    in.albedoTexture = &empty;
    exportGltfScene(dir, in);
    const json doc = readJson(dir / "scene.gltf");
    EXPECT_FALSE(doc["materials"][0]["pbrMetallicRoughness"].contains("baseColorTexture"));
    EXPECT_FALSE(doc.contains("images"));
}

TEST_F(GltfExport, WaterIsAPlaneOverTheFootprintWithATransmissiveMaterial) {
    const Heightfield hf = makeHeightfield(9, 7);  // 2 x 3 m cells: x in [-8, 8], z in [-9, 9]
    GltfSceneInput in = sampleInput(hf);
    // Without water: the terrain alone, and bytes that do not depend on the water's existence.
    exportGltfScene(dir, in);
    const std::vector<uint8_t> dryBin = readBytes(dir / "scene.bin");
    const json dry = readJson(dir / "scene.gltf");
    EXPECT_EQ(dry["nodes"].size(), 1u);
    EXPECT_EQ(dry["extensionsUsed"], json({"VULKAN_SCHNEE_engine_properties", "TERRALUX_geo", "TERRALUX_bake"}));

    in.water = GltfWater{104.5f, {0.02f, 0.05f, 0.25f}, 0.1f};
    exportGltfScene(dir, in);
    const json doc = readJson(dir / "scene.gltf");
    EXPECT_EQ(doc["extensionsUsed"],
              json({"VULKAN_SCHNEE_engine_properties", "TERRALUX_geo", "TERRALUX_bake",
                    "KHR_materials_transmission", "KHR_materials_ior"}));
    EXPECT_FALSE(doc.contains("extensionsRequired"));
    Loaded l = load(dir / "scene.gltf");
    ASSERT_TRUE(l.ok) << l.err;
    EXPECT_EQ(l.warn, "");
    const tinygltf::Model& m = l.model;
    ASSERT_EQ(m.nodes.size(), 2u);
    EXPECT_EQ(m.scenes[0].nodes, (std::vector<int>{0, 1}));
    EXPECT_EQ(m.nodes[1].name, "water");
    const tinygltf::Mesh& mesh = m.meshes[size_t(m.nodes[1].mesh)];
    EXPECT_EQ(mesh.name, "water");
    ASSERT_EQ(mesh.primitives.size(), 1u);
    const tinygltf::Primitive& prim = mesh.primitives[0];
    const std::vector<float> pos = floatData(m, prim.attributes.at("POSITION"));
    const std::vector<float> nrm = floatData(m, prim.attributes.at("NORMAL"));
    const std::vector<uint32_t> idx = indexData(m, prim.indices);
    ASSERT_EQ(pos.size(), 12u);
    ASSERT_EQ(idx.size(), 6u);
    // The footprint's corners at the level, up-facing, two triangles counter-clockwise from +Y.
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (size_t i = 0; i < 4; ++i) {
        lo = glm::min(lo, vec3At(pos, i));
        hi = glm::max(hi, vec3At(pos, i));
        EXPECT_EQ(vec3At(nrm, i), glm::vec3(0, 1, 0));
    }
    EXPECT_EQ(lo, glm::vec3(hf.minX(), 104.5f, hf.minZ()));
    EXPECT_EQ(hi, glm::vec3(hf.maxX(), 104.5f, hf.maxZ()));
    double area = 0.0;
    for (size_t t = 0; t < 2; ++t) {
        const glm::vec3 a = vec3At(pos, idx[3 * t]), b = vec3At(pos, idx[3 * t + 1]), c = vec3At(pos, idx[3 * t + 2]);
        const glm::vec3 n = glm::cross(b - a, c - a);
        EXPECT_GT(n.y, 0.0f) << "triangle " << t;
        area += 0.5 * n.y;
    }
    EXPECT_NEAR(area, (hf.maxX() - hf.minX()) * (hf.maxZ() - hf.minZ()), 1e-3);
    // The material: base colour and roughness, transmission and water's index of refraction.
    const json& mat = doc["materials"][size_t(prim.material)];
    EXPECT_EQ(mat["name"], "water");
    EXPECT_EQ(mat["pbrMetallicRoughness"]["baseColorFactor"], json({double(0.02f), double(0.05f), double(0.25f), 1.0}));
    EXPECT_EQ(mat["pbrMetallicRoughness"]["roughnessFactor"], double(0.1f));
    EXPECT_EQ(mat["pbrMetallicRoughness"]["metallicFactor"], 0.0);
    EXPECT_EQ(mat["extensions"]["KHR_materials_transmission"]["transmissionFactor"], 1.0);
    EXPECT_EQ(mat["extensions"]["KHR_materials_ior"]["ior"], 1.33);
    // The terrain's part of scene.bin is what it was without water.
    const std::vector<uint8_t> wetBin = readBytes(dir / "scene.bin");
    ASSERT_GT(wetBin.size(), dryBin.size());
    EXPECT_TRUE(std::equal(dryBin.begin(), dryBin.end(), wetBin.begin()));
    EXPECT_EQ(doc["buffers"][0]["byteLength"], wetBin.size());

    // A heightfield with no footprint has no water plane either; a bad plane is refused.
    fs::remove_all(dir);
    const Heightfield line = makeHeightfield(6, 1);
    GltfSceneInput meshless = sampleInput(line);
    meshless.water = in.water;
    exportGltfScene(dir, meshless);
    EXPECT_FALSE(readJson(dir / "scene.gltf").contains("nodes"));
    fs::remove_all(dir);
    GltfSceneInput bad = in;
    bad.water->level = NAN;
    EXPECT_THROW(exportGltfScene(dir, bad), std::runtime_error);
    bad.water = GltfWater{1.0f, {0.5f, 1.5f, 0.0f}, 0.1f};
    EXPECT_THROW(exportGltfScene(dir, bad), std::runtime_error);
    EXPECT_FALSE(fs::exists(dir / "scene.gltf"));
}
