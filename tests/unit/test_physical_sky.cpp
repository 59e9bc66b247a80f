// The physical sky (Preetham 1999): well-behaved everywhere, the paper's zenith formula, the
// shape of the sky and the sun through the atmosphere, and its equirect Sky.

#include "bake/PhysicalSky.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "EnvironmentImage.h"
#include "bake/Sky.h"
#include "bake/SphericalHarmonics.h"

using namespace terralux;

namespace {

constexpr double kPi = std::numbers::pi;

double luma(const glm::vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

bool finiteAndNonNegative(const glm::vec3& c) {
    return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && c.x >= 0 && c.y >= 0 &&
           c.z >= 0;
}

// A spherical Fibonacci set, plus the poles and horizon points the formulas treat specially.
std::vector<glm::vec3> directions(int n) {
    std::vector<glm::vec3> out;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double y = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - y * y);
        out.emplace_back(float(r * std::cos(golden * i)), float(y), float(r * std::sin(golden * i)));
    }
    for (const glm::vec3 d : {glm::vec3(0, 1, 0), glm::vec3(0, -1, 0), glm::vec3(1, 0, 0),
                              glm::vec3(0, 0, -1), glm::vec3(0.6f, 1e-7f, -0.8f), glm::vec3(0.6f, -1e-7f, 0.8f)})
        out.push_back(d);
    return out;
}

// Preetham et al. 1999, appendix A.2, written out independently of the code under test: zenith
// luminance in kcd/m² for turbidity T and the sun's zenith angle θs (radians).
double paperZenithLuminance(double T, double thetaS) {
    const double chi = (4.0 / 9.0 - T / 120.0) * (kPi - 2.0 * thetaS);
    return (4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192;
}

}  // namespace

TEST(PhysicalSky, FiniteAndNonNegativeEverywhere) {
    const std::vector<glm::vec3> dirs = directions(4000);
    for (double T : {1.7, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0})
        for (int el = -10; el <= 90; el += 5) {
            const PhysicalSky sky(sunDirection(135.0, el), T);
            for (const glm::vec3& d : dirs) {
                const glm::vec3 L = sky.radiance(d);
                ASSERT_TRUE(finiteAndNonNegative(L)) << "T " << T << " el " << el << " dir " << d.x << "," << d.y << "," << d.z;
                ASSERT_TRUE(std::isfinite(sky.luminance(d)) && sky.luminance(d) >= 0.0);
            }
            ASSERT_TRUE(finiteAndNonNegative(sky.sunIlluminance())) << "T " << T << " el " << el;
            if (el <= 0) {
                EXPECT_EQ(sky.sunIlluminance(), glm::vec3(0.0f)) << "el " << el;
            } else {
                EXPECT_GT(sky.sunIlluminanceLux(), 0.0) << "el " << el;
            }
            // Daylight, not darkness: the zenith stays lit down to the horizon.
            if (el >= 0) {
                EXPECT_GT(luma(sky.radiance(glm::vec3(0, 1, 0))), 0.0) << "T " << T << " el " << el;
            }
        }
}

TEST(PhysicalSky, ZenithLuminanceIsThePapersFormula) {
    for (auto [T, el] : {std::pair{3.0, 35.0}, {2.0, 60.0}, {6.0, 15.0}, {10.0, 80.0}}) {
        const PhysicalSky sky(sunDirection(200.0, el), T);
        const double expected = 1000.0 * paperZenithLuminance(T, (90.0 - el) * kPi / 180.0);
        EXPECT_NEAR(sky.luminance(glm::vec3(0, 1, 0)), expected, 1e-4 * expected) << "T " << T << " el " << el;
        // The RGB radiance carries the same luminance, in scene units.
        EXPECT_NEAR(luma(sky.radiance(glm::vec3(0, 1, 0))), kSceneUnitsPerLux * expected,
                    2e-3 * kSceneUnitsPerLux * expected);
    }
}

