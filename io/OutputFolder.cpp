#include "OutputFolder.h"

#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include "AtomicFile.h"

namespace terralux {

namespace {

namespace fs = std::filesystem;

constexpr const char* kLegacyLockName = ".terralux.lock";

std::string errnoText(int err) { return std::generic_category().message(err); }

// The process holding a flock lock on the file `fd` is open on, from the kernel's table of locks
// (/proc/locks: "1: FLOCK ADVISORY WRITE <pid> <major>:<minor>:<inode> 0 EOF", device numbers in
// hex), if it is listed there.
std::optional<long> flockHolder(int fd) {
    struct stat st {};
    if (::fstat(fd, &st) != 0) return std::nullopt;
    std::ifstream locks("/proc/locks");
    std::string line;
    while (std::getline(locks, line)) {
        std::istringstream fields(line);
        std::string index, kind, mode, access, id;
        long pid = 0;
        if (!(fields >> index >> kind) || kind != "FLOCK") continue;
        if (!(fields >> mode >> access >> pid >> id)) continue;
        unsigned major = 0, minor = 0;
        unsigned long long inode = 0;
        if (std::sscanf(id.c_str(), "%x:%x:%llu", &major, &minor, &inode) != 3) continue;
        if (inode == st.st_ino && major == ::major(st.st_dev) && minor == ::minor(st.st_dev) && pid > 0)
            return pid;
    }
    return std::nullopt;
}

// The pid in a leftover's name: the digits after `marker`, up to a '-'.
std::optional<long> pidInName(const std::string& name, size_t markerEnd) {
    long pid = 0;
    const char* first = name.data() + markerEnd;
    const char* last = name.data() + name.size();
    const auto [end, ec] = std::from_chars(first, last, pid);
    if (ec != std::errc() || end == first || end == last || *end != '-' || pid <= 0)
        return std::nullopt;
    return pid;
}

// Seconds since the epoch at which `pid` started (Linux /proc), if known.
std::optional<double> processStart(long pid) {
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string line;
    if (!std::getline(stat, line)) return std::nullopt;
    // Field 22, starttime in clock ticks since boot, counted after the ")" closing the name.
    const size_t close = line.rfind(')');
    if (close == std::string::npos) return std::nullopt;
    std::istringstream fields(line.substr(close + 1));
    std::string field;
    for (int i = 3; i <= 22; ++i)
        if (!(fields >> field)) return std::nullopt;
    std::ifstream boot("/proc/stat");
    std::string key;
    double btime = -1;
    while (boot >> key) {
        if (key == "btime") {
            boot >> btime;
            break;
        }
        boot.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    }
    const long ticks = ::sysconf(_SC_CLK_TCK);
    if (btime < 0 || ticks <= 0) return std::nullopt;
    return btime + std::stod(field) / double(ticks);
}

// Whether `pid` cannot be the writer of something last changed at `modified` (seconds since the
// epoch): no such process, or it started later (the pid was reused).
bool writerGone(long pid, double modified) {
    if (::kill(pid_t(pid), 0) != 0 && errno == ESRCH) return true;
    const std::optional<double> start = processStart(pid);
    // Two seconds of slack for the boot time's rounding.
    return start && *start > modified + 2.0;
}

double modifiedSeconds(const fs::path& p) {
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) return 0.0;
    return double(st.st_mtim.tv_sec) + 1e-9 * double(st.st_mtim.tv_nsec);
}

}  // namespace

OutputFolderLock::OutputFolderLock(const fs::path& dir) : dir_(dir) {
    std::error_code ec;
    const bool existed = fs::exists(dir_, ec);
    fs::create_directories(dir_, ec);
    if (ec || !fs::is_directory(dir_)) {
        throw FileWriteError(dir_.string() + ": cannot create the output folder (" +
                             (ec ? ec.message() : std::string("exists, not a folder")) + ")");
    }
    createdDir_ = !existed;
    try {
        acquire();
    } catch (...) {
        if (createdDir_ && fs::is_empty(dir_, ec) && !ec) fs::remove(dir_, ec);
        throw;
    }
}

void OutputFolderLock::acquire() {
    // The lock is on the folder itself, so nothing lands in it: an engine's importer watching the
    // export folder never sees a lock file, and a killed bake leaves none behind.
    const int fd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0)
        throw FileWriteError(dir_.string() + ": cannot open the output folder (" + errnoText(errno) + ")");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        const int err = errno;
        if (err != EWOULDBLOCK) {
            ::close(fd);
            throw FileWriteError(dir_.string() + ": cannot lock the output folder (" + errnoText(err) + ")");
        }
        const std::optional<long> pid = flockHolder(fd);
        ::close(fd);
        throw FileWriteError(dir_.string() + ": another bake is writing here (pid " +
                             (pid ? std::to_string(*pid) : std::string("unknown")) +
                             "); wait for it or choose another --out");
    }
    fd_ = fd;
    removeLegacyLockFile();
}

void OutputFolderLock::removeLegacyLockFile() {
    // Earlier versions locked `.terralux.lock` inside the folder; one a killed bake left is removed.
    // One that is still locked belongs to a live bake of such a version, which keeps it.
    const fs::path legacy = dir_ / kLegacyLockName;
    const int fd = ::open(legacy.c_str(), O_RDWR | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) return;
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) ::unlink(legacy.c_str());
    ::close(fd);
}

OutputFolderLock::~OutputFolderLock() {
    ::close(fd_);
    std::error_code ec;
    if (createdDir_ && fs::is_empty(dir_, ec) && !ec) fs::remove(dir_, ec);
}

std::vector<fs::path> removeStaleTemporaries(const fs::path& dir) {
    std::vector<std::pair<fs::path, std::optional<long>>> found;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        const std::string name = e.path().filename().string();
        if (name.rfind(".staging-", 0) == 0 && e.is_directory(ec))
            found.emplace_back(e.path(), pidInName(name, 9));
    }
    for (const fs::path& sub : {dir, dir / "sh_coeffs", dir / "reflection"}) {
        for (const auto& e : fs::directory_iterator(sub, ec)) {
            const std::string name = e.path().filename().string();
            const size_t at = name.rfind(".tmp-");
            if (at != std::string::npos && e.is_regular_file(ec))
                found.emplace_back(e.path(), pidInName(name, at + 5));
        }
    }
    std::vector<fs::path> removed;
    const long self = long(::getpid());
    for (const auto& [path, pid] : found) {
        if (!pid || *pid == self || !writerGone(*pid, modifiedSeconds(path))) continue;
        if (fs::remove_all(path, ec) != static_cast<std::uintmax_t>(-1) && !ec) removed.push_back(path);
    }
    return removed;
}

}  // namespace terralux
