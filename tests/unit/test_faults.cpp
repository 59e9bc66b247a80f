// Failures of the file layer (docs/formats.md, "Staged and atomic writes"): an injected failure at
// every file operation of a save or an export leaves the earlier files byte-identical and nothing
// temporary behind; a bake's output folder lock; a dead writer's leftovers.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include "AtomicFile.h"
#include "FaultInjection.h"
#include "GltfExport.h"
#include "ImageFile.h"
#include "OutputFolder.h"
#include "Project.h"
#include "ShProbeFile.h"
#include "scene/ImageCodes.h"

namespace fs = std::filesystem;
using namespace terralux;

namespace {

std::string readText(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// Every file below `dir` (relative path to contents), and every directory as an empty entry.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
    std::map<std::string, std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::string rel = fs::relative(e.path(), dir).generic_string();
        out[rel] = e.is_directory() ? std::string("<dir>") : readText(e.path());
    }
    return out;
}

// Staging folders and temporaries left anywhere below `dir`.
std::vector<std::string> leftovers(const fs::path& dir) {
    std::vector<std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        if (name.find(".tmp-") != std::string::npos || name.rfind(".staging-", 0) == 0)
            out.push_back(fs::relative(e.path(), dir).generic_string());
    }
    return out;
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

class Faults : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir = fs::temp_directory_path() /
              ("terralux_test_faults_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir);
        fs::create_directories(dir);
        resetFaultInjection(0);
    }
    void TearDown() override {
        resetFaultInjection(0);
        fs::remove_all(dir);
    }

    // The operations `f` does, counted with no failure injected.
    static uint64_t countOps(const std::function<void()>& f) {
        resetFaultInjection(0);
        f();
        const uint64_t n = fileOperationCount();
        resetFaultInjection(0);
        return n;
    }

    fs::path dir;
};

TEST_F(Faults, ProjectSaveNeverLeavesATruncatedFile) {
    const fs::path file = dir / "p.terralux.json";
    Project before;
    before.baseDir = dir;
    saveProject(before, file);
    const std::string old = readText(file);
    Project after = before;
    after.scene.sun.elevationDeg = 12.5;

    // Write the temporary, fsync it, rename it over the project.
    const uint64_t ops = countOps([&] { saveProject(after, file); });
    EXPECT_EQ(ops, 3u);
    const std::string fresh = readText(file);
    ASSERT_NE(fresh, old);

    for (uint64_t n = 1; n <= ops; ++n) {
        saveProject(before, file);
        resetFaultInjection(n);
        const std::string msg = errorOf([&] { saveProject(after, file); });
        resetFaultInjection(0);
        EXPECT_EQ(msg.rfind(file.string() + ": ", 0), 0u) << "op " << n << ": " << msg;
        EXPECT_EQ(readText(file), old) << "op " << n;
        EXPECT_TRUE(leftovers(dir).empty()) << "op " << n;
    }
    resetFaultInjection(ops + 1);
    saveProject(after, file);
    EXPECT_EQ(readText(file), fresh);
}

ShProbeGrid grid(float value) {
    ShProbeGrid g;
    g.dims = {2, 1, 1};
    g.spacing = 1.0f;
    g.probes.resize(2);
    for (auto& p : g.probes) p.coeffs[0] = glm::vec3(value);
    g.occupancy = {0, 1};
    return g;
}

TEST_F(Faults, ShProbeWriteLeavesTheOldFileOrTheNew) {
    const fs::path file = dir / "v.shprobe";
    writeShProbeFile(file, grid(1.0f));
    const std::string old = readText(file);

    const uint64_t ops = countOps([&] { writeShProbeFile(file, grid(2.0f)); });
    EXPECT_EQ(ops, 3u);
    for (uint64_t n = 1; n <= ops; ++n) {
        writeShProbeFile(file, grid(1.0f));
        resetFaultInjection(n);
        const std::string msg = errorOf([&] { writeShProbeFile(file, grid(2.0f)); });
        resetFaultInjection(0);
        EXPECT_EQ(msg.rfind(file.string() + ": ", 0), 0u) << "op " << n << ": " << msg;
        EXPECT_EQ(readText(file), old) << "op " << n;
        EXPECT_TRUE(leftovers(dir).empty()) << "op " << n;
    }
}

Heightfield terrain(float lift) {
    std::vector<float> h(16);
    for (size_t i = 0; i < h.size(); ++i) h[i] = lift + float(std::sin(double(i)));
    return Heightfield(4, 4, 2.0, 2.0, std::move(h));
}

GltfSceneInput scene(const Heightfield& hf, std::vector<std::string> volumes, float value) {
    GltfSceneInput in;
    in.heightfield = &hf;
    for (const auto& name : volumes) in.volumes.push_back({name, grid(value), "{\"probes\": []}\n"});
    in.reflectionFiles.push_back({"probes.rprobe", std::vector<uint8_t>(40, uint8_t(value))});
    in.extraFiles.push_back({"bake_report.json", "{\"value\": " + std::to_string(value) + "}\n"});
    return in;
}