TEST(PhysicalSky, BrighterAroundTheSun) {
    for (double T : {2.0, 3.0, 6.0}) {
        const PhysicalSky sky(sunDirection(135.0, 35.0), T);
        // 10° from the sun, and the same elevation on the opposite side of the sky.
        const glm::vec3 nearSun = sunDirection(145.0, 35.0), opposite = sunDirection(315.0, 35.0);
        EXPECT_GT(sky.luminance(nearSun), 2.0 * sky.luminance(opposite)) << "T " << T;
        EXPECT_GT(luma(sky.radiance(nearSun)), luma(sky.radiance(opposite))) << "T " << T;
    }
}

TEST(PhysicalSky, GroundHalfIsTheHorizon) {
    const PhysicalSky sky(sunDirection(135.0, 20.0), 3.0);
    for (double az = 0.0; az < 360.0; az += 30.0) {
        const glm::vec3 horizon = sunDirection(az, 0.0);
        const glm::vec3 below = glm::normalize(horizon + glm::vec3(0.0f, -0.7f, 0.0f));
        EXPECT_EQ(sky.radiance(below), sky.radiance(horizon)) << az;
        EXPECT_GT(luma(sky.radiance(horizon)), 0.0) << az;
    }
}

TEST(PhysicalSky, SunDimsAndReddensAsItLowers) {
    double lastLux = 1e30, lastBlueRed = 1e30;
    for (double el : {90.0, 60.0, 35.0, 20.0, 10.0, 5.0, 2.0}) {
        const PhysicalSky sky(sunDirection(135.0, el), 3.0);
        const glm::vec3 sun = sky.sunIlluminance();
        const double blueRed = sun.z / sun.x;
        EXPECT_LT(sky.sunIlluminanceLux(), lastLux) << el;
        EXPECT_LT(blueRed, lastBlueRed) << el;
        EXPECT_NEAR(luma(sun), kSceneUnitsPerLux * sky.sunIlluminanceLux(), 0.02 * luma(sun)) << el;
        lastLux = sky.sunIlluminanceLux();
        lastBlueRed = blueRed;
    }
    // A clear-day sun high in the sky is about 100 klx, 3 scene units.
    const PhysicalSky noon(sunDirection(135.0, 70.0), 3.0);
    EXPECT_GT(noon.sunIlluminanceLux(), 80000.0);
    EXPECT_LT(noon.sunIlluminanceLux(), 110000.0);
    // Haze dims it too.
    EXPECT_LT(PhysicalSky(sunDirection(135.0, 35.0), 6.0).sunIlluminanceLux(),
              PhysicalSky(sunDirection(135.0, 35.0), 3.0).sunIlluminanceLux());
    EXPECT_EQ(PhysicalSky(sunDirection(135.0, -1.0), 3.0).sunIlluminanceLux(), 0.0);
}

TEST(PhysicalSky, TwilightFadesContinuously) {
    const glm::vec3 up(0, 1, 0);
    const double atHorizon = PhysicalSky(sunDirection(135.0, 0.0), 3.0).luminance(up);
    EXPECT_NEAR(PhysicalSky(sunDirection(135.0, -0.01), 3.0).luminance(up), atHorizon, 0.01 * atHorizon);
    EXPECT_NEAR(PhysicalSky(sunDirection(135.0, -6.0), 3.0).luminance(up), 0.01 * atHorizon, 1e-3 * atHorizon);
    EXPECT_GT(PhysicalSky(sunDirection(135.0, 0.5), 3.0).luminance(up), atHorizon);
}

TEST(PhysicalSky, AirMassOfKastenAndYoung) {
    EXPECT_NEAR(relativeAirMass(0.0), 1.0, 1e-3);
    EXPECT_NEAR(relativeAirMass(60.0), 2.0, 0.01);
    EXPECT_NEAR(relativeAirMass(90.0), 37.9, 0.1);
}

// Direct sun on level ground against the sky's irradiance on it: one constant converts both to
// scene units, so this is the model's own ratio. Measured clear days give about 3 to 10 here;
// Preetham's sky is brighter than that against its sun (26 klx of sky to 44 klx of sun on level
// ground at 35°, T 3; docs/lighting.md, Physical sky), so the ratio is held to the model's
// value: a unit slip (kcd against cd, a stray π) moves it far outside.
TEST(PhysicalSky, DirectToDiffuseRatio) {
    const glm::vec3 sunDir = sunDirection(135.0, 35.0);
    const PhysicalSky model(sunDir, 3.0);
    const Sky sky = Sky::physical(model);
    const double direct = luma(model.sunIlluminance()) * sunDir.y;
    const double diffuse = luma(sky.openIrradianceUp());
    const double ratio = direct / diffuse;
    RecordProperty("direct_to_diffuse", std::to_string(ratio));
    EXPECT_GT(ratio, 1.5);
    EXPECT_LT(ratio, 2.0);
}

