// Reflection probes: placement, the cube bake and its encodings, the .rprobe file and the simvx
// box records (docs/lighting.md and docs/formats.md, "Reflection probes").

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>

#include <glm/geometric.hpp>
#include <tbb/global_control.h>

#include "ReflectionProbeFile.h"
#include "TestScenes.h"
#include "bake/ReflectionBake.h"
#include "bake/SphereSampling.h"

using namespace terralux;

namespace {

// The placement error message for `s` over `hf`, or "" when it places.
std::string placementError(const ReflectionProbeSettings& s, const Heightfield& hf) {
    try {
        placeReflectionProbes(s, hf);
    } catch (const PlacementError& e) {
        return e.what();
    }
    return "";
}

// A set of `n` probes in a row with face colours (i + 1) · (f + 1) / 10 and no texels.
ReflectionProbeSet facesSet(int n) {
    ReflectionProbeSet set;
    set.encoding = ReflectionEncoding::Faces;
    set.faceSize = 0;
    set.mipCount = 1;
    set.dims = {n, 1};
    set.origin = {-100.0f, 50.0f};
    set.spacing = {n > 1 ? 200.0f / float(n - 1) : 0.0f, 0.0f};
    set.cellSize = {n > 1 ? 200.0f / float(n - 1) : 200.0f, 300.0f};
    set.strength = 0.75f;
    set.blendDistance = 42.5f;
    for (int i = 0; i < n; ++i) {
        ReflectionProbe p;
        p.id = uint32_t(i);
        p.position = glm::vec3(-100.0f + 10.0f * float(i), 1234.5f + float(i), 50.0f);
        p.halfExtent = glm::vec3(12.5f, 300.25f + float(i), 150.0f);
        for (int f = 0; f < 6; ++f) p.faces[size_t(f)] = glm::vec3(float((i + 1) * (f + 1)) / 10.0f);
        set.probes.push_back(p);
    }
    return set;
}

float f32At(const std::vector<uint8_t>& b, size_t at) {
    uint32_t u = uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 | uint32_t(b[at + 3]) << 24;
    return std::bit_cast<float>(u);
}
uint32_t u32At(const std::vector<uint8_t>& b, size_t at) {
    return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 | uint32_t(b[at + 3]) << 24;
}

// The 48 bytes seed 002 specifies for one probe, written out by hand field by field.
std::vector<uint8_t> handRecord(const ReflectionProbe& p, float layer, float intensity, float blend) {
    std::vector<uint8_t> out(48);
    const float v[12] = {p.position.x, p.position.y, p.position.z, layer,
                         p.halfExtent.x, p.halfExtent.y, p.halfExtent.z, intensity,
                         1.0f, blend, 4.0f, 0.0f};
    for (int k = 0; k < 12; ++k) {
        const uint32_t u = std::bit_cast<uint32_t>(v[k]);
        for (int b = 0; b < 4; ++b) out[size_t(4 * k + b)] = uint8_t(u >> (8 * b));
    }
    return out;
}

}  // namespace

TEST(ReflectionPlacement, LimitsAreRefusedWithNamedMessages) {
    const Heightfield hf = test::flat(33, 10.0, 100.0f);
    ReflectionProbeSettings s;
    s.gridDims = {17, 16};
    EXPECT_EQ(placementError(s, hf),
              "reflection_probes.grid_dims = [17,16]: must be >= 1 each with a product <= 256 (is 272)");
    s.gridDims = {16, 16};
    EXPECT_EQ(placementError(s, hf), "");
    s.strength = 1.5;
    EXPECT_EQ(placementError(s, hf), "reflection_probes.strength = 1.5: must be in [0, 1]");
    s.strength = -0.25;
    EXPECT_EQ(placementError(s, hf), "reflection_probes.strength = -0.25: must be in [0, 1]");
    s.strength = 1.0;
    s.resolution = 24;
    EXPECT_EQ(placementError(s, hf), "reflection_probes.resolution = 24: must be a power of two in [8, 128]");
    s.resolution = 32;
    s.spacing = glm::vec2(10.0f, 0.0f);
    EXPECT_EQ(placementError(s, hf), "reflection_probes.spacing = [10,0]: must be > 0 each");
}

