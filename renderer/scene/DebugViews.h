#pragma once
// The debug views of docs/lighting.md: one table, read by the CLI, the UI selector, the renderer and
// the tests. The numbers come from shaders/debug_views.def, which the shaders read too.

#include <optional>
#include <string>
#include <vector>

namespace terralux {

// kViewBeauty, kViewAlbedo, ...: the view numbers as named constants.
#define TLX_VIEW(NAME, NUMBER) inline constexpr int kView##NAME = NUMBER;
#include "debug_views.def"
#undef TLX_VIEW

// Every view number the shaders know, in the order of debug_views.def.
const std::vector<int>& shaderViewNumbers();

// What the view's clear colour (where no terrain is drawn) is.
enum class ViewBackground {
    Black,
    Sky,        // the sky toward the horizon, exposed and tonemapped like the beauty image
    LinearSky,  // the same sky, scene-linear (clamped to [0, 1] in a PNG)
};

// The passes and inputs a view needs beyond the terrain pass.
struct ViewNeeds {
    bool probeLight = false;        // the probe pass's per-vertex irradiance and weight
    bool probeDiagnostics = false;  // its diagnostics half (moved share, error map) instead
    bool probeMarkers = false;      // the overlay pass with moved and rejected probes marked
    bool shadows = false;           // the shadow pass (when the scene's shadows are on)
    bool sunVisibility = false;     // the sun's visibility traced on the CPU at each vertex
    bool sky = false;               // the sky pass behind the terrain
    bool water = false;             // the water pass (when the scene has water)
    bool waterShading = false;      // its reflection and the copy of the frame under it
    bool reflectionProbes = false;  // the reflection probes in the lights set (when a set is bound)
    // The scene's LPV light (when lighting.indirect uses it) and its point and spot lights.
    bool sceneLights = false;
    bool lpvVolumes = false;        // the LPV's volumes whatever lighting.indirect says
    // The view shows the shadow maps themselves, so they are drawn for a sun that gives no light;
    // a lit view draws none for it (nothing it lights to shadow).
    bool showsShadows = false;
};

struct DebugView {
    int number;
    const char* name;
    const char* shows;
    bool linear;  // EXR holds scene-linear values; PNG holds the display encoding
    ViewBackground background;
    ViewNeeds needs;
};

// The views this renderer draws, in docs/lighting.md order.
const std::vector<DebugView>& debugViews();
// By number ("50") or name ("probe-irradiance"); nullopt when unknown or not drawn.
std::optional<DebugView> findDebugView(const std::string& numberOrName);
// By number; nullopt when unknown.
std::optional<DebugView> findDebugView(int number);
// "0 beauty, 1 albedo, …" for messages and --help.
std::string debugViewList();
// The view table in Markdown, for docs/lighting.md and the README.
std::string debugViewsMarkdown();
// "views 54 and 56" (from the table): the views that read the bake's probe diagnostics, for messages.
std::string diagnosticsViewList();

}  // namespace terralux
