#pragma once
// The render targets of the sizes drawn lately. The viewport draws one view at several sizes
// (a metered frame's 128-pixel meter, a dynamic-resolution step while the camera moves, the
// full frame when it stops); each size's targets are allocated once and kept while it is among
// the last few drawn, so stepping between them waits for nothing and allocates nothing.

#include <algorithm>
#include <cstddef>
#include <memory>
#include <vector>

#include "scene/DynamicResolution.h"

namespace terralux {

// Besides the size drawn now, one for every other size the viewport draws one view at: each rung
// of the dynamic-resolution ladder (DynamicResolution::kScales) and the meter. With three, a
// metered sun edit that stepped over two rungs pushed a target out and waited for the device to
// replace it (80-120 ms on the UI thread on lavapipe). The rungs halve the pixels, so all of them
// together are less than twice the full frame.
inline constexpr size_t kSpareTargets = DynamicResolution::kScales.size();

template <class Target>
using SpareTargets = std::vector<std::unique_ptr<Target>>;  // the least recently drawn first

// Makes the spare that `serves` the current target, the current one becoming a spare: whether
// one did.
template <class Target, class Serves>
bool takeSpare(std::unique_ptr<Target>& current, SpareTargets<Target>& spares, Serves serves) {
    const auto found = std::find_if(spares.begin(), spares.end(), [&](const auto& t) { return serves(t.get()); });
    if (found == spares.end()) return false;
    std::unique_ptr<Target> taken = std::move(*found);
    spares.erase(found);
    if (current) spares.push_back(std::move(current));
    current = std::move(taken);
    return true;
}

// Puts `fresh` in place of the current target, which becomes a spare; the least recently drawn
// spares past kSpareTargets are released: where one is, the caller waits for the device first.
template <class Target>
void replaceTarget(std::unique_ptr<Target>& current, SpareTargets<Target>& spares, std::unique_ptr<Target> fresh) {
    if (current) spares.push_back(std::move(current));
    if (spares.size() > kSpareTargets)
        spares.erase(spares.begin(), spares.begin() + std::ptrdiff_t(spares.size() - kSpareTargets));
    current = std::move(fresh);
}

}  // namespace terralux
