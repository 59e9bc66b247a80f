#include "CommandLineHelp.h"

#include <algorithm>
#include <sstream>

#include "ParameterTable.h"
#include "scene/DebugViews.h"

namespace terralux {
namespace {

constexpr size_t kHelpWidth = 97;
constexpr size_t kHelpColumn = 32;

bool authoringOnly(const std::string& syntax) {
    const auto& only = authoringOnlyOptions();
    const std::string name = syntax.substr(2, syntax.find_first_of(" ,") - 2);
    return std::find(only.begin(), only.end(), name) != only.end();
}

}  // namespace

const std::vector<std::string>& authoringOnlyOptions() {
    static const std::vector<std::string> names = {"render", "study",  "budget",  "size",      "debug-view", "overlay",
                                                   "time",   "profile", "camera", "no-probes", "no-rebake",  "device",
                                                   "scenario"};
    return names;
}

CommandLineHelp commandLineHelp(Binary binary) {
    const bool authoring = binary == Binary::Authoring;
    CommandLineHelp h;
    h.program = authoring ? "terralux" : "terralux-bake";
    if (authoring) {
        h.summary = "terrain-lighting authoring tool: DEM import, SH probe bake, .shprobe and glTF export";
        h.usage = {{"[PROJECT]", "open the authoring window"}, {"COMMAND [OPTIONS]", "work headless"}};
        h.description = "Terrain-lighting authoring: import a DEM, bake spherical-harmonics probes, export .shprobe + glTF.";
    } else {
        h.summary = "headless terrain-lighting bake: SH probes, .shprobe and glTF export, no display or GPU";
        h.usage = {{"COMMAND [OPTIONS]", "bake without a display or a GPU"}};
        h.description =
            "The bake of Terralux for farm nodes and scripts: the same bake, files and reports as 'terralux "
            "--bake', from a binary that links no GUI toolkit and no Vulkan loader. The authoring window, "
            "--render and --study are in terralux.";
    }
    h.commands = {
        {"--bake [PROJECT]",
         "Bake every enabled probe volume and export .shprobe files, a glTF scene and bake_report.json into "
         "the output folder."},
        {"--merge DIR",
         "Merge the tiles baked into DIR/tiles (--bake --tile) into one scene: DIR/scene.gltf lists every "
         "tile's probe grids and meshes, DIR/tiles.json indexes them, DIR/bake_report.json sums their reports. "
         "Refuses an incomplete set of tiles or tiles of different inputs, naming them."},
        {"--render [PROJECT]",
         "Render the terrain lit by the probes of the last bake in the output folder (baking first when "
         "there is none or it is stale) into --out IMAGE (.png display-encoded, .exr scene-linear), on the "
         "Vulkan device."},
        {"--study [PROJECT]",
         "Sweep the settings that trade bake time for accuracy (quality, rays, bounces, probe spacing or "
         "adaptive tolerance, error-map resolution, AO directions, LPV quality and cascades, reflection cube "
         "size, rays and encoding; shadow cascades, map size, filter and the terrain horizon on the Vulkan device), measure each "
         "against the exact answer on the same points, and write study.json, study.csv, study.png and "
         "study.html into --out DIR (default: \"study\" beside the project or in the current folder)."},
        {"--info [FILE]",
         "Describe a DEM (GDAL raster) as Terralux imports it; no FILE: the embedded sample terrain."},
        {"--print-project [PROJECT]", "Print the effective project (defaults, PROJECT, --set) as JSON."},
        {"--print-schema",
         "Print the JSON Schema (draft 2020-12) of the project file, for editors that check a project as it "
         "is typed."},
        {"--print-reference",
         "Print the parameter reference (Markdown): every parameter with its type, default, range, unit and "
         "meaning."},
        {"--help, -h", "Show this help."},
        {"--version", "Show the version."},
    };
    h.options = {
        {"--dem FILE", "Use FILE as the terrain instead of the project's (or the sample)."},
        {authoring ? "--out DIR | IMAGE" : "--out DIR",
         authoring ? "--bake: the output folder (default: export.out_dir, \"bake\" beside the project or in the "
                     "current folder); --study: its folder; --render: the image."
                   : "The output folder (default: export.out_dir, \"bake\" beside the project or in the current "
                     "folder)."},
        {"--budget SECONDS",
         "--study: the time it may take (default 120); settings that would not fit are skipped and listed "
         "with their estimate."},
        {"--quality PRESET", "draft | standard | high | reference (bake.quality)."},
        {"--compare-reference",
         "Also run the brute-force reference and report the error of every probe against it (slow)."},
        {"--size WxH", "Render size (default 1280x720)."},
        {"--debug-view N|NAME", "What --render draws: " + debugViewList() + "."},
        {"--overlay LIST",
         "--render: draw over the image, comma-separated: probes (probe positions: gold valid, cyan moved "
         "up, red rejected), leaves (adaptive octree leaves)."},
        {"--time T", "--render: seconds into the water's wave animation (default 0)."},
        {"--scenario NAME[,TO,T]",
         "--render: light with the bake's lighting scenario NAME (default: \"default\", the project's own sun "
         "and sky), or blend from NAME toward TO by T in [0, 1] as an engine blends two scenarios."},
        {"--profile",
         "--render: draw the frame again, warm, for at least a second and at least three times, and print "
         "what it cost (medians): each pass's GPU time from timestamps (where the device writes them), the "
         "GPU total, and the host's recording and read-back conversion, beside the cold and warm wall time."},
        {"--camera AZ,EL[,RADIUS]",
         "Orbit camera: azimuth (clockwise from north) and elevation in degrees, radius in metres (default: "
         "the project's camera)."},
        {"--no-probes", "Render without probe lighting."},
        {"--no-rebake",
         "--render: draw the bake in the output folder even when it is stale (its recorded settings or "
         "input files differ from the project's), saying what differs; without it such a bake is baked "
         "again first."},
        {"--device NAME",
         "--render, --study: the Vulkan device: cpu, gpu, or part of its name (default: discrete GPU, "
         "integrated, then CPU)."},
        {"--dry-run",
         "With --bake: place the probes and print, per volume, the probe count, the .shprobe bytes and the "
         "estimated bake time; bake and write nothing."},
        {"--tiles NX,NZ",
         "With --bake --tile: cut the terrain into NX tiles west to east and NZ north to south (a farm's job "
         "array, docs/farm.md)."},
        {"--tile I/N | IX,IZ",
         "With --bake and --tiles: bake tile I of N (row-major, from 0; a batch engine's task index) or the "
         "tile in column IX, row IZ, into OUT/tiles/tile_IZ_IX; a tile whose inputs are unchanged since its "
         "bake is skipped."},
        {"--halo METRES",
         "With --tile: the terrain traced around the tile (default: derived from the relief, so terrain "
         "beyond it changes a probe's light by under 1 %)."},
        {"--near-halo METRES",
         "With --tile: how much of the halo is read at the DEM's resolution; beyond it the halo is traced on the "
         "region's overview (default: a hundred overview cells, so its coarser heights change a probe's light by "
         "under 1 %)."},
        {"--set KEY.PATH=VALUE",
         "Override a project parameter by its JSON path; repeatable.\n"
         "Examples: --set sun.elevation_deg=12\n"
         "          --set probe_volumes[0].grid_dims=16,16\n"
         "          --set terrain.albedo=[0.25,0.22,0.2]\n"
         "An unknown path is an error."},
        {"--threads N", "Worker threads (default: all cores)."},
        {"--quiet", "No progress on stderr."},
        {"--progress text|json",
         "With --bake: progress on stderr as text (default) or as one JSON object a line, for a farm to "
         "read: {\"phase\", \"fraction\", \"elapsed_s\", \"eta_s\"}."},
    };
    if (!authoring) {
        std::erase_if(h.commands, [](const HelpEntry& e) { return authoringOnly(e.syntax); });
        std::erase_if(h.options, [](const HelpEntry& e) { return authoringOnly(e.syntax); });
    }
    h.sample =
        "With no project and no --dem, commands use the embedded sample terrain (256 x 256 cells of a 30 m "
        "SRTM DEM of the San Gabriel Mountains).";
    h.exitCodes = {{"0", "success"},
                   {"2", "bad usage or invalid input"},
                   {"3", "runtime failure"},
                   {"130", "interrupted"}};
    return h;
}

namespace {

// Words of `line` wrapped to kHelpWidth, continuation lines indented to `indent`.
void wrapInto(std::string& out, const std::string& line, size_t column, size_t indent) {
    std::istringstream words(line);
    std::string word;
    size_t width = column;
    bool first = true;
    while (words >> word) {
        if (!first && width + 1 + word.size() > kHelpWidth) {
            out += '\n';
            out.append(indent, ' ');
            width = indent;
        } else if (!first) {
            out += ' ';
            ++width;
        }
        out += word;
        width += word.size();
        first = false;
    }
}

void entries(std::string& out, const std::vector<HelpEntry>& list) {
    for (const HelpEntry& e : list) {
        std::string head = "  " + e.syntax;
        head.resize(std::max(head.size() + 1, kHelpColumn), ' ');
        out += head;
        std::istringstream lines(e.text);
        std::string line;
        bool first = true;
        while (std::getline(lines, line)) {
            if (!first) {
                out += '\n';
                out.append(kHelpColumn, ' ');
            }
            // An example line keeps its leading spaces.
            const size_t lead = line.find_first_not_of(' ');
            out += line.substr(0, lead);
            wrapInto(out, line.substr(lead), kHelpColumn + lead, kHelpColumn + lead);
            first = false;
        }
        out += "\n";
    }
}

}  // namespace

std::string helpText(const CommandLineHelp& h) {
    std::string out;
    for (size_t i = 0; i < h.usage.size(); ++i) {
        std::string head = (i ? "       " : "Usage: ") + h.program + " " + h.usage[i].arguments;
        head.resize(std::max(head.size() + 1, size_t(40)), ' ');
        out += head + h.usage[i].meaning + "\n";
    }
    out += "\n";
    wrapInto(out, h.description, 0, 0);
    out += "\n\nCommands:\n";
    entries(out, h.commands);
    out += "\nOptions:\n";
    entries(out, h.options);
    out += "\n";
    wrapInto(out, h.sample, 0, 0);
    out += "\n\n";
    std::string codes = "Exit codes:";
    for (size_t i = 0; i < h.exitCodes.size(); ++i)
        codes += (i ? ", " : " ") + h.exitCodes[i].syntax + " " + h.exitCodes[i].text;
    wrapInto(out, codes + ".", 0, 0);
    out += "\n";
    return out;
}

namespace {

// Text for roff: backslashes escaped, a leading '.' or '\'' made literal, hyphens in option names
// kept as minus signs (so they copy as typed).
std::string roff(const std::string& s) {
    std::string out;
    for (size_t i = 0; i < s.size(); ++i) {
        const char c = s[i];
        const bool lineStart = i == 0 || s[i - 1] == '\n';
        if (lineStart && (c == '.' || c == '\'')) out += "\\&";
        if (c == '\\') out += "\\e";
        else if (c == '-') out += "\\-";
        else out += c;
    }
    return out;
}

// A paragraph of prose: lines starting with spaces (examples) stay on lines of their own.
std::string roffText(const std::string& text) {
    std::string out;
    std::istringstream lines(text);
    std::string line;
    bool first = true;
    while (std::getline(lines, line)) {
        if (!first) out += "\n.br\n";
        // An example line: indented by two unbreakable spaces.
        out += line.starts_with(' ') ? "\\ \\ " + roff(line.substr(line.find_first_not_of(' '))) : roff(line);
        first = false;
    }
    return out;
}

std::string bold(const std::string& syntax) {
    // "--help, -h": each spelling bold.
    if (const size_t comma = syntax.find(", -"); comma != std::string::npos)
        return bold(syntax.substr(0, comma)) + ", " + bold(syntax.substr(comma + 2));
    // "--bake [PROJECT]": the option bold, its arguments italic.
    const size_t space = syntax.find(' ');
    if (space == std::string::npos) return "\\fB" + roff(syntax) + "\\fR";
    return "\\fB" + roff(syntax.substr(0, space)) + "\\fR \\fI" + roff(syntax.substr(space + 1)) + "\\fR";
}

}  // namespace

std::string manualPage(const CommandLineHelp& h, const std::string& version, const std::string& date) {
    std::string upper = h.program;
    std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return char(std::toupper(c)); });
    std::ostringstream m;
    m << ".\\\" Generated from the command line's help and the parameter table; do not edit.\n";
    m << ".TH " << roff(upper) << " 1 \"" << date << "\" \"" << roff(h.program) << " " << version
      << "\" \"Terralux manual\"\n.nh\n";
    m << ".SH NAME\n" << roff(h.program) << " \\- " << roff(h.summary) << "\n";
    m << ".SH SYNOPSIS\n";
    for (const auto& u : h.usage) m << ".B " << roff(h.program) << "\n\\fI" << roff(u.arguments) << "\\fR\n.br\n";
    m << ".SH DESCRIPTION\n" << roff(h.description) << "\n";
    m << ".PP\n" << roff(h.sample) << "\n";
    m << ".SH COMMANDS\n";
    for (const auto& e : h.commands) m << ".TP\n" << bold(e.syntax) << "\n" << roffText(e.text) << "\n";
    m << ".SH OPTIONS\n";
    for (const auto& e : h.options) m << ".TP\n" << bold(e.syntax) << "\n" << roffText(e.text) << "\n";
    m << ".SH PROJECT PARAMETERS\n"
      << "A project is a JSON file (*.terralux.json); every parameter below is also reachable as\n"
      << ".BI \\-\\-set \" PATH=VALUE\" .\n"
      << "Rows under a list (probe_volumes[], water.waves[], lights[]) take an index,\n"
      << "as in probe_volumes[0].grid_dims. A null value means auto where the row says what auto does.\n";
    std::string section;
    for (const ParameterReferenceRow& r : parameterReferenceRows()) {
        if (r.section != section) {
            section = r.section;
            m << ".SS " << roff(section) << "\n";
        }
        m << ".TP\n\\fB" << roff(r.path) << "\\fR (" << roff(r.type) << ", default " << roff(r.defaultValue) << ")\n"
          << roff(r.description) << "\n";
        std::string facts;
        if (!r.allowed.empty()) facts += "Allowed: " + r.allowed + ". ";
        if (!r.unit.empty()) facts += "Unit: " + r.unit + ". ";
        if (!r.autoMeaning.empty()) facts += "null: " + r.autoMeaning + ". ";
        facts += "An edit redoes: " + r.edit + ". Bake: " + r.bake + ".";
        m << ".br\n" << roff(facts) << "\n";
    }
    if (h.program == "terralux") {
        m << ".SH ENVIRONMENT\n"
          << ".TP\n.B TERRALUX_VK_DEVICE\n"
          << roff("The Vulkan device when --device is not given: cpu, gpu, or part of its name.") << "\n"
          << ".TP\n.B TERRALUX_VK_VALIDATION\n"
          << roff("1 enables the Khronos validation layer and prints its messages.") << "\n";
    }
    m << ".SH EXIT STATUS\n";
    for (const auto& e : h.exitCodes) m << ".TP\n.B " << e.syntax << "\n" << roff(e.text) << "\n";
    m << ".SH FILES\n"
      << ".TP\n.I /usr/share/terralux/terralux.schema.json\n"
      << roff("The JSON Schema of the project file, as --print-schema prints it.") << "\n"
      << ".TP\n.I /usr/share/doc/terralux/\n"
      << roff("The formats (.shprobe, the glTF extension, the bake report), the lighting models and the "
              "parameter reference.")
      << "\n";
    m << ".SH SEE ALSO\n"
      << (h.program == "terralux" ? ".BR terralux\\-bake (1)\n" : ".BR terralux (1)\n");
    return m.str();
}

}  // namespace terralux
