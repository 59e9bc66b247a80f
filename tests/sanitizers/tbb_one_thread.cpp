// Linked into every target of the ThreadSanitizer build only (the 'tsan' preset). Debian's oneTBB
// is not built with ThreadSanitizer, so the atomics with which its scheduler hands a loop's work
// and data to its workers are invisible, and every parallel loop is reported as racing on what
// the calling thread prepared for it. One thread a loop (the smallest max_allowed_parallelism of
// all global_control objects wins) leaves what ThreadSanitizer can judge: our own threads, the
// progress printer, cancellation, the window's workers and the locks between them.
#include <tbb/global_control.h>

namespace {
const tbb::global_control oneThreadALoop(tbb::global_control::max_allowed_parallelism, 1);
}  // namespace
