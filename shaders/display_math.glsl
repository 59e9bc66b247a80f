// The display encoding, in the common subset of GLSL and C++ (shaders/ShaderMath.h includes it
// for C++): the viewport's tone curve, the sRGB transfer curve and Rec. 709 luminance, written once. tonemap.glsl
// applies them per channel; the renderer's background colour, the reflection panel's cube cross
// and the tests call the same functions.
#ifndef TLX_DISPLAY_MATH_GLSL
#define TLX_DISPLAY_MATH_GLSL
#ifndef TLX_SHARED
#define TLX_SHARED
#endif

// ACES filmic fit (Narkowicz 2015, "ACES Filmic Tone Mapping Curve"): exposed scene-linear light
// to [0, 1].
TLX_SHARED float acesFit(float x) {
    return clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
}

// The fit's inverse on [0, 0.999] (clamped just below its asymptote): y = f(x) is a ratio of
// quadratics, so x is the root of (2.43y − 2.51)x² + (0.59y − 0.03)x + 0.14y = 0 that is >= 0.
TLX_SHARED float acesFitInverse(float y) {
    y = clamp(y, 0.0f, 0.999f);
    float a = 2.43f * y - 2.51f, b = 0.59f * y - 0.03f, k = 0.14f * y;
    return (-b - sqrt(max(b * b - 4.0f * a * k, 0.0f))) / (2.0f * a);
}

// Relative luminance of linear RGB with the Rec. 709 primaries (ITU-R BT.709-6, item 3.3): what the
// exposure meter, the sky's glow threshold, the bake's and the LPV's measures of light weigh.
TLX_SHARED float rec709Luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

// sRGB transfer curve (IEC 61966-2-1:1999, §5.2): linear [0, 1] to the encoded value, and back.
TLX_SHARED float srgbEncode(float c) {
    c = clamp(c, 0.0f, 1.0f);
    return c < 0.0031308f ? 12.92f * c : 1.055f * pow(c, 1.0f / 2.4f) - 0.055f;
}
TLX_SHARED float srgbDecode(float e) {
    e = clamp(e, 0.0f, 1.0f);
    return e < 0.04045f ? e / 12.92f : pow((e + 0.055f) / 1.055f, 2.4f);
}

#endif
