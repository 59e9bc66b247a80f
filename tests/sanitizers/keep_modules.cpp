// Preloaded into the sanitize presets' tests (LD_PRELOAD): dlclose does nothing, so a library the
// Vulkan loader unloads (the ICD, e.g. lavapipe) keeps its globals mapped and LeakSanitizer still
// sees the memory they point to. Without it, every allocation such a library keeps for its
// lifetime is reported as a leak from "<unknown module>", which no suppression can name.
// Built without sanitizers: it is loaded into every process of a test, instrumented or not.
extern "C" int dlclose(void*) { return 0; }
