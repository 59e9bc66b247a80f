// Writes a small synthetic glTF scene (terrain + two probe volumes) with the exporter, for the
// Khronos validator test; with --water (last), also the water plane and its material.
//   export_sample_scene OUT_DIR [WIDTH DEPTH [MESH_MAX_VERTICES]] [--water]

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "GltfExport.h"

using namespace terralux;

namespace {

ShProbeGrid syntheticGrid(glm::uvec3 dims, glm::vec3 origin, float spacing, size_t probeCount) {
    ShProbeGrid g;
    g.dims = dims;
    g.origin = origin;
    g.spacing = spacing;
    for (size_t i = 0; i < probeCount; ++i) {
        ShProbeRecord rec;
        rec.coeffs[0] = glm::vec3(0.8f, 0.75f, 0.7f) + 0.01f * float(i);
        for (size_t k = 1; k < 9; ++k)
            rec.coeffs[k] = glm::vec3(0.05f / float(k), 0.04f / float(k), -0.02f);
        g.probes.push_back(rec);
    }
    const size_t cells = size_t(dims.x) * dims.y * dims.z;
    for (size_t c = 0; c < cells; ++c)
        g.occupancy.push_back(c % 3 == 2 ? -1 : int32_t(c % probeCount));
    return g;
}

}  // namespace

int main(int argc, char** argv) {
    const bool water = argc > 2 && std::string(argv[argc - 1]) == "--water";
    if (water) --argc;
    if (argc != 2 && argc != 4 && argc != 5) {
        std::fprintf(stderr, "usage: export_sample_scene OUT_DIR [WIDTH DEPTH [MESH_MAX_VERTICES]] [--water]\n");
        return 2;
    }
    try {
        const int w = argc >= 4 ? std::stoi(argv[2]) : 33;
        const int d = argc >= 4 ? std::stoi(argv[3]) : 17;
        std::vector<float> heights(size_t(w) * size_t(d));
        for (int r = 0; r < d; ++r)
            for (int c = 0; c < w; ++c)
                heights[size_t(r) * size_t(w) + size_t(c)] =
                    float(40.0 * std::sin(0.3 * c) * std::cos(0.2 * r) + 0.5 * r);
        Heightfield hf(w, d, 30.0, 30.0, std::move(heights));
        hf.geo.crsName = "WGS 84 / UTM zone 31N";
        hf.geo.epsg = 32631;
        hf.geo.easting = 431250.0;
        hf.geo.northing = 4623450.0;

        GltfSceneInput in;
        in.heightfield = &hf;
        in.albedo = {0.32f, 0.3f, 0.26f};
        in.volumes.push_back({"valley", syntheticGrid({8, 2, 4}, {-480.f, -50.f, -240.f}, 60.f, 20), {}});
        in.volumes.push_back({"probes", syntheticGrid({4, 2, 4}, {-10.f, 0.f, -10.f}, 0.5f, 7), {}});
        in.bake = {{"shEncoding", "L2"}, {"quality", "draft"}, {"rays", 64}, {"bounces", 1}};
        in.generatorVersion = "test";
        if (argc == 5)
            in.meshMaxVertices = std::stoul(argv[4]);
        if (water)
            in.water = GltfWater{5.0f, {0.02f, 0.05f, 0.06f}, 0.05f};
        const GltfExportResult res = exportGltfScene(argv[1], in);
        for (const auto& f : res.files)
            std::printf("%s\n", f.string().c_str());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "export_sample_scene: %s\n", e.what());
        return 1;
    }
    return 0;
}
