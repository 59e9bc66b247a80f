#include "CommandLine.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include <QCommandLineParser>
#include <QStringList>

#include "DemImport.h"
#include "Project.h"
#include "SampleTerrain.h"
#include "TerrainLoading.h"

#ifndef TERRALUX_VERSION
#define TERRALUX_VERSION "0.0.0"
#endif

namespace terralux {
namespace {

const char* const kUsage = R"(Usage: terralux [COMMAND] [OPTIONS]

Terrain-lighting authoring: import a DEM, bake spherical-harmonics probes, export .shprobe + glTF.

Commands:
  --info [FILE]                 Describe a DEM (GDAL raster) as Terralux imports it; no FILE:
                                the embedded sample terrain.
  --print-project [PROJECT]     Print the effective project (defaults, PROJECT, --set) as JSON.
  --help, -h                    Show this help.
  --version                     Show the version.

Options:
  --dem FILE                    Use FILE as the terrain instead of the project's (or the sample).
  --set KEY.PATH=VALUE          Override a project parameter by its JSON path; repeatable.
                                Examples: --set sun.elevation_deg=12
                                          --set probe_volumes[0].grid_dims=16,16
                                          --set terrain.albedo=[0.25,0.22,0.2]
                                An unknown path is an error.
  --threads N                   Worker threads (default: all cores).
  --quiet                       No progress on stderr.

With no project and no --dem, commands use the embedded sample terrain (256 x 256 cells of a
30 m SRTM DEM of the San Gabriel Mountains).

Exit codes: 0 success, 2 bad usage or invalid input, 3 runtime failure, 130 interrupted.
)";

struct Args {
    QCommandLineParser parser;
    QCommandLineOption info{"info", "Describe a DEM."};
    QCommandLineOption printProject{"print-project", "Print the effective project."};
    QCommandLineOption help{QStringList{"help", "h"}, "Show help."};
    QCommandLineOption version{"version", "Show the version."};
    QCommandLineOption dem{"dem", "Terrain file.", "FILE"};
    QCommandLineOption set{"set", "Override.", "KEY=VALUE"};
    QCommandLineOption threads{"threads", "Worker threads.", "N"};
    QCommandLineOption quiet{"quiet", "No progress."};