TEST(ReflectionPlacement, AutoSpanPutsTheEndProbesOnTheEdgesAndOneProbeAtTheCentre) {
    // A plane rising 0.1 m per metre in x over a 320 m footprint centred on the origin.
    std::vector<float> h(33 * 33);
    for (int z = 0; z < 33; ++z)
        for (int x = 0; x < 33; ++x) h[size_t(z * 33 + x)] = 500.0f + float(x);
    const Heightfield hf(33, 33, 10.0, 10.0, h);
    ReflectionProbeSettings s;
    s.gridDims = {5, 3};
    s.heightOffset = 7.0;
    const ReflectionLayout L = placeReflectionProbes(s, hf);
    ASSERT_EQ(L.count(), 15u);
    EXPECT_FLOAT_EQ(L.positions[0].x, hf.minX());
    EXPECT_FLOAT_EQ(L.positions[0].z, hf.minZ());
    EXPECT_FLOAT_EQ(L.positions[14].x, hf.maxX());
    EXPECT_FLOAT_EQ(L.positions[14].z, hf.maxZ());
    // Scene order: x fastest.
    EXPECT_FLOAT_EQ(L.positions[1].x, hf.minX() + 80.0f);
    EXPECT_FLOAT_EQ(L.positions[5].z, hf.minZ() + 160.0f);
    for (const auto& p : L.positions) EXPECT_NEAR(p.y, hf.surfaceHeight(p.x, p.z) + 7.0f, 1e-3f);
    EXPECT_FLOAT_EQ(L.blendDistance, 2.0f * 80.0f);  // 2 · min(80, 160)

    s.gridDims = {1, 1};
    const ReflectionLayout one = placeReflectionProbes(s, hf);
    ASSERT_EQ(one.count(), 1u);
    EXPECT_FLOAT_EQ(one.positions[0].x, 0.0f);
    EXPECT_FLOAT_EQ(one.positions[0].z, 0.0f);
    // A one-probe grid's cell is the footprint.
    EXPECT_FLOAT_EQ(one.cellSize.x, 320.0f);
    EXPECT_FLOAT_EQ(one.cellSize.y, 320.0f);
}

// Seed 000's 2 · min(spacing), one rule for both kinds of grid: a one-probe axis counts the width its
// probe stands for (the footprint's extent along it), so a 1×1 diffuse volume and a 1×1 reflection
// grid on the same terrain fade over the same distance, and so do 1×N grids.
TEST(ReflectionPlacement, FallbackBlendIsTheDiffuseVolumesRule) {
    std::vector<float> h(41 * 21, 3.0f);
    const Heightfield hf(41, 21, 10.0, 20.0, std::move(h));  // 400 m × 400 m
    std::vector<float> h2(41 * 11, 3.0f);
    const Heightfield wide(41, 11, 10.0, 20.0, std::move(h2));  // 400 m × 200 m
    for (const Heightfield* t : {&hf, &wide}) {
        const float spanX = t->maxX() - t->minX(), spanZ = t->maxZ() - t->minZ();
        for (const auto& [nx, nz] : {std::pair{1, 1}, std::pair{1, 5}, std::pair{5, 1}, std::pair{5, 3}}) {
            ReflectionProbeSettings r;
            r.gridDims = {nx, nz};
            ProbeVolumeSettings v;
            v.gridDims = {nx, 1, nz};
            const float rd = placeReflectionProbes(r, *t).blendDistance;
            const float dd = placeProbes(v, *t).fallbackBlendDistance;
            const float sx = nx > 1 ? spanX / float(nx - 1) : spanX, sz = nz > 1 ? spanZ / float(nz - 1) : spanZ;
            EXPECT_FLOAT_EQ(rd, 2.0f * std::min(sx, sz)) << nx << "x" << nz;
            EXPECT_FLOAT_EQ(dd, rd) << nx << "x" << nz;
        }
    }
    // An explicit spacing on a one-probe axis places nothing, so it is not that axis' spacing.
    ProbeVolumeSettings v;
    v.gridDims = {1, 1, 1};
    v.spacing = glm::vec3(10.0f);
    EXPECT_FLOAT_EQ(placeProbes(v, wide).fallbackBlendDistance, 2.0f * 200.0f);
    // Set, it is taken as it is by both.
    v.fallbackBlendDistance = 7.0;
    ReflectionProbeSettings r;
    r.gridDims = {1, 1};
    r.fallbackBlendDistance = 7.0;
    EXPECT_FLOAT_EQ(placeProbes(v, wide).fallbackBlendDistance, 7.0f);
    EXPECT_FLOAT_EQ(placeReflectionProbes(r, wide).blendDistance, 7.0f);
}

