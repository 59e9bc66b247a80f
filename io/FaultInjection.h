#pragma once
// Fault injection for tests (docs/formats.md, "Staged and atomic writes"): every forward file
// operation of the file layer (writing a file, fsync, rename, keeping a previous file for
// rollback) asks injectedFailure() first, and fails as if the system call had returned EIO when
// it answers true. Rollback and cleanup never ask: they undo what was done.
//
//   TERRALUX_FAIL_FILE_OP=N    the Nth operation of the process (1-based) fails
//   TERRALUX_COUNT_FILE_OPS=1  print "terralux: N file operations (...)" to stderr at exit

#include <cstdint>
#include <filesystem>

namespace terralux {

// Counts the operation and says whether it is the one to fail. `op` is a string literal
// ("write", "fsync", "rename", "link"). Thread-safe.
bool injectedFailure(const char* op, const std::filesystem::path& path);

// Operations counted since the start (or the last resetFaultInjection).
uint64_t fileOperationCount();

// For unit tests: restart the count and make the Nth operation from now fail (0: none),
// overriding TERRALUX_FAIL_FILE_OP.
void resetFaultInjection(uint64_t failAt);

}  // namespace terralux
