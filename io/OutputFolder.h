#pragma once
// A bake's hold on its output folder (docs/formats.md, "Staged and atomic writes"): one bake writes
// into a folder at a time, and what a killed one left there is removed by the next.

#include <filesystem>
#include <vector>

namespace terralux {

// Takes `<dir>/.terralux.lock` with flock(LOCK_EX | LOCK_NB) and writes this process's pid into it;
// `dir` is created if missing. The kernel drops the lock when its process dies, so a killed bake
// never blocks the next one. Throws FileWriteError "<dir>: another bake is writing here (pid N);
// wait for it or choose another --out" when a live bake holds it, and for file system failures.
class OutputFolderLock {
public:
    explicit OutputFolderLock(const std::filesystem::path& dir);
    // Removes the lock file (the folder too when this lock created it and it stayed empty).
    ~OutputFolderLock();
    OutputFolderLock(const OutputFolderLock&) = delete;
    OutputFolderLock& operator=(const OutputFolderLock&) = delete;

private:
    void acquire();
    std::filesystem::path dir_, file_;
    int fd_ = -1;
    bool createdDir_ = false;
};

// Removes the leftovers of writers that died: ".staging-<pid>-..." folders in `dir` and
// "<name>.tmp-<pid>-..." files in `dir`, its sh_coeffs/ and reflection/, whose pid is no running
// process, or one that started after the leftover was last changed (a reused pid). Leftovers of
// this process and of live ones are kept. Returns what it removed.
std::vector<std::filesystem::path> removeStaleTemporaries(const std::filesystem::path& dir);

}  // namespace terralux
