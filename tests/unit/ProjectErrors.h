#pragma once
// The validation message a project gets for one `--set` edit, for the parameter tests.

#include <string>

#include <nlohmann/json.hpp>

#include "Project.h"

namespace terralux::test {

// The error reading the default project (or `base`) after `path=value`; empty when it is accepted.
inline std::string projectErrorFor(const std::string& path, const nlohmann::json& value,
                                   nlohmann::json base = defaultProjectJson()) {
    try {
        applyOverride(base, path + "=" + value.dump());
        sceneFromJson(base, "p.json", nullptr);
    } catch (const ProjectError& e) {
        return e.what();
    }
    return "";
}

}  // namespace terralux::test