// A commit that replaces files, adds one and retires a stale one fails at each of its operations
// in turn: the folder is byte-identical afterwards, with no staging folder left.
TEST_F(Faults, ExportFailingAtAnyOperationLeavesTheEarlierFiles) {
    const Heightfield first = terrain(10.0f), second = terrain(20.0f);
    exportGltfScene(dir, scene(first, {"a", "b"}, 1.0f));
    const auto before = snapshot(dir);

    const GltfSceneInput next = scene(second, {"b", "c"}, 2.0f);
    const fs::path copy = dir.string() + "_count";
    fs::remove_all(copy);
    fs::copy(dir, copy, fs::copy_options::recursive);
    const uint64_t ops = countOps([&] { exportGltfScene(copy, next); });
    fs::remove_all(copy);
    // 8 files written and synced, a.shprobe and its sidecar moved aside, 8 files renamed into
    // place, the 6 that exist before kept for rollback, sh_coeffs/, reflection/ and the folder
    // synced.
    EXPECT_EQ(ops, 8u * 2 + 2 + 8 + 6 + 3);

    for (uint64_t n = 1; n <= ops; ++n) {
        resetFaultInjection(n);
        const std::string msg = errorOf([&] { exportGltfScene(dir, next); });
        resetFaultInjection(0);
        EXPECT_EQ(msg.rfind(dir.string(), 0), 0u) << "op " << n << ": " << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
        EXPECT_TRUE(snapshot(dir) == before) << "op " << n << " (" << msg << ") changed the folder";
        EXPECT_TRUE(leftovers(dir).empty()) << "op " << n;
    }
    resetFaultInjection(ops + 1);
    exportGltfScene(dir, next);
    EXPECT_FALSE(snapshot(dir) == before);
    EXPECT_FALSE(fs::exists(dir / "sh_coeffs/a.shprobe"));
}

// Into an empty folder: a failure removes the sh_coeffs/ and reflection/ folders it made.
TEST_F(Faults, FirstExportFailingLeavesAnEmptyFolder) {
    const Heightfield hf = terrain(10.0f);
    const GltfSceneInput in = scene(hf, {"a"}, 1.0f);
    const uint64_t ops = countOps([&] { exportGltfScene(dir, in); });
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (uint64_t n = 1; n <= ops; ++n) {
        resetFaultInjection(n);
        EXPECT_THROW(exportGltfScene(dir, in), FileWriteError) << "op " << n;
        resetFaultInjection(0);
        EXPECT_TRUE(fs::is_empty(dir)) << "op " << n;
    }
}

TEST_F(Faults, OneBakePerFolder) {
    const fs::path out = dir / "out";
    {
        const OutputFolderLock held(out);
        ASSERT_TRUE(fs::is_directory(out));
        // The lock is on the folder: nothing lands in the export.
        EXPECT_TRUE(fs::is_empty(out));
        // flock locks belong to the open file, so a second lock conflicts within one process too.
        const std::string msg = errorOf([&] { OutputFolderLock again(out); });
        EXPECT_EQ(msg, out.string() + ": another bake is writing here (pid " +
                           std::to_string(::getpid()) + "); wait for it or choose another --out");
    }
    // Released: the lock file is gone, and so is the folder the lock made for nothing.
    EXPECT_FALSE(fs::exists(out));
    fs::create_directories(out);
    { const OutputFolderLock again(out); }
    EXPECT_TRUE(fs::is_directory(out));
    EXPECT_TRUE(fs::is_empty(out));
}

TEST_F(Faults, ADeadHoldersLockDoesNotBlock) {
    const fs::path out = dir / "out";
    fs::create_directories(out);
    int ready[2];
    ASSERT_EQ(::pipe(ready), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        // Holds the lock until killed: no destructor runs, the lock file stays.
        new OutputFolderLock(out);
        (void)!::write(ready[1], "x", 1);
        for (;;) ::pause();
    }
    char c = 0;
    ASSERT_EQ(::read(ready[0], &c, 1), 1);
    EXPECT_NE(errorOf([&] { OutputFolderLock busy(out); }).find("(pid " + std::to_string(child) + ")"),
              std::string::npos);
    EXPECT_TRUE(fs::is_empty(out));
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
    // The killed holder left nothing in the folder, and its lock went with it.
    EXPECT_TRUE(fs::is_empty(out));
    EXPECT_EQ(errorOf([&] { OutputFolderLock mine(out); }), "");
    ::close(ready[0]);
    ::close(ready[1]);
}

// Every output is the same bytes from run to run: an EXR too, which OpenImageIO would otherwise
// stamp with the second it was written.
TEST_F(Faults, AnExrIsTheSameBytesWhenWrittenAgain) {
    std::vector<float> rgba(8 * 4 * 4, 0.25f);
    writeImage(dir / "a.exr", 8, 4, rgba);
    std::this_thread::sleep_for(std::chrono::milliseconds(1100));
    writeImage(dir / "b.exr", 8, 4, rgba);
    EXPECT_EQ(readText(dir / "a.exr"), readText(dir / "b.exr"));
    uint32_t w = 0, h = 0;
    EXPECT_EQ(readImageRgba(dir / "b.exr", w, h), rgba);
}

