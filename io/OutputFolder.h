#pragma once
// A bake's hold on its output folder (docs/formats.md, "Staged and atomic writes"): one bake writes
// into a folder at a time, and what a killed one left there is removed by the next.

#include <filesystem>
#include <vector>

namespace terralux {

// Takes flock(LOCK_EX | LOCK_NB) on `dir` itself (created if missing), so the lock leaves no file
// in the folder. The kernel drops the lock when its process dies, so a killed bake never blocks
// the next one. Throws FileWriteError "<dir>: another bake is writing here (pid N); wait for it or
// choose another --out" when a live bake holds it (the pid from /proc/locks), and for file system
// failures. A `.terralux.lock` that an earlier version left, unlocked, is removed.
class OutputFolderLock {
public:
    explicit OutputFolderLock(const std::filesystem::path& dir);
    // Lets go of the lock (and removes the folder when this lock created it and it stayed empty).
    ~OutputFolderLock();
    OutputFolderLock(const OutputFolderLock&) = delete;
    OutputFolderLock& operator=(const OutputFolderLock&) = delete;

private:
    void acquire();
    void removeLegacyLockFile();
    std::filesystem::path dir_;
    int fd_ = -1;
    bool createdDir_ = false;
};

// Removes the leftovers of writers that died: ".staging-<pid>-..." folders in `dir` and
// "<name>.tmp-<pid>-..." files in `dir`, its sh_coeffs/ and reflection/, whose pid is no running
// process, or one that started after the leftover was last changed (a reused pid). Leftovers of
// this process and of live ones are kept. Returns what it removed.
std::vector<std::filesystem::path> removeStaleTemporaries(const std::filesystem::path& dir);

}  // namespace terralux
