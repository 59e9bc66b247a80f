// The rules C++ and GLSL share (shaders/ShaderMath.h: display encoding and luminance, SH basis, fog optics)
// evaluated by a compute shader built from the same headers, against their C++ evaluation, at
// samples spread over each function's domain; and the SH basis against the CPU bake's own
// double-precision closed forms.
#include <cmath>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include "ShaderMath.h"
#include "bake/SphericalHarmonics.h"
#include "render/features/Water.h"
#include "vk/Buffer.h"
#include "vk/ComputePipeline.h"
#include "vk/Descriptors.h"
#include "vk/PipelineLayout.h"
#include "vk/VulkanContext.h"
#include "water/Water.h"

namespace terralux::shaders {
std::span<const uint32_t> shaderMathComp();  // tests/render/shader_math.comp
std::span<const uint32_t> waterWavesComp();  // tests/render/water_waves.comp
}

using namespace terralux;

namespace {

constexpr int kOutputs = 22;

struct Sample {
    glm::vec4 a, b;
};

// Samples over the domains: light 0..64 (log-spaced, with 0), values 0..1 with the sRGB knees,
// heights −200..2000 m, g −0.9..0.9, directions over the sphere (the horizontal included), and
// distances 0..20 km.
std::vector<Sample> samples() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<Sample> s;
    const float knees[] = {0.0f, 0.0031308f, 0.04045f, 0.5f, 0.999f, 1.0f};
    for (int i = 0; i < 512; ++i) {
        const float light = i == 0 ? 0.0f : std::exp2(u(rng) * 12.0f - 6.0f);
        const float value = i < 6 ? knees[i] : u(rng);
        glm::vec3 d(u(rng) * 2.0f - 1.0f, i % 17 == 0 ? 0.0f : u(rng) * 2.0f - 1.0f, u(rng) * 2.0f - 1.0f);
        d = glm::normalize(d + glm::vec3(1e-3f));
        s.push_back({glm::vec4(light, value, u(rng) * 2200.0f - 200.0f, u(rng) * 1.8f - 0.9f),
                     glm::vec4(d, u(rng) * 20000.0f)});
    }
    return s;
}

std::array<float, kOutputs> onCpu(const Sample& s) {
    std::array<float, kOutputs> o{};
    o[0] = glsl::acesFit(s.a.x);
    o[1] = glsl::srgbEncode(s.a.y);
    o[2] = glsl::srgbDecode(s.a.y);
    o[3] = glsl::acesFitInverse(s.a.y);
    for (int k = 0; k < 9; ++k) o[size_t(4 + k)] = glsl::shBasis(k, s.b.x, s.b.y, s.b.z);
    o[13] = glsl::fogOpticalDepth(0.002f, 0.001f, s.a.z, s.b.y, s.b.w);
    o[14] = glsl::henyeyGreenstein(s.a.w, s.b.y);
    o[15] = glsl::srgbEncode(glsl::acesFit(s.a.x));
    o[16] = glsl::fogSkyOpticalDepth(0.002f, 0.001f, s.a.z, s.b.y, s.b.w);
    o[17] = glsl::equirectU(s.b.x, s.b.z, s.a.y);
    o[18] = glsl::equirectV(s.b.y);
    // A cascade texel of 0..200 m, a sun 0..63° high (tan 0..2), DEM cells of 60 m.
    o[19] = glsl::shadowShortestDrawn(0.01f * s.b.w, 2.0f * s.a.y);
    o[20] = glsl::shadowTakesHorizon(0.01f * s.b.w, 2.0f * s.a.y, 60.0f) ? 1.0f : 0.0f;
    o[21] = glsl::rec709Luminance(s.a.x, s.a.y, std::abs(s.b.x));
    return o;
}

const char* kNames[kOutputs] = {"acesFit", "srgbEncode", "srgbDecode", "acesFitInverse", "Y0", "Y1", "Y2",
                                "Y3", "Y4", "Y5", "Y6", "Y7", "Y8", "fogOpticalDepth", "henyeyGreenstein",
                                "display", "fogSkyOpticalDepth", "equirectU", "equirectV",
                                "shadowShortestDrawn", "shadowTakesHorizon", "rec709Luminance"};

// A device with validation, or none (the test skips).
std::unique_ptr<vk::VulkanContext> device(std::string& why) {
    try {
        vk::ContextOptions o;
        o.validation = true;
        return std::make_unique<vk::VulkanContext>(o);
    } catch (const vk::VulkanUnavailable& e) {
        why = e.what();
        return nullptr;
    }
}