TEST(ReflectionPlacement, BoxFollowsTheDocumentedRule) {
    std::vector<float> h(33 * 33);
    for (int z = 0; z < 33; ++z)
        for (int x = 0; x < 33; ++x) h[size_t(z * 33 + x)] = 500.0f + float(x);  // 0.1 m per m in x
    const Heightfield hf(33, 33, 10.0, 10.0, h);
    ReflectionProbeSettings s;
    s.gridDims = {3, 2};
    s.heightOffset = 5.0;
    const ReflectionLayout L = placeReflectionProbes(s, hf);
    // Cells 160 m in x and 320 m in z; probe 1 sits at x = 0 over ground at 516 m; its cell spans
    // x in [-80, 80], whose lowest ground is at x = -80: 508 m.
    const glm::vec3 e = L.halfExtent(1);
    EXPECT_FLOAT_EQ(e.x, 80.0f);
    EXPECT_FLOAT_EQ(e.z, 160.0f);
    EXPECT_NEAR(e.y, 0.5f * ((516.0f + 5.0f + 320.0f) - 508.0f), 1e-3f);
}

TEST(ReflectionCube, FaceDirectionsAndFaceSelectionAgree) {
    for (int f = 0; f < 6; ++f)
        for (float s : {0.1f, 0.5f, 0.8f})
            for (float t : {0.2f, 0.5f, 0.9f}) {
                float s2, t2;
                EXPECT_EQ(cubeFace(cubeDirection(f, s, t), s2, t2), f);
                EXPECT_NEAR(s2, s, 1e-5f);
                EXPECT_NEAR(t2, t, 1e-5f);
            }
    // The Vulkan convention's face centres.
    EXPECT_EQ(cubeDirection(0, 0.5f, 0.5f), glm::vec3(1, 0, 0));
    EXPECT_EQ(cubeDirection(3, 0.5f, 0.5f), glm::vec3(0, -1, 0));
    EXPECT_EQ(cubeDirection(5, 0.5f, 0.5f), glm::vec3(0, 0, -1));
    // +Y's top row looks toward -Z (north), +X's left column toward +Z.
    EXPECT_LT(cubeDirection(2, 0.5f, 0.0f).z, 0.0f);
    EXPECT_GT(cubeDirection(0, 0.0f, 0.5f).z, 0.0f);
    // Texel solid angles cover the sphere.
    double total = 0;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) total += 6.0 * cubeTexelSolidAngle(8, x, y);
    EXPECT_NEAR(total, 4.0 * std::numbers::pi, 1e-5);
    EXPECT_EQ(cubeMipCount(32), 4);  // 32, 16, 8, 4
    EXPECT_EQ(cubeMipCount(8), 2);
}

