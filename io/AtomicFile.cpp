#include "AtomicFile.h"
#include "FaultInjection.h"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>

#include <unistd.h>

namespace terralux {

std::filesystem::path temporarySibling(const std::filesystem::path& target) {
    static std::atomic<unsigned> counter{0};
    auto name = target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                std::to_string(counter.fetch_add(1));
    return target.parent_path() / name;
}

void writeFileAtomically(const std::filesystem::path& target, std::span<const uint8_t> bytes) {
    const std::filesystem::path tmp = temporarySibling(target);
    if (injectedFailure("write", tmp))
        throw FileWriteError(target.string() + ": cannot write (" + std::strerror(EIO) + ")");
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f)
        throw FileWriteError(target.string() + ": cannot write (" + std::strerror(errno) + ")");
    errno = 0;
    const bool written = bytes.empty() || std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    const int writeErr = errno;
    errno = 0;
    const bool flushed = std::fflush(f) == 0 && !injectedFailure("fsync", tmp) && ::fsync(::fileno(f)) == 0;
    const int flushErr = flushed ? 0 : errno ? errno : EIO;
    const bool closed = std::fclose(f) == 0;
    if (!written || !flushed || !closed) {
        const int err = !written ? writeErr : !flushed ? flushErr : errno;
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw FileWriteError(target.string() + ": write failed (" + std::strerror(err ? err : EIO) + ")");
    }
    std::error_code ec;
    if (injectedFailure("rename", target))
        ec = std::make_error_code(std::errc::io_error);
    else
        std::filesystem::rename(tmp, target, ec);
    if (ec) {
        const std::string reason = ec.message();
        std::filesystem::remove(tmp, ec);
        throw FileWriteError(target.string() + ": cannot replace (" + reason + ")");
    }
}

void writeFileAtomically(const std::filesystem::path& target, std::string_view text) {
    writeFileAtomically(target, std::span<const uint8_t>(
                                    reinterpret_cast<const uint8_t*>(text.data()), text.size()));
}

}  // namespace terralux