// One compute dispatch of `count` invocations (64 a group) with `set` bound at `setIndex`, after
// the uploads and before the host reads the results; waits for it.
void dispatch(const vk::VulkanContext& ctx, VkPipeline pipeline, const vk::PipelineLayout& layout,
              const vk::DescriptorSet& set, uint32_t setIndex, size_t count) {
    const glm::ivec4 push(int(count), 0, 0, 0);
    ctx.submitAndWait([&](VkCommandBuffer cb) {
        VkMemoryBarrier toShader{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr, VK_ACCESS_TRANSFER_WRITE_BIT,
                                 VK_ACCESS_SHADER_READ_BIT};
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                             &toShader, 0, nullptr, 0, nullptr);
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
        const VkDescriptorSet handle = set.handle();
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout.handle(), setIndex, 1, &handle, 0, nullptr);
        vkCmdPushConstants(cb, layout.handle(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
        vkCmdDispatch(cb, uint32_t(count + 63) / 64, 1, 1);
        VkMemoryBarrier toHost{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr, VK_ACCESS_SHADER_WRITE_BIT,
                               VK_ACCESS_HOST_READ_BIT};
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0,
                             nullptr, 0, nullptr);
    });
}

}  // namespace

TEST(ShaderMath, TheShadersEvaluateEachSharedRuleAsCppDoes) {
    std::string why;
    const std::unique_ptr<vk::VulkanContext> ctx = device(why);
    if (!ctx) GTEST_SKIP() << "no Vulkan: " << why;
    const std::vector<Sample> in = samples();
    constexpr VkShaderStageFlags compute = VK_SHADER_STAGE_COMPUTE_BIT;
    const vk::Buffer inputs = vk::Buffer::deviceLocal(*ctx, in.data(), in.size() * sizeof(Sample),
                                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vk::Buffer outputs = vk::Buffer::hostReadable(*ctx, in.size() * kOutputs * sizeof(float),
                                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    const vk::DescriptorSet set = vk::DescriptorSetBuilder()
                                      .storage(0, "inputs", inputs, compute)
                                      .storage(1, "outputs", outputs, compute)
                                      .build(*ctx);
    const VkDescriptorSetLayout layouts[] = {set.layout()};
    const vk::PipelineLayout layout(*ctx, layouts, sizeof(glm::ivec4), compute);
    const vk::UniquePipeline pipeline = vk::createComputePipeline(*ctx, layout.handle(), shaders::shaderMathComp());
    dispatch(*ctx, pipeline.get(), layout, set, 0, in.size());
    const auto* gpu = static_cast<const float*>(outputs.map());
    // Bounds relative to the value (to 0.1 near zero). Arithmetic alone agrees to an ulp or two
    // (a fused multiply-add here or there): 2.5e-7, which a constant copied to six digits fails
    // (the SH basis's old 0.282095 was 7.4e-7 off). Vulkan lets pow be a few ulps off IEEE
    // (2e-6) and exp's error grows with its argument, up to 80 in the fog's optical depth (5e-5).
    // atan and acos may be 4096 ulps off (2.4e-4 relative); lavapipe's acos is 1.2e-4 off near
    // the zenith, a fortieth of a texel of a 2k sky (5e-4). A division may be 2.5 ulps off (1e-6).
    const double bound[kOutputs] = {2.5e-7, 2e-6, 2e-6, 2.5e-7, 2.5e-7, 2.5e-7, 2.5e-7, 2.5e-7, 2.5e-7,
                                    2.5e-7, 2.5e-7, 2.5e-7, 2.5e-7, 5e-5, 2.5e-7, 2e-6, 5e-5, 5e-4, 5e-4,
                                    1e-6, 1e-6, 2.5e-7};
    for (int f = 0; f < kOutputs; ++f) {
        double worst = 0.0;
        for (size_t i = 0; i < in.size(); ++i) {
            const float cpu = onCpu(in[i])[size_t(f)], dev = gpu[i * kOutputs + size_t(f)];
            worst = std::max(worst, std::abs(double(cpu) - double(dev)) / std::max(std::abs(double(cpu)), 0.1));
        }
        EXPECT_LT(worst, bound[f]) << kNames[f];
    }
    EXPECT_EQ(ctx->validationMessageCount(), 0u);
}

// The shared equirectangular mapping inverts the directions the sky's SH projection gives its
// texel centres (Sky::computeSh): the bake, the SH and the sky pass agree on where a texel is.
TEST(ShaderMath, TheEquirectMappingFindsEachTexelOfTheSky) {
    const int w = 64, h = 32;
    for (const float rotation : {0.0f, 0.3f, 0.9f})
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const double u = (x + 0.5) / w, v = (y + 0.5) / h;
                const double phi = (u - 0.5 + rotation) * 2.0 * std::numbers::pi, theta = v * std::numbers::pi;
                const float dx = float(std::sin(theta) * std::sin(phi)), dy = float(std::cos(theta)),
                            dz = float(-std::sin(theta) * std::cos(phi));
                ASSERT_NEAR(glsl::equirectU(dx, dz, rotation), u, 1e-5) << x << "," << y << " rotation " << rotation;
                ASSERT_NEAR(glsl::equirectV(dy), v, 1e-5) << x << "," << y;
            }
}

// The shared float basis is the CPU bake's double-precision basis rounded once.
TEST(ShaderMath, TheSharedShBasisIsTheBakesBasis) {
    std::mt19937 rng(3);
    std::normal_distribution<float> g;
    for (int i = 0; i < 1000; ++i) {
        const glm::vec3 d = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
        const std::array<float, 9> bake = sh::evalBasis(d);
        for (int k = 0; k < 9; ++k)
            EXPECT_NEAR(glsl::shBasis(k, d.x, d.y, d.z), bake[size_t(k)], 2e-7f) << "k " << k;
    }
    EXPECT_EQ(glsl::kShY00, sh::evalBasis(glm::vec3(0.0f, 1.0f, 0.0f))[0]);
}

// The display curve's inverses undo it (the water pass reads the frame under it back to light).
TEST(ShaderMath, TheDisplayCurveInvertsWhereItIsNotClamped) {
    for (float x = 0.0f; x < 8.0f; x += 0.01f) {
        const float y = glsl::acesFit(x);
        if (y >= 0.999f) break;
        EXPECT_NEAR(glsl::acesFitInverse(y), x, 1e-4f * std::max(1.0f, x)) << x;
        EXPECT_NEAR(glsl::srgbDecode(glsl::srgbEncode(y)), y, 1e-6f) << y;
    }
}

// The water shaders' Gerstner waves (water.glsl, through the block packWater writes) against
// water::gerstner, the CPU's double-precision evaluation: displacement and normal at rest points
// over a kilometre, in deep water and with the depth-aware dispersion, with the shore fade.
TEST(ShaderMath, TheWaterShadersWavesAreTheCpusWaves) {
    std::string why;
    const std::unique_ptr<vk::VulkanContext> ctx = device(why);
    if (!ctx) GTEST_SKIP() << "no Vulkan: " << why;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<glm::vec4> points;
    for (int i = 0; i < 256; ++i)
        points.emplace_back(u(rng) * 1000.0f - 500.0f, u(rng) * 1000.0f - 500.0f, 0.3f + u(rng) * 40.0f, u(rng));
    constexpr VkShaderStageFlags compute = VK_SHADER_STAGE_COMPUTE_BIT;
    const vk::Buffer input = vk::Buffer::deviceLocal(*ctx, points.data(), points.size() * sizeof(glm::vec4),
                                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vk::Buffer output = vk::Buffer::hostReadable(*ctx, points.size() * 2 * sizeof(glm::vec4),
                                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vk::Buffer block = vk::Buffer::hostVisible(*ctx, sizeof(blocks::WaterBlock), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    const vk::DescriptorSet set = vk::DescriptorSetBuilder()
                                      .uniform(0, "water", block, compute)
                                      .storage(5, "points", input, compute)
                                      .storage(6, "results", output, compute)
                                      .build(*ctx);
    const vk::UniqueSetLayout empty = vk::DescriptorSetBuilder().buildLayout(*ctx);
    const VkDescriptorSetLayout layouts[] = {empty.get(), empty.get(), set.layout()};
    const vk::PipelineLayout layout(*ctx, layouts, sizeof(glm::ivec4), compute);
    const vk::UniquePipeline pipeline = vk::createComputePipeline(*ctx, layout.handle(), shaders::waterWavesComp());

    RenderSettings s;
    s.water.enabled = true;
    // The open sea's eight waves (the most a scene holds), the last one given by amplitude.
    s.water.waves = water::wavePreset("open sea");
    ASSERT_EQ(s.water.waves.size(), size_t(WaterSettings::kMaxWaves));
    s.water.waves.back() = GerstnerWave{200.0, 3.0, 0.05, std::nullopt, 0.7};
    ASSERT_EQ(water::checkWaves(s.water.waves), "");
    double amplitudes = 0.0;
    std::vector<water::WaveTerms> terms;
    for (const GerstnerWave& w : s.water.waves) {
        terms.push_back(water::waveTerms(w));
        amplitudes += terms.back().amplitude;
    }
    for (const bool depthAware : {false, true}) {
        s.water.depthAware = depthAware;
        s.time = 37.25;
        features::WaterInputs in;
        in.level = 0.0f;
        const blocks::WaterBlock packed = features::packWater(s, in);
        block.write(&packed, sizeof packed);
        dispatch(*ctx, pipeline.get(), layout, set, TLX_SET_SUBSYSTEM, points.size());
        const auto* gpu = static_cast<const glm::vec4*>(output.map());
        double worstDisplacement = 0.0, worstNormal = 0.0;
        for (size_t i = 0; i < points.size(); ++i) {
            const glm::vec4 p = points[i];
            const water::SurfacePoint cpu =
                water::gerstner(terms, {p.x, p.y}, s.time, depthAware ? std::optional<double>(p.z) : std::nullopt, p.w);
            worstDisplacement = std::max(worstDisplacement, glm::length(cpu.displacement - glm::dvec3(gpu[2 * i])));
            worstNormal = std::max(worstNormal, glm::length(cpu.normal - glm::dvec3(gpu[2 * i + 1])));
        }
        // Float phases of up to a thousand radians carry about 1e-4 rad: a thousandth of the
        // summed amplitude holds them, and a convention that differs (a sign, an axis, the
        // azimuth) is off by the amplitude itself.
        EXPECT_LT(worstDisplacement, 1e-3 * amplitudes) << (depthAware ? "depth-aware" : "deep");
        EXPECT_LT(worstNormal, 1e-3) << (depthAware ? "depth-aware" : "deep");
    }
    EXPECT_EQ(ctx->validationMessageCount(), 0u);
}
