// .shprobe v1: byte layout against a hand-built reference, round trips, every rejection rule,
// and the atomic-write guarantees.

#include "ShProbeFile.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace fs = std::filesystem;
using terralux::decodeShProbe;
using terralux::encodeShProbe;
using terralux::readShProbeFile;
using terralux::ShProbeError;
using terralux::ShProbeGrid;
using terralux::ShProbeRecord;
using terralux::writeShProbeFile;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr size_t kOccStart = 48 + 2 * 160;  // occupancy offset in the sample file

// Independent little-endian writer, so the reference bytes do not reuse the code under test.
struct LeBytes {
    std::vector<uint8_t> v;
    void u32(uint32_t x) {
        for (int i = 0; i < 4; ++i)
            v.push_back(static_cast<uint8_t>((x >> (8 * i)) & 0xFF));
    }
    void i32(int32_t x) {
        uint32_t u;
        std::memcpy(&u, &x, 4);
        u32(u);
    }
    void f32(float x) {
        uint32_t u;
        std::memcpy(&u, &x, 4);
        u32(u);
    }
    void zeros(size_t n) { v.insert(v.end(), n, 0); }
};

void putU32(std::vector<uint8_t>& b, size_t off, uint32_t x) {
    for (size_t i = 0; i < 4; ++i)
        b[off + i] = static_cast<uint8_t>((x >> (8 * i)) & 0xFF);
}
void putF32(std::vector<uint8_t>& b, size_t off, float x) {
    uint32_t u;
    std::memcpy(&u, &x, 4);
    putU32(b, off, u);
}
void putI32(std::vector<uint8_t>& b, size_t off, int32_t x) {
    uint32_t u;
    std::memcpy(&u, &x, 4);
    putU32(b, off, u);
}

// Distinct per probe / coefficient / channel, exactly representable.
float coeffValue(int probe, int k, int c) {
    return (probe == 0 ? 1.0f : -1.0f) *
               (static_cast<float>(k) + 0.25f * static_cast<float>(c + 1)) +
           100.0f * static_cast<float>(probe);
}

// 2 probes, 2x1x2 cells, probe 0 shared by two cells, one empty cell.
ShProbeGrid sampleGrid() {
    ShProbeGrid g;
    g.dims = {2, 1, 2};
    g.origin = {-1.5f, 2.0f, 3.25f};
    g.spacing = 0.5f;
    g.defaultScale = 1.25f;
    g.defaultAmbient = 0.2f;
    g.probes.resize(2);
    for (int p = 0; p < 2; ++p) {
        for (int k = 0; k < 9; ++k) {
            g.probes[static_cast<size_t>(p)].coeffs[static_cast<size_t>(k)] = {
                coeffValue(p, k, 0), coeffValue(p, k, 1), coeffValue(p, k, 2)};
        }
    }
    g.probes[0].scale = 0.75f;
    g.probes[0].ambient = 0.05f;
    g.probes[1].scale = 2.0f;
    g.probes[1].ambient = 0.3f;
    g.occupancy = {0, -1, 1, 0};
    return g;
}