TEST(PhysicalSky, EquirectShDcIsTheImageMean) {
    const PhysicalSky model(sunDirection(80.0, 25.0), 4.0);
    const int w = 128, h = 64;
    const Sky sky = Sky::physical(model, w, h);
    EXPECT_FALSE(sky.isUniform());
    // The solid-angle-weighted mean of the radiance at the texel centres (Sky.h's mapping at
    // rotation 0: row 0 at the zenith, the centre column facing north).
    glm::dvec3 sum(0.0);
    double weights = 0.0;
    for (int y = 0; y < h; ++y) {
        const double t0 = kPi * y / h, t1 = kPi * (y + 1) / h, theta = 0.5 * (t0 + t1);
        const double omega = 2.0 * kPi / w * (std::cos(t0) - std::cos(t1));
        for (int x = 0; x < w; ++x) {
            const double phi = ((x + 0.5) / w - 0.5) * 2.0 * kPi;
            const glm::vec3 d(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                              float(-std::sin(theta) * std::cos(phi)));
            sum += glm::dvec3(model.radiance(d)) * omega;
            weights += omega;
        }
    }
    const glm::dvec3 mean = sum / weights;
    const glm::vec3 dc = sky.sh().c[0] / float(2.0 * std::sqrt(kPi));  // L_0 = 2√π × mean
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(dc[c], mean[c], 1e-4 * mean[c]) << c;
    // The lookup reads the model back (no sun disc added, no rotation).
    const glm::vec3 toward = glm::normalize(glm::vec3(0.3f, 0.5f, -0.8f));
    EXPECT_NEAR(luma(sky.radiance(toward)), luma(model.radiance(toward)), 0.05 * luma(model.radiance(toward)));
}

// Found by fuzz_env_image: an EXR header attribute claiming more bytes than the file holds made
// OpenEXR allocate and fill all of them (seconds and hundreds of MB for a 1 KB file). It is
// refused before OpenEXR sees it, naming the attribute; a sane size goes on to OpenImageIO.
TEST(EnvironmentImage, ExrAttributePastTheEndIsRefused) {
    auto write = [](const std::filesystem::path& p, uint32_t size) {
        std::string b = std::string("\x76\x2f\x31\x01\x02\x00\x00\x00", 8) + "comments" + '\0' + "string" + '\0';
        for (int shift = 0; shift < 32; shift += 8) b.push_back(char((size >> shift) & 0xFF));
        b += "abcd";
        b.push_back('\0');
        std::ofstream(p, std::ios::binary) << b;
    };
    const auto dir = std::filesystem::temp_directory_path();
    write(dir / "terralux_exr_claims.exr", 0x40000000u);
    try {
        checkEquirectImage((dir / "terralux_exr_claims.exr").string());
        FAIL() << "accepted";
    } catch (const ImageError& e) {
        EXPECT_NE(std::string(e.what()).find("EXR header attribute 'comments' claims 1073741824 bytes, past the end of the file"),
                  std::string::npos) << e.what();
    }
    write(dir / "terralux_exr_sane.exr", 4);
    try {
        checkEquirectImage((dir / "terralux_exr_sane.exr").string());
        FAIL() << "accepted";
    } catch (const ImageError& e) {
        EXPECT_EQ(std::string(e.what()).find("past the end"), std::string::npos) << e.what();
    }
}

