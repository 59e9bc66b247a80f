#include "FaultInjection.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace terralux {

namespace {

constexpr const char* kOps[] = {"write", "fsync", "rename", "link"};
constexpr size_t kOpCount = sizeof kOps / sizeof kOps[0];

uint64_t envNumber(const char* name) {
    const char* v = std::getenv(name);
    if (!v || !*v) return 0;
    char* end = nullptr;
    const unsigned long long n = std::strtoull(v, &end, 10);
    return *end == '\0' ? uint64_t(n) : 0;
}

struct State {
    std::atomic<uint64_t> failAt{envNumber("TERRALUX_FAIL_FILE_OP")};
    std::atomic<uint64_t> count{0};
    std::atomic<uint64_t> byOp[kOpCount] = {};
    const bool report = envNumber("TERRALUX_COUNT_FILE_OPS") != 0;

    ~State() {
        if (!report) return;
        std::string kinds;
        for (size_t i = 0; i < kOpCount; ++i)
            kinds += (i ? ", " : "") + std::string(kOps[i]) + " " + std::to_string(byOp[i].load());
        std::fprintf(stderr, "terralux: %llu file operations (%s)\n",
                     static_cast<unsigned long long>(count.load()), kinds.c_str());
    }
};

// Constructed on first use, so the environment is read once, before any operation.
State& state() {
    static State s;
    return s;
}

}  // namespace

bool injectedFailure(const char* op, const std::filesystem::path&) {
    State& s = state();
    for (size_t i = 0; i < kOpCount; ++i)
        if (std::strcmp(op, kOps[i]) == 0) s.byOp[i].fetch_add(1);
    const uint64_t n = s.count.fetch_add(1) + 1;
    return n == s.failAt.load();
}

uint64_t fileOperationCount() { return state().count.load(); }

void resetFaultInjection(uint64_t failAt) {
    State& s = state();
    s.count = 0;
    for (auto& c : s.byOp) c = 0;
    s.failAt = failAt;
}

}  // namespace terralux
