#pragma once
// The project's sun, sky and terrain albedo as the bake and the renderer use them: one place, so
// the baked probes and the preview light the terrain the same way.

#include "Project.h"
#include "bake/DiffuseBake.h"

namespace terralux {

// Uniform sky, or the HDR (tinted by sky.color, × intensity, turned by rotation). Throws
// ImageError for an unreadable HDR. HDR skies are cached by path, file time and size, and
// rotation; tint and intensity scale the cached environment, so edits of them and of anything
// else reuse it.
Sky skyOf(const Project& project);
// How many times an HDR was read and filtered since start (for tests of the cache).
size_t hdrSkyReads();
// Sun, sky and albedo; the caller sets the tracer.
BakeLighting lightingOf(const Project& project);

// The fog as the renderer draws it: base height and colour resolved (unset base height = the lowest
// terrain; unset colour = the sky's mean radiance over the sphere).
FogSettings resolvedFog(const FogSettings& fog, const Sky& sky, const Heightfield& terrain);

}  // namespace terralux