// A PNG written from a frame's 8-bit codes is the file written from its floats; the codes are
// refused as an EXR, which holds scene-linear floats.
TEST_F(Faults, APngFromCodesIsThePngFromFloatsAndAnExrRefusesCodes) {
    std::vector<float> rgba(8 * 4 * 4);
    for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = float(i) / 100.0f - 0.1f;  // below 0 to above 1
    rgba[5] = std::numeric_limits<float>::quiet_NaN();
    rgba[6] = std::numeric_limits<float>::infinity();
    rgba[7] = 0.5f;
    std::vector<uint8_t> codes(rgba.size());
    for (size_t i = 0; i < rgba.size(); ++i) codes[i] = unitToByte(rgba[i]);
    EXPECT_EQ(codes[0], 0);
    EXPECT_EQ(codes[5], 0);
    EXPECT_EQ(codes[6], 0);
    EXPECT_EQ(codes[7], 128);  // 0.5 * 255 = 127.5, rounded away from zero
    EXPECT_EQ(codes.back(), 255);
    writeImage(dir / "floats.png", 8, 4, rgba);
    writeImage(dir / "codes.png", 8, 4, codes);
    EXPECT_EQ(readText(dir / "floats.png"), readText(dir / "codes.png"));
    EXPECT_EQ(errorOf([&] { writeImage(dir / "codes.exr", 8, 4, codes); }),
              (dir / "codes.exr").string() +
                  ": 8-bit samples cannot be written as EXR, which holds scene-linear floats; use .png");
    EXPECT_FALSE(fs::exists(dir / "codes.exr"));
}

// The lock file an earlier version's killed bake left is removed; a locked one is kept.
TEST_F(Faults, ALegacyLockFileIsRemovedUnlessHeld) {
    const fs::path out = dir / "out";
    fs::create_directories(out);
    { std::ofstream(out / ".terralux.lock") << "12345\n"; }
    { const OutputFolderLock mine(out); }
    EXPECT_FALSE(fs::exists(out / ".terralux.lock"));
    { std::ofstream(out / ".terralux.lock") << "12345\n"; }
    const int held = ::open((out / ".terralux.lock").c_str(), O_RDWR);
    ASSERT_GE(held, 0);
    ASSERT_EQ(::flock(held, LOCK_EX | LOCK_NB), 0);
    { const OutputFolderLock mine(out); }
    EXPECT_TRUE(fs::exists(out / ".terralux.lock"));
    ::close(held);
}

TEST_F(Faults, RemovesWhatDeadWritersLeft) {
    // A pid that is surely free: a child that has exited and been reaped.
    const pid_t dead = ::fork();
    if (dead == 0) ::_exit(0);
    ::waitpid(dead, nullptr, 0);
    const std::string d = std::to_string(dead), self = std::to_string(::getpid());
    fs::create_directories(dir / "sh_coeffs");
    fs::create_directories(dir / (".staging-" + d + "-0-00ff"));
    std::ofstream(dir / (".staging-" + d + "-0-00ff") / "scene.gltf") << "x";
    fs::create_directories(dir / (".staging-" + self + "-0-00ff"));  // this process: may be live
    fs::create_directories(dir / ".staging-1-0-00ff");                // pid 1 lives, started earlier
    fs::create_directories(dir / ".staging-1-1-00ff");                // pid 1 started after this
    fs::last_write_time(dir / ".staging-1-1-00ff", fs::file_time_type::clock::now() - std::chrono::hours(24 * 365 * 30));
    std::ofstream(dir / ("scene.gltf.tmp-" + d + "-3")) << "x";
    std::ofstream(dir / "sh_coeffs" / ("v.shprobe.tmp-" + d + "-00ab")) << "x";
    std::ofstream(dir / "notes.tmp-x") << "mine";  // no pid: not ours to judge
    std::ofstream(dir / "keep.txt") << "mine";

    const auto removed = removeStaleTemporaries(dir);
    EXPECT_EQ(removed.size(), 4u);
    EXPECT_FALSE(fs::exists(dir / (".staging-" + d + "-0-00ff")));
    EXPECT_FALSE(fs::exists(dir / ".staging-1-1-00ff"));
    EXPECT_FALSE(fs::exists(dir / ("scene.gltf.tmp-" + d + "-3")));
    EXPECT_FALSE(fs::exists(dir / "sh_coeffs" / ("v.shprobe.tmp-" + d + "-00ab")));
    EXPECT_TRUE(fs::exists(dir / (".staging-" + self + "-0-00ff")));
    EXPECT_TRUE(fs::exists(dir / ".staging-1-0-00ff"));
    EXPECT_TRUE(fs::exists(dir / "notes.tmp-x"));
    EXPECT_TRUE(fs::exists(dir / "keep.txt"));
}

}  // namespace
