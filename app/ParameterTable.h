#pragma once
// The one table of project parameters. Each row declares a parameter once, with everything that
// reads it: its JSON path, type, range or choices, what `null` ("auto") means, unit, label and
// description, the work an edit invalidates, and the field of the SceneDescription it binds to.
// The project reader and writer, the validation messages, `--set`, the UI rows and their limits,
// `terralux --print-schema` and the parameter reference (docs/parameters.md) are all generated
// from it. Adding a parameter is one row here plus the code that uses the field.

#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/ProbePlacement.h"
#include "scene/SceneDescription.h"

namespace terralux {

class Heightfield;

enum class ParamType {
    Number,       // a finite double in [min, max]
    Integer,      // a whole number in [min, max]
    Boolean,
    String,       // optionally matching `pattern`
    Choice,       // one of `choices`
    Color,        // three numbers, each in [min, max]
    NumberList,   // minItems..maxItems numbers, each in [min, max] (scalarAllowed: or one number)
    IntegerList,  // minItems..maxItems whole numbers, each in [min, max]
};

// What an edit of a parameter invalidates, cheapest first. The UI does no more than this.
enum Invalidation : unsigned {
    kRedraw = 0,           // draw the next frame with the new value
    kUpload = 1u << 0,     // new lighting or material uniforms for the renderer
    kRebake = 1u << 1,     // the draft probe preview is baked again
    kReplace = 1u << 2,    // probe volumes are placed again (overlays, estimate)
    kReimport = 1u << 3,   // the DEM is imported again (everything above follows)
    kNothing = 1u << 4,    // read only by the bake and the exporters: nothing to redraw
};

// Whether a bake reads a row: what bakeInputs (BakeJob.h) records in a bake's report and the
// staleness check compares, so an edit of a row the bake ignores never marks a bake stale.
enum class BakeUse {
    Reads,    // the value, wherever the scene reads the row (isRead)
    File,     // a file path: the bake reads the file it resolves to (path, size, modification
              // time); the empty path stands for the row's zeroText ("embedded sample")
    Ignores,  // the renderer's, the viewport's or the output's: no bake reads it
};

inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

struct ParameterSpec {
    // "sun.elevation_deg"; rows of each element of a list of objects (objectLists) are
    // "<list>[].<key>": "probe_volumes[].grid_dims", "water.waves[].wavelength".
    std::string path;
    ParamType type = ParamType::Number;
    double min = -kUnbounded, max = kUnbounded;
    bool minExclusive = false, maxExclusive = false;
    int minItems = 0, maxItems = 0;  // lists
    bool scalarAllowed = false;      // a NumberList that may also be one number
    std::vector<std::string> choices;
    std::string pattern, patternRule;  // strings: a regex, and the rule it enforces in words
    // Set when `null` is allowed: what it means ("auto-span", "the preset decides").
    std::optional<std::string> autoMeaning;
    std::string unit, label, description;
    // What the smallest number (0) or the empty string means, shown by the editor in its place
    // ("source", "no map", "embedded sample"); empty when it means nothing special.
    std::string zeroText;
    unsigned invalidates = kRedraw;
    BakeUse bake = BakeUse::Reads;
    int decimals = 2;     // UI precision
    bool slider = false;  // UI: a slider beside the spin box (angles)
    bool colorList = false;  // UI: a NumberList of RGB triples, one colour button per triple
    bool uiRow = true;    // shown as a dock row (false: edited elsewhere, or by the viewport)
    // The engine console variable the row sets ("rEx.LPV.Size"), taken from the lpv.ini writer's
    // list (io/LpvConsoleVariables.h) so the two never disagree; empty for other rows.
    std::string consoleVariable;
    // Lists whose length depends on other parameters (a box grid has 3 dims, a terrain grid 2):
    // the exact count for this scene, 0 for one plain number, -1 when the row is not read.
    std::function<int(const SceneDescription&, size_t volume)> items;
    // Rows that are read only in some scenes but keep their value in the others (adaptive.*
    // rows of a terrain volume): false where the row is not read. Unset: always read.
    std::function<bool(const SceneDescription&, size_t volume)> readWhen;

    // Binding to the scene. `volume` indexes the row's list for the rows of a list's elements
    // (probe_volumes, water.waves), and is 0 for the others.
    std::function<nlohmann::json(const SceneDescription&, size_t volume)> get;
    // Receives a value that passed the row's own checks; may reject with the row's context.
    std::function<void(SceneDescription&, size_t volume, const nlohmann::json&)> set;
    // Rows whose null stands for a value the terrain decides (auto-span origins and spacings):
    // that value on `terrain`, in the row's JSON shape, for an editor to show while "auto" is
    // ticked; null where the placement cannot say it (an adaptive volume, a refused grid).
    std::function<nlohmann::json(const SceneDescription&, const Heightfield& terrain, size_t volume)> resolved;

