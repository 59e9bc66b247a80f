// check_bake_output DIR: loads DIR/scene.gltf with tinygltf and checks every shProbeGrids entry
// against the header of the .shprobe it names, and bake_report.json against both. Exit 0 when all
// agree; otherwise prints each disagreement.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "GltfExport.h"
#include "ShProbeFile.h"

using namespace terralux;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: check_bake_output DIR\n";
        return 2;
    }
    const fs::path dir = argv[1];
    int failures = 0;
    auto expect = [&](bool ok, const std::string& what) {
        if (!ok) {
            std::cout << "FAIL: " << what << "\n";
            ++failures;
        }
    };
    const nlohmann::json entries = readShProbeGridEntries(dir / "scene.gltf");
    std::ifstream reportIn(dir / "bake_report.json");
    const nlohmann::json report = nlohmann::json::parse(reportIn);
    expect(entries.size() == report["volumes"].size(), "one glTF entry per baked volume");
    std::string previous;
    for (const auto& e : entries) {
        const std::string path = e["shProbePath"];
        expect(path > previous, "entries sorted by file name: " + path);
        previous = path;
        const ShProbeGrid g = readShProbeFile(dir / path);
        const std::string name = e["volumeName"];
        expect(path == "sh_coeffs/" + name + ".shprobe", "volumeName is the file stem: " + name);
        expect(e["probeCount"] == g.probes.size(), name + ": probeCount");
        expect(e["gridDimensions"] == nlohmann::json{g.dims.x, g.dims.y, g.dims.z}, name + ": gridDimensions");
        for (int a = 0; a < 3; ++a)
            expect(e["gridOrigin"][a].get<float>() == g.origin[a], name + ": gridOrigin");
        expect(e["gridSpacing"].get<float>() == g.spacing, name + ": gridSpacing");
        expect(e["defaultScale"].get<float>() == g.defaultScale, name + ": defaultScale");
        expect(e["defaultAmbient"].get<float>() == g.defaultAmbient, name + ": defaultAmbient");
        bool reported = false;
        for (const auto& v : report["volumes"])
            if (v["name"] == name) {
                reported = true;
                expect(v["probes"] == g.probes.size(), name + ": report probe count");
                expect(v["bytes"] == fs::file_size(dir / path), name + ": report bytes");
            }
        expect(reported, name + ": in bake_report.json");
        // Every occupied cell points at a probe; a terrain grid covers every column.
        size_t occupied = 0;
        for (int32_t c : g.occupancy) occupied += c >= 0;
        expect(occupied >= g.probes.size(), name + ": every probe owns at least one cell");
        std::cout << name << ": " << g.probes.size() << " probes, " << occupied << " of "
                  << g.occupancy.size() << " cells occupied\n";
    }
    if (failures == 0) std::cout << "ok: " << entries.size() << " grid(s) agree\n";
    return failures == 0 ? 0 : 1;
}