TEST(ReflectionCube, AUniformSkySeenEverywhereGivesTheSkyOnEveryFaceAndTexel) {
    // A probe past the footprint with the skirt off sees no terrain: the sky above and the ground
    // colour's radiance below, here equal to the sky.
    const Heightfield hf = test::flat(9, 10.0, 0.0f);
    const HeightfieldTracer tracer(hf, HeightfieldTracer::Options{false});
    BakeLighting L;
    L.tracer = &tracer;
    const glm::vec3 sky(0.4f, 0.55f, 0.9f);
    L.sky = Sky::uniform(sky);
    const IrradianceCache cache(L, 8, 16, 1, 0, {});
    ReflectionLighting light{&L, &cache, 1, sky};
    ReflectionProbeSettings s;
    s.gridDims = {1, 1};
    s.origin = glm::vec2(5000.0f, 0.0f);
    s.resolution = 8;
    s.rayCount = 2;
    const ReflectionLayout layout = placeReflectionProbes(s, hf);
    ReflectionProbeSet set = bakeReflectionProbes(light, s, layout, 7, {});
    ASSERT_EQ(set.probes.size(), 1u);
    for (const auto& f : set.probes[0].faces) {
        EXPECT_NEAR(f.x, sky.x, 1e-5f);
        EXPECT_NEAR(f.y, sky.y, 1e-5f);
        EXPECT_NEAR(f.z, sky.z, 1e-5f);
    }
    for (const auto& t : set.probes[0].texels) EXPECT_NEAR(glm::length(t - sky), 0.0f, 1e-5f);
    toEncoding(set, ReflectionEncoding::Faces);
    for (const glm::vec3 d : {glm::vec3(0, 1, 0), glm::normalize(glm::vec3(1, -2, 3))})
        EXPECT_NEAR(glm::length(set.evaluate(0, d, 0.5f) - sky), 0.0f, 1e-5f);
}

TEST(ReflectionCube, FacesAboveAPlaneMatchTheAnalyticAnswer) {
    // Uniform sky L over an infinite plane of albedo a (skirt on), no sun, one bounce: the ground
    // has irradiance πL and radiance aL. +Y sees L, -Y sees aL, and each side face is half sky,
    // half ground: (1 + a) L / 2.
    const Heightfield hf = test::flat(17, 10.0, 100.0f);
    const HeightfieldTracer tracer(hf);
    BakeLighting L;
    L.tracer = &tracer;
    L.sky = Sky::uniform(glm::vec3(1.0f));
    L.albedo = glm::vec3(0.3f);
    const IrradianceCache cache(L, 8, 64, 1, 0, {});
    ReflectionLighting light{&L, &cache, 1, glm::vec3(0.0f)};
    ReflectionProbeSettings s;
    s.gridDims = {1, 1};
    s.heightOffset = 10.0;
    s.resolution = 16;
    s.rayCount = 4;
    const ReflectionProbeSet set = bakeReflectionProbes(light, s, placeReflectionProbes(s, hf), 3, {});
    const auto& f = set.probes[0].faces;
    EXPECT_NEAR(f[2].x, 1.0f, 1e-4f);
    EXPECT_NEAR(f[3].x, 0.3f, 3e-3f);
    for (int side : {0, 1, 4, 5}) EXPECT_NEAR(f[size_t(side)].x, 0.65f, 0.01f) << "face " << side;
}

TEST(ReflectionCube, PrefilterAtRoughnessOneIsIrradianceOverPi) {
    // L(d) = 1 + b·d: irradiance E(n) = π (1 + 2/3 b·n), so at roughness 1 (GGX D = 1/π, the
    // weights reduce to n·l) the prefiltered radiance is E/π = 1 + 2/3 b·n.
    const glm::vec3 b(0.3f, 0.6f, -0.2f);
    RadianceCube cube;
    cube.size = 32;
    cube.texels.resize(6 * 32 * 32);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x)
                cube.at(f, x, y) = glm::vec3(1.0f + glm::dot(b, cubeDirection(f, (x + 0.5f) / 32.0f, (y + 0.5f) / 32.0f)));
    ReflectionProbeSet set;
    set.faceSize = 32;
    set.mipCount = cubeMipCount(32);
    set.probes.resize(1);
    set.probes[0].texels = prefilterCube(cube);
    ASSERT_EQ(set.probes[0].texels.size(), set.texelsPerProbe());
    for (uint32_t i = 0; i < 64; ++i) {
        const glm::vec3 n = fibonacciSphere(i, 64, 0.3f);
        const float truth = 1.0f + 2.0f / 3.0f * glm::dot(b, n);
        EXPECT_NEAR(prefilteredRadiance(cube, n, 1.0f).x, truth, 0.01f * truth);
        // The chain's roughest mip (4 × 4 a face), read as the renderer reads it: exact at the
        // texel centres, within 4 % between them (bilinear over 22-degree texels).
        EXPECT_NEAR(set.evaluate(0, n, 1.0f).x, truth, 0.04f * truth) << "direction " << i;
    }
    // Mip 0 is the cube itself: roughness 0 reads it back.
    EXPECT_NEAR(set.evaluate(0, cubeDirection(4, 0.5f + 0.5f / 32.0f, 0.5f + 0.5f / 32.0f), 0.0f).x,
                cube.at(4, 16, 16).x, 1e-5f);
}

