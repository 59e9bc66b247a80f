#pragma once
// The project's sun, sky and terrain albedo as the bake and the renderer use them: one place, so
// the baked probes and the preview light the terrain the same way.

#include "Project.h"
#include "bake/DiffuseBake.h"

namespace terralux {

// Uniform sky, or the HDR (tinted by sky.color, × intensity, turned by rotation). Throws
// ImageError for an unreadable HDR.
Sky skyOf(const Project& project);
// Sun, sky and albedo; the caller sets the tracer.
BakeLighting lightingOf(const Project& project);

}  // namespace terralux
