#pragma once
// The mountain DEMs the unit tests walk vertex by vertex: three committed crops and, where the
// shared data is installed beside the repository, the whole N42E001 tile.

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace terralux::test {

struct MountainDem {
    std::filesystem::path file;
    bool shared = false;  // the whole shared tile, not a committed crop
};

// Those present; an absent shared tile is named on stdout and left out.
inline std::vector<MountainDem> mountainDems() {
    namespace fs = std::filesystem;
    std::vector<MountainDem> dems;
    for (const char* name : {"rainier_crop.tif", "n42e001_voids_crop.tif", "bigtujunga_utm11_crop.tif", "N42E001.hgt"}) {
        const bool shared = std::string(name) == "N42E001.hgt";
        const fs::path file = (shared ? fs::path(TERRALUX_SHARED_DATA) : fs::path(TERRALUX_TEST_DATA)) / "dem" / name;
        if (!fs::exists(file)) {
            std::printf("%s is absent (shared data not installed)\n", file.string().c_str());
            continue;
        }
        dems.push_back({file, shared});
    }
    return dems;
}

}  // namespace terralux::test
