#pragma once
// The debug views of LIGHTING.md, selectable by number or name everywhere (UI, CLI, tests).

#include <optional>
#include <string>
#include <vector>

namespace terralux {

struct DebugView {
    int number;
    const char* name;
    const char* shows;
    bool linear;  // EXR holds scene-linear values; PNG holds the display encoding
};

// The views this renderer draws, in LIGHTING.md order.
const std::vector<DebugView>& debugViews();
// By number ("50") or name ("probe-irradiance"); nullopt when unknown or not drawn.
std::optional<DebugView> findDebugView(const std::string& numberOrName);
// "0 beauty, 1 albedo, …" for messages and --help.
std::string debugViewList();

}  // namespace terralux
