// Every uniform block and storage struct, in one list: C++ expands it once for the structs and
// once for their std140/std430 size checks (renderer/render/UniformBlocks.h). A new subsystem's
// block is one more line here.
#include "blocks/camera.h"
#include "blocks/surface.h"
#include "blocks/sun_sky.h"
#include "blocks/probes.h"
#include "blocks/overlay.h"
