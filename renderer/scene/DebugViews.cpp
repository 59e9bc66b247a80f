#include "scene/DebugViews.h"

namespace terralux {

const std::vector<int>& shaderViewNumbers() {
    static const std::vector<int> numbers = {
#define TLX_VIEW(NAME, NUMBER) NUMBER,
#include "debug_views.def"
#undef TLX_VIEW
    };
    return numbers;
}

const std::vector<DebugView>& debugViews() {
    constexpr ViewNeeds none{}, diagnostics{false, true, false}, diagnosticsAndMarkers{false, true, true},
        shadows{.shadows = true, .showsShadows = true}, visibility{false, false, false, false, true},
        lit{true, false, false, true, false, true, true, true, true, true}, light{true, false, false},
        lpvOnly{false, false, false, false, false, false, false, false, false, false, true},
        waterOnly{false, false, false, false, false, false, true, false},
        reflections{false, false, false, false, false, false, false, false, true};
    static const std::vector<DebugView> views = {
        {kViewBeauty, "beauty", "final image", false, ViewBackground::Sky, lit},
        {kViewAlbedo, "albedo", "surface albedo", false, ViewBackground::Black, none},
        {kViewNormal, "normal", "world normal as colour", false, ViewBackground::Black, none},
        {kViewNormalVariance, "normal-variance",
         "variance σ² of the terrain normals under each pixel (Toksvig), which widens the specular "
         "lobe: heat ramp, red at 0.1 and above (EXR: σ² in red, 1 in green on terrain)",
         true, ViewBackground::Black, none},
        {kViewFilled, "filled",
         "the final image with the cells the DEM left as nodata, and the import filled, tinted magenta",
         false, ViewBackground::Sky, lit},
        {kViewAo, "ao",
         "raw ambient occlusion: the cosine-weighted sky visibility from the heightfield's horizons "
         "(EXR: visibility in red, 1 in green on terrain)",
         true, ViewBackground::Black, none},
        {kViewSunVisibility, "sun-visibility",
         "share of the sun's disc visible, traced on the CPU by the bake's tracer at each vertex (EXR: "
         "visibility in red, 1 in green on terrain)",
         true, ViewBackground::Black, visibility},
        {kViewNdotL, "ndotl", "N·L", false, ViewBackground::Black, none},
        {kViewShadow, "shadow", "shadow-map factor of the sun, 1 lit (EXR: factor in red, 1 in green on terrain)",
         true, ViewBackground::Black, shadows},
        {kViewLinear, "linear", "pre-tonemap colour", true, ViewBackground::LinearSky, lit},
        {kViewCascades, "cascades",
         "shadow cascade index: red, green, blue, yellow for cascades 1-4, grey beyond the shadow "
         "distance, dark lines at the splits",
         false, ViewBackground::Black, shadows},
        {kViewFog, "fog", "fog amount, 1 − transmittance to the camera (EXR: amount in red, 1 in green on terrain)",
         true, ViewBackground::Black, none},
        {kViewProbeIrradiance, "probe-irradiance", "probe irradiance × weight", true,
         ViewBackground::Black, light},
        {kViewProbeWeight, "probe-weight", "probe blend weight", false, ViewBackground::Black, light},
        {kViewReflectionColor, "reflection-color",
         "reflection probes' prefiltered radiance toward the mirror direction × their blend weight "
         "(black without reflection probes)",
         true, ViewBackground::Black, reflections},
        {kViewReflectionWeight, "reflection-weight",
         "reflection-probe blend weight applied over the sky's specular: the coverage fade × "
         "reflection_probes.strength (black without reflection probes)",
         false, ViewBackground::Black, reflections},
        {kViewProbeValidity, "probe-validity",
         "invalid / relocated probes: grey lit by probes at their placement, cyan by moved probes, "
         "red inside a volume with no valid probe; markers cyan moved, red rejected (with the probe "
         "overlay also gold valid)",
         false, ViewBackground::Black, diagnosticsAndMarkers},
        {kViewInterpolationError, "interpolation-error",
         "interpolation error heat map: blue 0 %, cyan 2.5 %, green 5 %, yellow 7.5 %, red 10 % and "
         "above, grey unmeasured (EXR: error in red, 1 in green where measured)",
         true, ViewBackground::Black, diagnostics},
        {kViewLpvCascade0, "lpv-cascade0",
         "irradiance of the LPV's cascade 0 alone, as E/π (what a white Lambertian surface reflects), "
         "black outside it; PNG exposed for the volumes' light (E/π ÷ cascade 0's light range, printed), EXR as it is",
         true, ViewBackground::Black, lpvOnly},
        {kViewLpvGeometry, "lpv-geometry",
         "cascade 0's geometry volume at the surface: the share of the light flowing into the ground "
         "it stops, heat ramp from blue (none) to red (all) (EXR: share in red, 1 in green on terrain)",
         true, ViewBackground::Black, lpvOnly},
        {kViewLpvAo, "lpv-ao",
         "sky visibility marched through cascade 0's geometry volume, 1 open, fading to black at the "
         "cascade's edge as view 61 (EXR: value in red, 1 in green on terrain inside cascade 0)",
         true, ViewBackground::Black, lpvOnly},
        {kViewLpvAll, "lpv-all", "LPV irradiance of all cascades blended, as E/π, black outside them; PNG on view 61's scale", true,
         ViewBackground::Black, lpvOnly},
        {kViewWaterMask, "water-mask",
         "water / land: blue where the water surface is in view, brown land (EXR: 1 in red on water, 1 in green everywhere)",
         true, ViewBackground::Black, waterOnly},
        {kViewShoreDistance, "shore-distance",
         "distance from the water to the nearest land: heat ramp from blue at the shore to red at "
         "water.shore_fade_distance and beyond, black land (EXR: metres in red, 1 in green on water)",
         true, ViewBackground::Black, waterOnly},
        {kViewWaterNormal, "water-normal", "the waves' normal as colour; land grey", false, ViewBackground::Black,
         waterOnly},
    };
    return views;
}

std::optional<DebugView> findDebugView(const std::string& s) {
    for (const auto& v : debugViews())
        if (s == v.name || s == std::to_string(v.number)) return v;
    return std::nullopt;
}

std::optional<DebugView> findDebugView(int number) {
    for (const auto& v : debugViews())
        if (v.number == number) return v;
    return std::nullopt;
}

std::string debugViewList() {
    std::string out;
    for (const auto& v : debugViews())
        out += (out.empty() ? "" : ", ") + std::to_string(v.number) + " " + v.name;
    return out;
}

std::string diagnosticsViewList() {
    std::vector<std::string> numbers;
    for (const auto& v : debugViews())
        if (v.needs.probeDiagnostics) numbers.push_back(std::to_string(v.number));
    std::string out = numbers.size() == 1 ? "view " : "views ";
    for (size_t i = 0; i < numbers.size(); ++i)
        out += (i == 0 ? "" : i + 1 == numbers.size() ? " and " : ", ") + numbers[i];
    return out;
}

std::string debugViewsMarkdown() {
    std::string out = "| view | name | shows | EXR holds | passes beyond the terrain |\n|---:|---|---|---|---|\n";
    for (const auto& v : debugViews()) {
        std::string passes;
        if (v.needs.probeLight) passes = "probe-vertices (light)";
        if (v.needs.probeDiagnostics) passes = "probe-vertices (diagnostics), the bake's sidecar";
        if (v.needs.probeMarkers) passes += ", overlays (probe markers)";
        if (v.needs.reflectionProbes) passes += (passes.empty() ? "" : ", ") + std::string("reflection probes (when bound)");
        if (v.needs.shadows)
            passes = std::string(v.needs.showsShadows ? "shadow (when shadows are on)"
                                                      : "shadow (when shadows are on and the sun gives light)") +
                     (passes.empty() ? "" : ", " + passes);
        if (v.needs.sunVisibility) passes = "CPU sun tracing at the vertices (cached per sun)";
        if (v.needs.sceneLights) passes += ", LPV (when lighting.indirect uses it) and local lights";
        if (v.needs.lpvVolumes) passes = "LPV volumes (computed on the CPU for the camera)";
        if (v.needs.sky) passes += ", sky";
        if (v.needs.waterShading) passes += ", water reflection and water (when the scene has water)";
        else if (v.needs.water) passes += (passes.empty() ? "" : ", ") + std::string("water (when the scene has water)");
        out += "| " + std::to_string(v.number) + " | `" + v.name + "` | " + v.shows + " | " +
               (v.linear ? "scene-linear values" : "the display encoding") + " | " +
               (passes.empty() ? "none" : passes) + " |\n";
    }
    return out;
}

}  // namespace terralux
