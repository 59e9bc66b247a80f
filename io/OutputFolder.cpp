#include "OutputFolder.h"

#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "AtomicFile.h"

namespace terralux {

namespace {

namespace fs = std::filesystem;

constexpr const char* kLockName = ".terralux.lock";

std::string errnoText(int err) { return std::generic_category().message(err); }

// The pid a lock file names, if it names one yet.
std::optional<long> readPid(int fd) {
    char buf[32] = {};
    const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
    long pid = 0;
    if (n <= 0) return std::nullopt;
    const auto [end, ec] = std::from_chars(buf, buf + n, pid);
    if (ec != std::errc() || pid <= 0) return std::nullopt;
    return pid;
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

OutputFolderLock::OutputFolderLock(const fs::path& dir) : dir_(dir), file_(dir / kLockName) {
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
    // The holder removes the file before it lets go, so a lock taken on a file that is no longer
    // the one at the path is retried on the new file.
    for (int attempt = 0; attempt < 100; ++attempt) {
        const int fd = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (fd < 0)
            throw FileWriteError(file_.string() + ": cannot create the lock file (" + errnoText(errno) + ")");
        if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            const int err = errno;
            if (err != EWOULDBLOCK) {
                ::close(fd);
                throw FileWriteError(file_.string() + ": cannot lock (" + errnoText(err) + ")");
            }
            // The holder writes its pid right after it locks; give it that moment.
            std::optional<long> pid = readPid(fd);
            for (int i = 0; i < 20 && !pid; ++i) {
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
                pid = readPid(fd);
            }
            ::close(fd);
            throw FileWriteError(dir_.string() + ": another bake is writing here (pid " +
                                 (pid ? std::to_string(*pid) : std::string("unknown")) +
                                 "); wait for it or choose another --out");
        }
        struct stat held {}, named {};
        if (::fstat(fd, &held) != 0 || ::stat(file_.c_str(), &named) != 0 ||
            held.st_ino != named.st_ino || held.st_dev != named.st_dev) {
            ::close(fd);
            continue;
        }
        const std::string pid = std::to_string(::getpid()) + "\n";
        if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != ssize_t(pid.size())) {
            const int err = errno;
            ::unlink(file_.c_str());
            ::close(fd);
            throw FileWriteError(file_.string() + ": cannot write the lock file (" + errnoText(err) + ")");
        }
        fd_ = fd;
        return;
    }
    throw FileWriteError(file_.string() + ": cannot lock (the lock file keeps being replaced)");
}

OutputFolderLock::~OutputFolderLock() {
    // Unlinked while still held: whoever opened the old file sees it gone and retries.
    ::unlink(file_.c_str());
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