    Args() {
        parser.setSingleDashWordOptionMode(QCommandLineParser::ParseAsLongOptions);
        parser.addOptions({info, printProject, help, version, dem, set, threads, quiet});
    }
};

class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

std::string str(const QString& s) { return s.toStdString(); }

std::string fixed(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

int commandInfo(const Args& a) {
    const QStringList positional = a.parser.positionalArguments();
    if (positional.size() > 1) throw UsageError("--info takes one FILE");
    DemImportResult r;
    if (positional.isEmpty())
        r = importDemFromMemory(kSampleTerrainName, sampleTerrainBytes(), sampleTerrainSize());
    else
        r = importDem(str(positional[0]));
    const Heightfield& hf = r.heightfield;
    const DemSourceInfo& s = r.source;
    for (const auto& w : s.warnings) std::cerr << "terralux: warning: " << s.path << ": " << w << "\n";

    const size_t cells = size_t(hf.width()) * hf.depth();
    double sum = 0.0;
    for (float h : hf.heights()) sum += h;
    std::ostringstream o;
    o << "file:         " << s.path << "\n";
    o << "driver:       " << s.driver << "\n";
    o << "raster:       " << s.sourceWidth << " x " << s.sourceHeight << " (band 1)\n";
    o << "source crs:   "
      << (s.sourceCrs.empty() ? std::string("none (taken as metres)") : s.sourceCrs)
      << (s.sourceEpsg ? " (EPSG:" + std::to_string(s.sourceEpsg) + ")" : std::string()) << "\n";
    o << "source pixel: " << s.sourcePixelX << " x " << std::abs(s.sourcePixelY)
      << (s.geographic ? " deg" : " m") << "\n";
    if (s.reprojected)
        o << "reprojected:  " << hf.geo.crsName << " (EPSG:" << hf.geo.epsg << "), bilinear\n";
    o << "grid:         " << hf.width() << " x " << hf.depth() << " vertices"
      << (s.resampled ? " (area-averaged to the maximum resolution)" : "") << "\n";
    o << "pixel size:   " << fixed(hf.cellSizeX(), 3) << " x " << fixed(hf.cellSizeZ(), 3) << " m\n";
    o << "height:       " << fixed(hf.minHeight(), 2) << " .. " << fixed(hf.maxHeight(), 2)
      << " m (mean " << fixed(sum / double(cells), 2) << ", relief "
      << fixed(hf.maxHeight() - hf.minHeight(), 2) << ")\n";
    o << "nodata:       " << hf.nodataCount() << " of " << cells << " cells ("
      << fixed(100.0 * double(hf.nodataCount()) / double(cells), 3) << " %)"
      << (hf.nodataCount() ? ", filled by inverse-distance interpolation" : "") << "\n";
    o << "extent:       x " << fixed(hf.minX(), 2) << " .. " << fixed(hf.maxX(), 2) << " m, z "
      << fixed(hf.minZ(), 2) << " .. " << fixed(hf.maxZ(), 2) << " m ("
      << fixed((hf.maxX() - hf.minX()) / 1000.0, 3) << " x "
      << fixed((hf.maxZ() - hf.minZ()) / 1000.0, 3) << " km; north is -z)\n";
    o << "origin:       easting " << fixed(hf.geo.easting, 3) << ", northing "
      << fixed(hf.geo.northing, 3) << " (footprint centre, engine x = z = 0)\n";
    std::cout << o.str();
    return kExitOk;
}

int commandPrintProject(const Args& a) {
    const QStringList positional = a.parser.positionalArguments();
    if (positional.size() > 1) throw UsageError("--print-project takes one PROJECT");
    std::vector<std::string> warnings;
    std::vector<std::string> sets;
    for (const QString& s : a.parser.values(a.set)) sets.push_back(str(s));
    const Project p = loadEffectiveProject(positional.isEmpty() ? "" : str(positional[0]), sets,
                                           a.parser.isSet(a.dem) ? str(a.parser.value(a.dem)) : "",
                                           &warnings);
    for (const auto& w : warnings) std::cerr << "terralux: warning: " << w << "\n";
    std::cout << projectToJson(p).dump(2) << "\n";
    return kExitOk;
}

}  // namespace

int runCommandLine(int argc, char** argv) {
    Args a;
    QStringList arguments;
    for (int i = 0; i < argc; ++i) arguments << QString::fromLocal8Bit(argv[i]);
    try {
        if (!a.parser.parse(arguments)) throw UsageError(str(a.parser.errorText()));
        if (a.parser.isSet(a.help)) {
            std::cout << kUsage;
            return kExitOk;
        }
        if (a.parser.isSet(a.version)) {
            std::cout << "terralux " << TERRALUX_VERSION << "\n";
            return kExitOk;
        }
        const int commands = int(a.parser.isSet(a.info)) + int(a.parser.isSet(a.printProject));
        if (commands > 1) throw UsageError("choose one command: --info or --print-project");
        if (a.parser.isSet(a.threads)) {
            bool ok = false;
            const int n = a.parser.value(a.threads).toInt(&ok);
            if (!ok || n < 1 || n > 1024)
                throw UsageError("--threads " + str(a.parser.value(a.threads)) +
                                 ": must be an integer in [1, 1024]");
        }
        if (a.parser.isSet(a.info)) return commandInfo(a);
        if (a.parser.isSet(a.printProject)) return commandPrintProject(a);
        if (!a.parser.positionalArguments().isEmpty())
            throw UsageError("unexpected argument '" + str(a.parser.positionalArguments()[0]) +
                             "' (no command given)");
        std::cout << kUsage;
        return kExitOk;
    } catch (const UsageError& e) {
        std::cerr << "terralux: " << e.what() << "\nTry 'terralux --help'.\n";
        return kExitUsage;
    } catch (const DemError& e) {
        std::cerr << "terralux: " << e.what() << "\n";
        return kExitUsage;
    } catch (const ProjectError& e) {
        std::cerr << "terralux: " << e.what() << "\n";
        return kExitUsage;
    } catch (const std::exception& e) {
        std::cerr << "terralux: " << e.what() << "\n";
        return kExitRuntime;
    }
}

}  // namespace terralux
