#pragma once
// Exports never leave a half-written file: write a temporary sibling, then rename over the target.

#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string_view>

namespace terralux {

class FileWriteError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Writes `bytes` to `<target>.tmp-<unique>` in the target's directory, flushes, closes and renames
// it over `target`. On failure the temporary is removed, `target` is untouched, and
// FileWriteError names the file and the reason.
void writeFileAtomically(const std::filesystem::path& target, std::span<const uint8_t> bytes);
void writeFileAtomically(const std::filesystem::path& target, std::string_view text);

// A unique temporary sibling name for `target` (used for directories of several files too).
std::filesystem::path temporarySibling(const std::filesystem::path& target);

}  // namespace terralux