TEST(ReflectionCube, BakeIsTheSameForAnyThreadCount) {
    std::vector<float> h(33 * 33);
    for (int z = 0; z < 33; ++z)
        for (int x = 0; x < 33; ++x) h[size_t(z * 33 + x)] = 40.0f * std::sin(0.3f * float(x)) * std::cos(0.2f * float(z));
    const Heightfield hills(33, 33, 10.0, 10.0, h);
    const HeightfieldTracer tracer(hills);
    const BakeLighting L = test::skyAndSun(tracer);
    const IrradianceCache cache(L, 16, 16, 2, 0, {});
    ReflectionLighting light{&L, &cache, 1, glm::vec3(0.1f)};
    ReflectionProbeSettings s;
    s.gridDims = {3, 2};
    s.resolution = 8;
    s.rayCount = 3;
    const ReflectionLayout layout = placeReflectionProbes(s, hills);
    auto bytes = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        return encodeReflectionProbes(bakeReflectionProbes(light, s, layout, 11, {}));
    };
    const auto one = bytes(1);
    EXPECT_EQ(one, bytes(2));
    EXPECT_EQ(one, bytes(4));
}

TEST(ReflectionFile, RoundTripsBothEncodingsAndRefusesBrokenFiles) {
    ReflectionProbeSet faces = facesSet(3);
    const auto fb = encodeReflectionProbes(faces);
    ASSERT_EQ(fb.size(), kRprobeHeaderBytes + 3 * kRprobeProbeBytes);
    EXPECT_EQ(u32At(fb, 0), 0x50524C54u);
    EXPECT_EQ(std::memcmp(fb.data(), "TLRP", 4), 0);
    const ReflectionProbeSet back = decodeReflectionProbes(fb, "f.rprobe");
    EXPECT_EQ(back.probes.size(), 3u);
    EXPECT_EQ(back.probes[2].faces[5], faces.probes[2].faces[5]);
    EXPECT_EQ(back.blendDistance, 42.5f);
    EXPECT_EQ(encodeReflectionProbes(back), fb);

    ReflectionProbeSet cube = facesSet(2);
    cube.encoding = ReflectionEncoding::Cubemap;
    cube.faceSize = 8;
    cube.mipCount = cubeMipCount(8);
    for (auto& p : cube.probes) p.texels.assign(cube.texelsPerProbe(), glm::vec3(0.5f, 0.25f, 2.0f));
    const auto cb = encodeReflectionProbes(cube);
    EXPECT_EQ(cb.size(), kRprobeHeaderBytes + 2 * (kRprobeProbeBytes + 12 * (6 * 64 + 6 * 16)));
    EXPECT_EQ(encodeReflectionProbes(decodeReflectionProbes(cb, "c.rprobe")), cb);

    auto refused = [](std::vector<uint8_t> b) {
        try {
            decodeReflectionProbes(b, "x.rprobe");
        } catch (const ReflectionFileError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(refused(std::vector<uint8_t>(fb.begin(), fb.begin() + 10)),
              "x.rprobe: 10 bytes: shorter than the 64-byte header");
    auto truncated = fb;
    truncated.pop_back();
    EXPECT_EQ(refused(truncated), "x.rprobe: 375 bytes: the header describes 376");
    auto nan = fb;
    const float q = std::nanf("");
    std::memcpy(nan.data() + 64 + 32, &q, 4);
    EXPECT_EQ(refused(nan), "x.rprobe: probe 0: face 0: radiance must be finite and >= 0");
    auto version = fb;
    version[4] = 2;
    EXPECT_EQ(refused(version), "x.rprobe: version 2: this reader knows version 1");
}

TEST(SimvxRecords, OneProbeMatchesTheHandComputedBytes) {
    const ReflectionProbeSet set = facesSet(1);
    const ReflectionBoxRecords r = encodeBoxRecords(set, {});
    ASSERT_EQ(r.desktop.size(), 400u);
    EXPECT_EQ(u32At(r.desktop, 0), 1u);
    for (size_t k = 4; k < 16; ++k) EXPECT_EQ(r.desktop[k], 0) << k;
    const auto rec = handRecord(set.probes[0], 0.0f, 0.75f, 42.5f);
    EXPECT_EQ(std::vector<uint8_t>(r.desktop.begin() + 16, r.desktop.begin() + 64), rec);
    for (size_t k = 64; k < 400; ++k) EXPECT_EQ(r.desktop[k], 0) << k;
    ASSERT_EQ(r.wire.size(), 52u);
    EXPECT_EQ(u32At(r.wire, 0), 0u);
    EXPECT_EQ(std::vector<uint8_t>(r.wire.begin() + 4, r.wire.end()), rec);
    EXPECT_EQ(f32At(r.desktop, 16 + 40), 4.0f);  // SCHED_UPDATE_REQUESTED
}

TEST(SimvxRecords, EightProbesFillEverySlotWithItsLayer) {
    const ReflectionProbeSet set = facesSet(8);
    const ReflectionBoxRecords r = encodeBoxRecords(set, {});
    EXPECT_EQ(u32At(r.desktop, 0), 8u);
    ASSERT_EQ(r.wire.size(), 8u * 52u);
    for (size_t slot = 0; slot < 8; ++slot) {
        const auto rec = handRecord(set.probes[slot], float(slot * 6), 0.75f, 42.5f);
        EXPECT_EQ(std::vector<uint8_t>(r.desktop.begin() + 16 + 48 * slot, r.desktop.begin() + 64 + 48 * slot), rec)
            << "slot " << slot;
        EXPECT_EQ(u32At(r.wire, 52 * slot), uint32_t(slot));
        // The wire leaves the layer at 0 for the runtime to patch.
        EXPECT_EQ(std::vector<uint8_t>(r.wire.begin() + 52 * slot + 4, r.wire.begin() + 52 * (slot + 1)),
                  handRecord(set.probes[slot], 0.0f, 0.75f, 42.5f));
    }
}

TEST(SimvxRecords, NineProbesAreClampedToEightInSceneOrderOrToTheChosenSubset) {
    const ReflectionProbeSet set = facesSet(9);
    const ReflectionBoxRecords r = encodeBoxRecords(set, {});
    EXPECT_EQ(r.total, 9u);
    EXPECT_EQ(r.exported, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6, 7}));
    EXPECT_EQ(u32At(r.desktop, 0), 8u);
    EXPECT_EQ(r.desktop.size(), 400u);
    EXPECT_EQ(r.wire.size(), 8u * 52u);

    const ReflectionBoxRecords chosen = encodeBoxRecords(set, {8, 0, 4});
    EXPECT_EQ(chosen.exported, (std::vector<uint32_t>{0, 4, 8}));
    EXPECT_EQ(std::vector<uint8_t>(chosen.desktop.begin() + 16 + 96, chosen.desktop.begin() + 16 + 144),
              handRecord(set.probes[8], 12.0f, 0.75f, 42.5f));
    EXPECT_EQ(u32At(chosen.wire, 104), 8u);

    auto refused = [&](const std::vector<int>& subset) {
        try {
            encodeBoxRecords(set, subset);
        } catch (const PlacementError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(refused({1, 9}), "reflection_probes.simvx_subset[1] = 9: must be a probe index below 9, the grid's probe count");
    EXPECT_EQ(refused({3, 3}), "reflection_probes.simvx_subset: index 3 appears twice: each probe at most once");
    EXPECT_EQ(refused({0, 1, 2, 3, 4, 5, 6, 7, 8}), "reflection_probes.simvx_subset: 9 indices: at most 8");
}
