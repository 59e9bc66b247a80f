#pragma once
// The project document: a versioned JSON file holding a SceneDescription, validated against
// the rules of the parameter table (ParameterTable.h). Paths inside it are relative to the project file.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/ProbePlacement.h"
#include "scene/SceneDescription.h"

namespace terralux {

// Invalid project content or override: the message names the JSON path, the value and the rule.
class ProjectError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// The project file's version (docs/formats.md, "Project file"): older files are migrated step
// by step on reading, newer ones refused.
inline constexpr int kProjectVersion = 8;
inline constexpr int kMaxBoxGridProbes = kMaxVolumeProbes;  // cells; docs/lighting.md, "Probe limits"
inline constexpr int kMaxBounces = 16;
inline constexpr int kMaxRampStops = 8;              // terrain.ramp_heights
inline constexpr int kMaxLocalLights = 1024;         // lights: what one LPV update injects
inline constexpr int kMaxScenarios = 16;             // scenarios: each costs a bake of its coefficients
// The name of the project's own sun and sky among its lighting scenarios.
inline constexpr const char* kDefaultScenario = "default";

struct Project {
    SceneDescription scene;
    // Directory that relative paths in the document are resolved against.
    std::filesystem::path baseDir = std::filesystem::current_path();
    std::filesystem::path file;  // empty for an unsaved project

    std::filesystem::path resolve(const std::string& relative) const;
    std::filesystem::path demPath() const;    // empty: use the embedded sample
    std::filesystem::path hdrPath() const;
    std::filesystem::path albedoMapPath() const;  // empty when terrain.albedo_map names none
    std::filesystem::path outDir() const;
};

// Defaults, as JSON: every key the document may hold.
nlohmann::json defaultProjectJson();
nlohmann::json sceneToJson(const SceneDescription& scene);
// One step of the project file's history: what changed from `from` to from + 1, and the edit
// that keeps an older file meaning what it meant (it may add notes to `notes`).
struct ProjectMigration {
    int from = 1;
    const char* summary = "";
    void (*apply)(nlohmann::json& doc, std::vector<std::string>& notes) = nullptr;
};
const std::vector<ProjectMigration>& projectMigrations();
// `doc` brought to kProjectVersion, one step at a time, each step's notes prefixed with `source`;
// a document without a version is taken as current. Throws ProjectError for a version newer
// than kProjectVersion or one that is not an integer >= 1.
nlohmann::json migrateProjectJson(nlohmann::json doc, const std::string& source, std::vector<std::string>* notes);
// Reads and validates every parameter of the table (app/ParameterTable.h) of a document migrated
// to the current version; absent keys take their defaults, an unknown key is an error. `source`
// prefixes messages (a file name, or "--set"); `warnings` gets the migration's notes.
SceneDescription sceneFromJson(const nlohmann::json& doc, const std::string& source,
                               std::vector<std::string>* warnings);

// Applies one `key.path=value` override; the path must name an existing parameter
// (`probe_volumes[0].grid_dims`, `sun.elevation_deg`). The value is JSON, or a bare string, or a
// comma list for array parameters and unset ones (`probe_volumes[0].origin=-100,500,-200`).
void applyOverride(nlohmann::json& doc, const std::string& assignment);

// The project's lighting scenarios by name, the default first: "default", then scenarios[].name.
std::vector<std::string> scenarioNames(const SceneDescription& scene);
// `name` when the scene has that scenario, else "default" (what a view of a renamed or removed
// scenario falls back to).
std::string knownScenario(const SceneDescription& scene, const std::string& name);
// The scene lit as scenario `name` lights it: its sun and sky in place of the project's own
// ("default": the scene as it is). Throws ProjectError naming the scenarios there are when no
// scenario has that name.
SceneDescription scenarioScene(const SceneDescription& scene, const std::string& name);

Project loadProject(const std::filesystem::path& file, std::vector<std::string>* warnings);
// Writes atomically (temporary file in the same directory, then rename).
void saveProject(const Project& project, const std::filesystem::path& file);
nlohmann::json projectToJson(const Project& project);

}  // namespace terralux