// Found by fuzz_env_image too: a channel list whose declared size is not where OpenEXR stops
// reading it (OpenEXR reads channels up to an empty name) hid the next attribute's claim from a
// walk that skipped by declared sizes. The walk reads each type as OpenEXR does: channel lists
// by their entries, a preview by its width x height x 4.
TEST(EnvironmentImage, ExrClaimsAfterAChannelListAndInAPreviewAreRefused) {
    auto u32 = [](uint32_t v) {
        std::string b;
        for (int shift = 0; shift < 32; shift += 8) b.push_back(char((v >> shift) & 0xFF));
        return b;
    };
    const std::string head("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
    // One channel "R" (16 bytes of layout) and the list's end, declared as 2 bytes.
    const std::string chlist = std::string("channels") + '\0' + "chlist" + '\0' + u32(2) + "R" + '\0' +
                               std::string(16, '\0') + '\0';
    const auto dir = std::filesystem::temp_directory_path();
    auto refusal = [&](const std::string& name, const std::string& bytes) {
        const auto p = dir / name;
        std::ofstream(p, std::ios::binary) << bytes;
        try {
            checkEquirectImage(p.string());
        } catch (const ImageError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    const std::string afterList = refusal(
        "terralux_exr_after_chlist.exr",
        head + chlist + "Software" + '\0' + "string" + '\0' + u32(0x6863008au) + "abc" + '\0');
    EXPECT_NE(afterList.find("attribute 'Software' claims 1751318666 bytes, past the end"), std::string::npos)
        << afterList;
    const std::string preview = refusal(
        "terralux_exr_preview.exr",
        head + "preview" + '\0' + "preview" + '\0' + u32(8) + u32(60000) + u32(60000) + '\0');
    EXPECT_NE(preview.find("attribute 'preview' claims 14400000000 bytes, past the end"), std::string::npos)
        << preview;
}

// Found by the 30-minute fuzz_env_image run: a 748-byte EXR whose data window is 7 340 036 x 257
// made OpenEXR size its line buffers by that width (440 MB, 3 s under AddressSanitizer) before
// OpenImageIO's open returned and the equirectangular rule could refuse it. The header walk
// applies the rule to the data window first; a 2:1 window goes on.
TEST(EnvironmentImage, ExrDataWindowThatIsNoSkyIsRefusedBeforeOpenExrSizesItsBuffers) {
    auto u32 = [](uint32_t v) {
        std::string b;
        for (int shift = 0; shift < 32; shift += 8) b.push_back(char((v >> shift) & 0xFF));
        return b;
    };
    const auto dir = std::filesystem::temp_directory_path();
    auto refusal = [&](uint32_t xMax, uint32_t yMax) {
        const auto p = dir / "terralux_exr_window.exr";
        std::ofstream(p, std::ios::binary) << std::string("\x76\x2f\x31\x01\x02\x00\x00\x00", 8) + "dataWindow" + '\0' +
                                                  "box2i" + '\0' + u32(16) + u32(0) + u32(0) + u32(xMax) + u32(yMax) + '\0';
        try {
            checkEquirectImage(p.string());
        } catch (const ImageError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(refusal(7340035, 256).find("EXR data window 7340036x257 is not an equirectangular image"), std::string::npos);
    EXPECT_NE(refusal(65535, 32767).find("EXR data window 65536x32768 is not an equirectangular image (width twice "
                                         "the height, at most 32768)"),
              std::string::npos);
    const std::string sky = refusal(7, 3);  // 8 x 4: the header walk lets it through to OpenImageIO
    EXPECT_EQ(sky.find("data window"), std::string::npos) << sky;
}

// Two scenarios' skies mixed into one image for the background between them: each texel is the
// mix of the two skies toward its centre, whatever their kinds and rotations.
TEST(PhysicalSky, BlendedEquirectMixesTheTwoSkiesTowardEachTexel) {
    const Sky physical = Sky::physical(PhysicalSky(sunDirection(80.0, 25.0), 4.0), 128, 64);
    std::vector<float> rgb(64 * 32 * 3);
    for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = float((i * 7) % 13) / 13.0f;
    const Sky turned = Sky::equirect(rgb, 64, 32, 2.0f, 40.0f);
    const Sky uniform = Sky::uniform(glm::vec3(0.2f, 0.3f, 0.4f));
    const int w = 96, h = 48;
    const std::vector<glm::vec3> mixed = blendedEquirect(physical, turned, 0.25f, w, h);
    ASSERT_EQ(mixed.size(), size_t(w * h));
    for (int y = 0; y < h; y += 5)
        for (int x = 0; x < w; x += 7) {
            // The texel centre's direction as the sky pass maps it (equirectU/V at rotation 0).
            const double theta = kPi * (y + 0.5) / h, phi = ((x + 0.5) / w - 0.5) * 2.0 * kPi;
            const glm::vec3 d(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                              float(-std::sin(theta) * std::cos(phi)));
            const glm::vec3 expected = 0.75f * physical.radiance(d) + 0.25f * turned.radiance(d);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(mixed[size_t(y * w + x)][c], expected[c], 1e-4f * (1.0f + expected[c])) << x << "," << y;
        }
    // Uniform with uniform is the mixed colour; the ends are the skies themselves.
    const std::vector<glm::vec3> flat = blendedEquirect(uniform, Sky::uniform(glm::vec3(1.0f)), 0.5f, 4, 2);
    for (const glm::vec3& v : flat)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[c], glm::vec3(0.6f, 0.65f, 0.7f)[c], 1e-6f);
    const std::vector<glm::vec3> end = blendedEquirect(uniform, physical, 1.0f, w, h);
    const std::vector<glm::vec3> start = blendedEquirect(physical, uniform, 0.0f, w, h);
    EXPECT_EQ(end, start);
    EXPECT_THROW(blendedEquirect(uniform, physical, 0.5f, 0, 4), std::invalid_argument);
}

// A lookup never blurs beyond Sky::kMaxFilterSolidAngle (docs/lighting.md, "HDR sky"): a ray that
// stands for more of the sphere (draft's 96 rays, 0.13 sr each) reads the sky as one of 1024 rays
// does, and a prefilter of that size keeps band 2 of the sky's projection within 1 %.
TEST(SkyPrefilter, ALookupBlursNoMoreThanTheBound) {
    const Sky sky = Sky::physical(PhysicalSky(sunDirection(135.0, 20.0), 3.0), 512, 256);
    const float bound = Sky::kMaxFilterSolidAngle;
    EXPECT_NEAR(bound, 4.0f * float(kPi) / 1024.0f, 1e-7f);
    double seen = 0.0, sharp = 0.0;
    for (int i = 0; i < 64; ++i) {
        const glm::vec3 d = glm::normalize(glm::vec3(std::sin(0.7f * i), 0.05f + 0.9f * float(i % 8) / 8.0f, std::cos(0.7f * i)));
        EXPECT_EQ(sky.radiance(d, 4.0f * float(kPi) / 96.0f), sky.radiance(d, bound));
        EXPECT_EQ(sky.radiance(d, 1.0f), sky.radiance(d, bound));
        seen += std::abs(luma(sky.radiance(d, 4.0f * float(kPi) / 96.0f)) - luma(sky.radiance(d, 0.0f)));
        sharp += luma(sky.radiance(d, 0.0f));
    }
    // Below the bound the level still follows the ray's share: the blur is there, and small.
    EXPECT_GT(seen, 0.0);
    EXPECT_LT(seen / sharp, 0.02);
    // The SH of the sky projected from 96-ray-sized lookups at the texel centres keeps band 2 within 1 %.
    int w = 0, h = 0;
    sky.image(&w, &h);
    sh::ShRgb blurred;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double theta = kPi * (y + 0.5) / h, phi = ((x + 0.5) / w - 0.5) * 2.0 * kPi;
            const glm::vec3 d(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                              float(-std::sin(theta) * std::cos(phi)));
            const float dOmega = float(2.0 * kPi * kPi / (double(w) * h) * std::sin(theta));
            sh::accumulate(blurred, d, sky.radiance(d, 4.0f * float(kPi) / 96.0f), dOmega);
        }
    double band2 = 0.0, band2Exact = 0.0;
    for (int k = 4; k < 9; ++k) {
        band2 += luma(blurred.c[size_t(k)]) * luma(sky.sh().c[size_t(k)]);
        band2Exact += luma(sky.sh().c[size_t(k)]) * luma(sky.sh().c[size_t(k)]);
    }
    EXPECT_NEAR(band2 / band2Exact, 1.0, 0.01);
}
