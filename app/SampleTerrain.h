#pragma once
// The terrain every command uses when neither a project nor --dem names one: a 256 x 256 crop of
// a real 30 m SRTM DEM (provenance: app/sample/SOURCES.md), compiled into the binary.

#include <cstddef>

namespace terralux {
inline constexpr const char* kSampleTerrainName = "sample_dem.tif";
const unsigned char* sampleTerrainBytes();
size_t sampleTerrainSize();
}  // namespace terralux
