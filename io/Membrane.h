// The membrane (discrete Laplace) fill of nodata holes (docs/lighting.md, "Terrain").
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace terralux {

struct MembraneReport {
    size_t holes = 0;    // 4-connected holes solved
    int iterations = 0;  // the most conjugate-gradient iterations one hole needed
    bool converged = true;  // every hole met the tolerance within the iteration cap
};

// Iteration cap of one hole's solve; the multigrid-preconditioned iteration needs a few tens.
inline constexpr int kMembraneMaxIterations = 200;

// Where a hole's solve starts: the heights already in its cells (another fill's result), or
// the mean of the valid cells around it (what the import uses: the solve's cost hardly depends
// on the start, and no other fill has to run first).
enum class MembraneStart { Heights, RimMean };

// Replaces the heights of each 4-connected hole (cells with nodata[i] != 0 of a row-major w x h
// grid) with the solution of the five-point Laplace equation: each hole cell the mean of its
// neighbours, the valid cells around the hole fixed, the grid's edge a zero-slope boundary.
// Starts from `start` and stops when neither a Jacobi step nor the
// multigrid's estimate of the error moves any cell by 0.1 mm, or by the float spacing of the
// hole's rim heights where that is coarser. A hole with no valid neighbour is left as it is; a
// solve that breaks down leaves the hole at its start (the rim's mean for RimMean).
// Throws std::invalid_argument when the sizes disagree or the grid has 2^31 cells or more.
MembraneReport membraneFill(std::vector<float>& heights, int w, int h, const std::vector<uint8_t>& nodata,
                            MembraneStart start = MembraneStart::Heights);

}  // namespace terralux