    bool perVolume() const { return path.rfind("probe_volumes[].", 0) == 0; }
    bool perWave() const { return path.rfind("water.waves[].", 0) == 0; }
    bool perLight() const { return path.rfind("lights[].", 0) == 0; }
    bool perScenario() const { return path.rfind("scenarios[].", 0) == 0; }
    // The list whose elements hold the row ("probe_volumes", "water.waves"); empty for the rest.
    std::string listPath() const;
    bool inList() const { return !listPath().empty(); }
    // The path inside an element for the rows of a list ("grid_dims"), else the path.
    std::string localPath() const;
    // The default, read from a default-constructed scene (or probe volume, or wave).
    nlohmann::json defaultValue() const;
    bool nullable() const { return autoMeaning.has_value(); }
    // Whether this scene reads the row (for per-volume rows, of volume `volume`, which must
    // exist): `items` not -1 and `readWhen` not false. The docks hide rows that are not read.
    bool isRead(const SceneDescription& scene, size_t volume) const;
    // "[0, 90]", "(0, 1]", "> 0", "one of a | b": the rule as validation messages state it.
    std::string rangeText() const;
};

// Thrown by a row's `set` (or a rule between rows) when a value that passed the row's own checks
// breaks a rule that involves other parameters. `subPath` names an element ("[1]") if any.
struct ParameterRejection {
    std::string rule;
    std::string subPath;
};

const std::vector<ParameterSpec>& parameterTable();

// The project's lists of objects, as JSON paths: "probe_volumes", "water.waves", "lights" and
// "scenarios". Each element
// is an object whose keys are the rows "<list>[].<key>".
const std::vector<std::string>& objectLists();

// The row for a path with or without element indices ("probe_volumes[2].grid_dims" and
// "probe_volumes[].grid_dims" both find it); nullptr when no row has that path.
const ParameterSpec* findParameter(const std::string& path);

// "probe_volumes[2].grid_dims" -> "probe_volumes[].grid_dims".
std::string normaliseParameterPath(const std::string& path);

// What an edit at `path` invalidates: its row's flags, or every flag of the rows below a section
// or list ("probe_volumes[0]", "sun", "water.waves"); everything for "" (a new or reopened
// project).
unsigned invalidatedBy(const std::string& path);

// An edit at `path` in words, for undo: "Grid (probes) of volume 'probes'" (the element named
// from `doc`, the project as JSON), "Scale height (fog)", "wave 2", "the sun".
std::string editLabel(const std::string& path, const nlohmann::json& doc);

// Sections that hold rows ("sun", "probe_volumes[].adaptive"): JSON objects in the project.
bool isParameterSection(const std::string& path);

// The authoring window's dock that edits a row (its objectName and title).
struct ParameterDock {
    std::string objectName, title;
};
ParameterDock parameterDock(const ParameterSpec& spec);
// The objectName of a row's editor: "param.sun.elevation_deg"; rows of the selected probe
// volume are "param.volume.<key>", of the selected light "param.light.<key>". Lists add ".0",
// ".1", ...; a slider adds ".slider"; the "auto" box of a nullable list adds ".auto".
std::string uiObjectName(const ParameterSpec& spec);
// The smallest value a UI spin box offers: the minimum, or one display step above an excluded one.
double uiMinimum(const ParameterSpec& spec);
// A short word for the null ("auto") value in a spin box: the meaning up to its first colon.
std::string autoShort(const ParameterSpec& spec);

// A float as the shortest decimal that reads back as the same float (0.3f is 0.3, not
// 0.30000001192092896): how the project writes its float fields, and the exporters theirs.
double shortestDecimal(float f);

// JSON Schema (draft 2020-12) of the project file, generated from the table.
nlohmann::json projectSchema();
// What a bake of `scene` reads, as JSON in the project's shape: every row whose BakeUse is Reads,
// wherever the scene reads it (isRead), under "settings"; every File row's value, under "files"
// keyed by the row's path, through `identity` (which BakeJob gives the file's path, size and
// modification time).
nlohmann::json bakeReadSettings(const SceneDescription& scene,
                                const std::function<nlohmann::json(const ParameterSpec&, const std::string& value)>& identity);

// One row of the parameter reference, as text: what docs/parameters.md and the manual page show.
struct ParameterReferenceRow {
    std::string section;  // "sun", "probe_volumes[]"
    std::string path, type, defaultValue, allowed, unit, edit, bake, autoMeaning, description;
};
std::vector<ParameterReferenceRow> parameterReferenceRows();
// The parameter reference in Markdown (docs/parameters.md), generated from the table.
std::string parameterReferenceMarkdown();
// The parameter editors of each dock with their objectNames (docs/UI_OBJECT_NAMES.md), generated
// from the table.
std::string uiObjectNamesMarkdown();

}  // namespace terralux