std::vector<uint8_t> sampleBytesByHand() {
    LeBytes b;
    b.u32(0x52485053u);
    b.u32(1);
    b.u32(2);
    b.u32(2);
    b.u32(1);
    b.u32(2);
    b.f32(-1.5f);
    b.f32(2.0f);
    b.f32(3.25f);
    b.f32(0.5f);
    b.f32(1.25f);
    b.f32(0.2f);
    const float scales[2] = {0.75f, 2.0f};
    const float ambients[2] = {0.05f, 0.3f};
    for (int p = 0; p < 2; ++p) {
        for (int k = 0; k < 9; ++k) {
            b.f32(coeffValue(p, k, 0));
            b.f32(coeffValue(p, k, 1));
            b.f32(coeffValue(p, k, 2));
            b.f32(0.0f);
        }
        b.f32(scales[p]);
        b.f32(ambients[p]);
        b.zeros(8);
    }
    b.i32(0);
    b.i32(-1);
    b.i32(1);
    b.i32(0);
    return b.v;
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

template <class F>
std::string errorOf(F&& f) {
    try {
        f();
    } catch (const ShProbeError& e) {
        return e.what();
    }
    ADD_FAILURE() << "expected ShProbeError";
    return {};
}

// Decoding must fail with a message that starts with the name and contains `part`.
void expectDecodeError(const std::vector<uint8_t>& bytes, const std::string& part) {
    const std::string msg = errorOf([&] { decodeShProbe(bytes, "t.shprobe"); });
    EXPECT_EQ(msg.rfind("t.shprobe: ", 0), 0u) << msg;
    EXPECT_TRUE(contains(msg, part)) << "message: " << msg << "\nexpected to contain: " << part;
}

void expectEncodeError(const ShProbeGrid& g, const std::string& part) {
    const std::string msg = errorOf([&] { encodeShProbe(g); });
    EXPECT_TRUE(contains(msg, part)) << "message: " << msg << "\nexpected to contain: " << part;
}

std::vector<uint8_t> readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeAll(const fs::path& p, const std::vector<uint8_t>& bytes) {
    std::ofstream out(p, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
}

class ShProbeFileTest : public ::testing::Test {
protected:
    void SetUp() override {
        std::random_device rd;
        dir_ = fs::temp_directory_path() /
               ("terralux_shprobe_" + std::to_string(rd()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    std::vector<std::string> tempLeftovers() const {
        std::vector<std::string> out;
        for (const auto& e : fs::directory_iterator(dir_)) {
            const std::string n = e.path().filename().string();
            if (contains(n, ".tmp-"))
                out.push_back(n);
        }
        return out;
    }
    fs::path dir_;
};

}  // namespace

// ---- layout -------------------------------------------------------------------------------

TEST(ShProbeLayout, EncodeMatchesHandBuiltBytes) {
    const std::vector<uint8_t> expected = sampleBytesByHand();
    const std::vector<uint8_t> got = encodeShProbe(sampleGrid());
    ASSERT_EQ(expected.size(), 48u + 2u * 160u + 4u * 4u);
    ASSERT_EQ(got.size(), expected.size());
    for (size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i], expected[i]) << "first difference at byte " << i;
    }
}

TEST(ShProbeLayout, SpecificOffsets) {
    const std::vector<uint8_t> b = encodeShProbe(sampleGrid());
    // Literal byte patterns guard against a reference helper that shares a bug with the encoder.
    const std::vector<uint8_t> magic(b.begin(), b.begin() + 4);
    EXPECT_EQ(magic, (std::vector<uint8_t>{0x53, 0x50, 0x48, 0x52}));
    EXPECT_EQ(std::vector<uint8_t>(b.begin() + 4, b.begin() + 8),
              (std::vector<uint8_t>{0x01, 0x00, 0x00, 0x00}));
    EXPECT_EQ(b[8], 2);  // probe count
    EXPECT_EQ(b[12], 2);
    EXPECT_EQ(b[16], 1);
    EXPECT_EQ(b[20], 2);
    // origin X = -1.5f = 0xBFC00000
    EXPECT_EQ(std::vector<uint8_t>(b.begin() + 24, b.begin() + 28),
              (std::vector<uint8_t>{0x00, 0x00, 0xC0, 0xBF}));
    // spacing 0.5f = 0x3F000000
    EXPECT_EQ(std::vector<uint8_t>(b.begin() + 36, b.begin() + 40),
              (std::vector<uint8_t>{0x00, 0x00, 0x00, 0x3F}));
    // record 1 scale 2.0f = 0x40000000 at 48 + 160 + 144
    const size_t scale1 = 48 + 160 + 144;
    EXPECT_EQ(std::vector<uint8_t>(b.begin() + scale1, b.begin() + scale1 + 4),
              (std::vector<uint8_t>{0x00, 0x00, 0x00, 0x40}));
    for (size_t rec = 0; rec < 2; ++rec) {
        const size_t base = 48 + 160 * rec;
        for (size_t i = 152; i < 160; ++i)
            EXPECT_EQ(b[base + i], 0) << "record " << rec << " +" << i;
        for (size_t k = 0; k < 9; ++k) {
            for (size_t i = 12; i < 16; ++i)
                EXPECT_EQ(b[base + 16 * k + i], 0) << "w lane " << k;
        }
    }
    // occupancy {0, -1, 1, 0} starts right after the records
    EXPECT_EQ(std::vector<uint8_t>(b.begin() + kOccStart, b.end()),
              (std::vector<uint8_t>{0, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0xFF, 1, 0, 0, 0, 0, 0, 0, 0}));
}

TEST(ShProbeLayout, DecodeHandBuiltBytes) {
    EXPECT_EQ(decodeShProbe(sampleBytesByHand(), "t.shprobe"), sampleGrid());
}

TEST(ShProbeLayout, CellIndexAndFileSize) {
    ShProbeGrid g;
    g.dims = {3, 4, 5};
    EXPECT_EQ(g.cellIndex(0, 0, 0), 0u);
    EXPECT_EQ(g.cellIndex(2, 0, 0), 2u);
    EXPECT_EQ(g.cellIndex(1, 2, 0), 1u + 2u * 3u);
    EXPECT_EQ(g.cellIndex(1, 2, 3), 1u + 2u * 3u + 3u * 12u);
    g.probes.resize(7);
    EXPECT_EQ(g.fileSize(), 48u + 160u * 7u + 4u * 60u);
    EXPECT_EQ(sampleGrid().fileSize(), encodeShProbe(sampleGrid()).size());
    g.dims = {0xFFFFFFFFu, 0xFFFFFFFFu, 0xFFFFFFFFu};
    EXPECT_EQ(g.fileSize(), std::numeric_limits<uint64_t>::max());
}

// ---- round trips --------------------------------------------------------------------------

TEST(ShProbeRoundTrip, DecodeOfEncode) {
    const ShProbeGrid g = sampleGrid();
    EXPECT_EQ(decodeShProbe(encodeShProbe(g), "x"), g);

    ShProbeGrid empty;  // default: 1 cell, no probes
    empty.occupancy = {-1};
    EXPECT_EQ(decodeShProbe(encodeShProbe(empty), "x"), empty);

    ShProbeGrid big;
    big.dims = {5, 3, 4};
    big.origin = {-1e6f, 0.0f, 123.456f};
    big.spacing = 7.5f;
    big.probes.resize(11);
    for (size_t p = 0; p < big.probes.size(); ++p) {
        for (size_t k = 0; k < 9; ++k) {
            big.probes[p].coeffs[k] = {1e-30f * static_cast<float>(p), -3.0e30f,
                                       0.1f * static_cast<float>(k)};
        }
        big.probes[p].scale = 0.5f + static_cast<float>(p);
        big.probes[p].ambient = -0.25f;
    }
    big.occupancy.assign(60, -1);
    for (size_t i = 0; i < big.occupancy.size(); i += 3)
        big.occupancy[i] = static_cast<int32_t>(i % 11);
    EXPECT_EQ(decodeShProbe(encodeShProbe(big), "x"), big);
}

TEST_F(ShProbeFileTest, FileRoundTrip) {
    const fs::path p = dir_ / "probes.shprobe";
    writeShProbeFile(p, sampleGrid());
    EXPECT_EQ(readAll(p), sampleBytesByHand());
    EXPECT_EQ(readShProbeFile(p), sampleGrid());
    EXPECT_TRUE(tempLeftovers().empty());
}

TEST_F(ShProbeFileTest, OverwriteReplacesExisting) {
    const fs::path p = dir_ / "probes.shprobe";
    writeAll(p, std::vector<uint8_t>(1000, 0xAB));
    writeShProbeFile(p, sampleGrid());
    EXPECT_EQ(readShProbeFile(p), sampleGrid());
    EXPECT_TRUE(tempLeftovers().empty());
}

// ---- rejections ---------------------------------------------------------------------------

TEST(ShProbeReject, BadMagic) {
    auto b = sampleBytesByHand();
    putU32(b, 0, 0x12345678u);
    expectDecodeError(b, "magic 0x12345678, expected 0x52485053");
}

TEST(ShProbeReject, BadVersion) {
    auto b = sampleBytesByHand();
    putU32(b, 4, 2);
    expectDecodeError(b, "version = 2");
    putU32(b, 4, 0);
    expectDecodeError(b, "version = 0");
}

TEST(ShProbeReject, TruncatedHeader) {
    const auto full = sampleBytesByHand();
    expectDecodeError(std::vector<uint8_t>(full.begin(), full.begin() + 47),
                      "file is 47 bytes, shorter than the 48-byte header");
    expectDecodeError({}, "file is 0 bytes, shorter than the 48-byte header");
}

TEST(ShProbeReject, SizeTooSmall) {
    auto b = sampleBytesByHand();
    b.pop_back();
    expectDecodeError(b, "file is 383 bytes, header needs 48 + 160*2 + 4*4 = 384");
    // Header alone claiming probes.
    b.resize(48);
    expectDecodeError(b, "file is 48 bytes, header needs 48 + 160*2 + 4*4 = 384");
}

TEST(ShProbeReject, SizeTooLargeByOne) {
    auto b = sampleBytesByHand();
    b.push_back(0);
    expectDecodeError(b, "file is 385 bytes, header needs 48 + 160*2 + 4*4 = 384");
}

TEST(ShProbeReject, ZeroDims) {
    const char* axes[3] = {"X", "Y", "Z"};
    for (size_t a = 0; a < 3; ++a) {
        auto b = sampleBytesByHand();
        putU32(b, 12 + 4 * a, 0);
        expectDecodeError(b, std::string("grid dim ") + axes[a] + " = 0");
    }
}

TEST(ShProbeReject, CellProductOverflows64Bits) {
    auto b = sampleBytesByHand();
    putU32(b, 12, 0xFFFFFFFFu);
    putU32(b, 16, 0xFFFFFFFFu);
    putU32(b, 20, 0xFFFFFFFFu);
    expectDecodeError(b, "grid dims 4294967295 x 4294967295 x 4294967295");
}

TEST(ShProbeReject, OccupancyBytesOverflow64Bits) {
    // 2^31 * 2^31 * 2 = 2^63 cells fits; 4 * cells does not.
    auto b = sampleBytesByHand();
    putU32(b, 12, 0x80000000u);
    putU32(b, 16, 0x80000000u);
    putU32(b, 20, 2);
    expectDecodeError(b, "grid dims 2147483648 x 2147483648 x 2");
    // 2^31 * 2^31 * 1 = 2^62 cells: 4 * cells is exactly 2^64.
    putU32(b, 20, 1);
    expectDecodeError(b, "grid dims 2147483648 x 2147483648 x 1");
}

TEST(ShProbeReject, TotalSizeOverflows64Bits) {
    // (2^31 - 1) * 715827883 * 3 = 2^62 - 1 cells: 4 * cells = 2^64 - 4 fits, adding the header
    // does not.
    auto b = sampleBytesByHand();
    putU32(b, 12, 2147483647u);
    putU32(b, 16, 715827883u);
    putU32(b, 20, 3);
    expectDecodeError(b, "grid dims 2147483647 x 715827883 x 3");
}

TEST(ShProbeReject, HugeButRepresentableDimsInTinyFile) {
    // 2^48 cells: no overflow, so it must be a plain size mismatch (and must not allocate).
    auto b = sampleBytesByHand();
    putU32(b, 12, 65536);
    putU32(b, 16, 65536);
    putU32(b, 20, 65536);
    expectDecodeError(b, "file is 384 bytes, header needs 48 + 160*2 + 4*281474976710656");
}

TEST(ShProbeReject, Spacing) {
    const std::pair<float, const char*> cases[] = {
        {0.0f, "grid spacing = 0 must be finite and > 0"},
        {-1.0f, "grid spacing = -1 must be finite and > 0"},
        {kNaN, "grid spacing = nan"},
        {kInf, "grid spacing = inf"},
        {-kInf, "grid spacing = -inf"},
    };
    for (const auto& [value, part] : cases) {
        auto b = sampleBytesByHand();
        putF32(b, 36, value);
        expectDecodeError(b, part);
    }
}

TEST(ShProbeReject, NonFiniteOriginAndDefaults) {
    const char* axes[3] = {"X", "Y", "Z"};
    for (size_t a = 0; a < 3; ++a) {
        auto b = sampleBytesByHand();
        putF32(b, 24 + 4 * a, kNaN);
        expectDecodeError(b, std::string("grid origin ") + axes[a] + " = nan must be finite");
    }
    auto b = sampleBytesByHand();
    putF32(b, 40, kInf);
    expectDecodeError(b, "default SH scale = inf must be finite");
    b = sampleBytesByHand();
    putF32(b, 44, kNaN);
    expectDecodeError(b, "default ambient = nan must be finite");
}

TEST(ShProbeReject, OccupancyOutOfRange) {
    auto b = sampleBytesByHand();
    putI32(b, kOccStart + 4 * 1, 2);  // == count
    expectDecodeError(b, "occupancy[1] = 2 is outside [-1, 2)");
    b = sampleBytesByHand();
    putI32(b, kOccStart + 4 * 3, -2);
    expectDecodeError(b, "occupancy[3] = -2 is outside [-1, 2)");
    b = sampleBytesByHand();
    putI32(b, kOccStart, std::numeric_limits<int32_t>::min());
    expectDecodeError(b, "occupancy[0] = -2147483648 is outside [-1, 2)");
}

TEST(ShProbeReject, NonFiniteCoefficients) {
    auto b = sampleBytesByHand();
    putF32(b, 48 + 160 * 1 + 16 * 4 + 4 * 1, kNaN);
    expectDecodeError(b, "probe 1 coefficient 4 (G) is not finite");
    b = sampleBytesByHand();
    putF32(b, 48 + 160 * 0 + 16 * 8 + 4 * 2, kInf);
    expectDecodeError(b, "probe 0 coefficient 8 (B) is not finite");
    b = sampleBytesByHand();
    putF32(b, 48 + 160 * 1 + 16 * 0 + 4 * 0, -kInf);
    expectDecodeError(b, "probe 1 coefficient 0 (R) is not finite");
}

TEST(ShProbeReject, NonFiniteProbeScaleAndAmbient) {
    auto b = sampleBytesByHand();
    putF32(b, 48 + 160 * 1 + 144, kNaN);
    expectDecodeError(b, "probe 1 scale = nan must be finite");
    b = sampleBytesByHand();
    putF32(b, 48 + 148, kInf);
    expectDecodeError(b, "probe 0 ambient = inf must be finite");
}

TEST(ShProbeReject, EncoderAppliesTheSameRules) {
    ShProbeGrid g = sampleGrid();
    g.occupancy.pop_back();
    expectEncodeError(g, "occupancy has 3 entries, grid dims 2 x 1 x 2 need 4");

    g = sampleGrid();
    g.dims.y = 0;
    expectEncodeError(g, "grid dim Y = 0");

    g = sampleGrid();
    g.dims = {0xFFFFFFFFu, 0xFFFFFFFFu, 0xFFFFFFFFu};
    expectEncodeError(g, "grid dims 4294967295 x 4294967295 x 4294967295");

    g = sampleGrid();
    g.spacing = -2.0f;
    expectEncodeError(g, "grid spacing = -2");

    g = sampleGrid();
    g.origin.z = kInf;
    expectEncodeError(g, "grid origin Z = inf");

    g = sampleGrid();
    g.occupancy[2] = 5;
    expectEncodeError(g, "occupancy[2] = 5 is outside [-1, 2)");

    g = sampleGrid();
    g.probes[1].coeffs[6].r = kNaN;
    expectEncodeError(g, "probe 1 coefficient 6 (R) is not finite");

    g = sampleGrid();
    g.probes[0].ambient = kNaN;
    expectEncodeError(g, "probe 0 ambient = nan");
}

// ---- file I/O -----------------------------------------------------------------------------

TEST_F(ShProbeFileTest, ReadErrorsStartWithPath) {
    const fs::path p = dir_ / "bad.shprobe";
    auto b = sampleBytesByHand();
    putF32(b, 36, 0.0f);
    writeAll(p, b);
    const std::string msg = errorOf([&] { readShProbeFile(p); });
    EXPECT_EQ(msg.rfind(p.string() + ": ", 0), 0u) << msg;
    EXPECT_TRUE(contains(msg, "grid spacing = 0")) << msg;

    // Forged header with huge dims: rejected from the header, before reading the body.
    b = sampleBytesByHand();
    putU32(b, 12, 65536);
    putU32(b, 16, 65536);
    writeAll(p, b);
    EXPECT_TRUE(contains(errorOf([&] { readShProbeFile(p); }), "file is 384 bytes, header needs"));

    writeAll(p, std::vector<uint8_t>(10, 0));
    EXPECT_TRUE(contains(errorOf([&] { readShProbeFile(p); }), "shorter than the 48-byte header"));

    const fs::path missing = dir_ / "missing.shprobe";
    const std::string msg2 = errorOf([&] { readShProbeFile(missing); });
    EXPECT_EQ(msg2.rfind(missing.string() + ": ", 0), 0u) << msg2;

    const std::string msg3 = errorOf([&] { readShProbeFile(dir_); });
    EXPECT_EQ(msg3.rfind(dir_.string() + ": ", 0), 0u) << msg3;
}

TEST_F(ShProbeFileTest, WriteIntoMissingDirectoryLeavesNothing) {
    const fs::path sub = dir_ / "no_such_dir";
    const fs::path p = sub / "probes.shprobe";
    const std::string msg = errorOf([&] { writeShProbeFile(p, sampleGrid()); });
    EXPECT_EQ(msg.rfind(p.string() + ": ", 0), 0u) << msg;
    EXPECT_FALSE(fs::exists(sub));
    EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(ShProbeFileTest, FailedEncodeLeavesExistingFileUntouched) {
    const fs::path p = dir_ / "probes.shprobe";
    writeShProbeFile(p, sampleGrid());
    const std::vector<uint8_t> before = readAll(p);

    ShProbeGrid bad = sampleGrid();
    bad.probes[0].coeffs[3].g = kNaN;
    const std::string msg = errorOf([&] { writeShProbeFile(p, bad); });
    EXPECT_EQ(msg.rfind(p.string() + ": ", 0), 0u) << msg;
    EXPECT_TRUE(contains(msg, "probe 0 coefficient 3 (G) is not finite")) << msg;

    EXPECT_EQ(readAll(p), before);
    EXPECT_TRUE(tempLeftovers().empty());
}

TEST_F(ShProbeFileTest, FailedRenameRemovesTemporary) {
    // A non-empty directory at the target path makes the final rename fail after the temporary
    // has been written.
    const fs::path target = dir_ / "probes.shprobe";
    fs::create_directories(target / "keep");
    EXPECT_THROW(writeShProbeFile(target, sampleGrid()), ShProbeError);
    EXPECT_TRUE(fs::is_directory(target / "keep"));
    EXPECT_TRUE(tempLeftovers().empty());
}
