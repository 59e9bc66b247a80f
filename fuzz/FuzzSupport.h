#pragma once
// Shared by the fuzz targets: an invariant that fails is reported like a crash, so libFuzzer
// keeps the input that broke it.

#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>

namespace terralux::fuzz {

[[noreturn]] inline void invariantFailed(const char* what, const char* file, int line) {
    std::fprintf(stderr, "%s:%d: fuzz invariant failed: %s\n", file, line, what);
    std::abort();
}

}  // namespace terralux::fuzz

#define FUZZ_CHECK(cond) \
    ((cond) ? void(0) : ::terralux::fuzz::invariantFailed(#cond, __FILE__, __LINE__))
