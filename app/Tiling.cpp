#include "Tiling.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace terralux {

namespace {

// Whole integers only: "2", not "2.5" or "2x".
bool parseInt(std::string_view s, int& out) {
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && end == s.data() + s.size();
}

bool parsePair(const std::string& s, char sep, int& a, int& b) {
    const size_t at = s.find(sep);
    return at != std::string::npos && parseInt(std::string_view(s).substr(0, at), a) &&
           parseInt(std::string_view(s).substr(at + 1), b);
}

}  // namespace

TileSpec parseTiles(const std::string& tiles, const std::string& tile, const std::optional<double>& haloMetres) {
    TileSpec t;
    constexpr int kMaxTilesPerAxis = 1024;
    if (!parsePair(tiles, ',', t.nx, t.nz) || t.nx < 1 || t.nz < 1 || t.nx > kMaxTilesPerAxis ||
        t.nz > kMaxTilesPerAxis)
        throw std::invalid_argument("--tiles " + tiles + ": must be NX,NZ, two whole numbers from 1 to " +
                                    std::to_string(kMaxTilesPerAxis));
    int a = 0, b = 0;
    if (parsePair(tile, '/', a, b)) {
        if (b != t.count())
            throw std::invalid_argument("--tile " + tile + ": N must be the tile count of --tiles " + tiles + " (" +
                                        std::to_string(t.count()) + ")");
        if (a < 0 || a >= b)
            throw std::invalid_argument("--tile " + tile + ": I must lie in [0, " + std::to_string(b) + ")");
        t.ix = a % t.nx;
        t.iz = a / t.nx;
    } else if (parsePair(tile, ',', a, b)) {
        if (a < 0 || a >= t.nx || b < 0 || b >= t.nz)
            throw std::invalid_argument("--tile " + tile + ": IX must lie in [0, " + std::to_string(t.nx) +
                                        ") and IZ in [0, " + std::to_string(t.nz) + ")");
        t.ix = a;
        t.iz = b;
    } else {
        throw std::invalid_argument("--tile " + tile + ": must be I/N (I from 0) or IX,IZ");
    }
    if (haloMetres && !(std::isfinite(*haloMetres) && *haloMetres >= 0.0))
        throw std::invalid_argument("--halo " + std::to_string(*haloMetres) + ": must be a distance in metres >= 0");
    t.haloMetres = haloMetres;
    return t;
}

Halo haloFor(const DemGrid& region, const std::optional<double>& metres) {
    Halo h;
    h.relief = region.maxHeight - region.minHeight;
    h.derived = !metres;
    h.metres = metres ? *metres : h.relief * std::sqrt((1.0 - kHaloShare) / kHaloShare);
    constexpr double kDegrees = 57.29577951308232;
    h.sunBelowDeg = h.metres > 0.0 ? std::atan(h.relief / h.metres) * kDegrees : 90.0;
    return h;
}

double nearHaloFor(const Halo& halo, double overviewCell, const std::optional<double>& metres) {
    return std::min(halo.metres, metres ? *metres : overviewCell / kHaloShare);
}

TileWindow tileWindow(const DemGrid& region, const TileSpec& t, double overviewCell) {
    const int cellsX = region.width - 1, cellsZ = region.depth - 1;
    if (cellsX < 2 * t.nx || cellsZ < 2 * t.nz)
        throw std::invalid_argument("--tiles " + std::to_string(t.nx) + "," + std::to_string(t.nz) + ": the " +
                                    std::to_string(region.width) + "x" + std::to_string(region.depth) +
                                    " grid must give every tile at least 2 cells a side");
    TileWindow w;
    // Integer cuts of the cells: each tile's share differs from another's by at most one cell.
    const int c1 = int((long long)(t.ix + 1) * cellsX / t.nx), r1 = int((long long)(t.iz + 1) * cellsZ / t.nz);
    w.col0 = int((long long)t.ix * cellsX / t.nx);
    w.row0 = int((long long)t.iz * cellsZ / t.nz);
    w.cols = c1 - w.col0 + 1;
    w.rows = r1 - w.row0 + 1;
    w.regionCols = region.width;
    w.regionRows = region.depth;
    w.halo = haloFor(region, t.haloMetres);
    w.nearMetres = overviewCell > 0.0 || t.nearHaloMetres ? nearHaloFor(w.halo, overviewCell, t.nearHaloMetres)
                                                          : w.halo.metres;
    // The core grown by `metres` on each side, in whole cells, clipped to the region.
    auto grow = [&](double metres, int& col0, int& row0, int& cols, int& rows) {
        const double hx = std::ceil(metres / region.cellX), hz = std::ceil(metres / region.cellZ);
        const int gx = int(std::min(hx, double(cellsX))), gz = int(std::min(hz, double(cellsZ)));
        col0 = std::max(0, w.col0 - gx);
        row0 = std::max(0, w.row0 - gz);
        cols = std::min(cellsX, c1 + gx) - col0 + 1;
        rows = std::min(cellsZ, r1 + gz) - row0 + 1;
    };
    grow(w.halo.metres, w.haloCol0, w.haloRow0, w.haloCols, w.haloRows);
    grow(w.nearMetres, w.tracedCol0, w.tracedRow0, w.tracedCols, w.tracedRows);
    w.far = w.tracedCols < w.haloCols || w.tracedRows < w.haloRows;
    return w;
}

GridWindow overviewWindow(const TileWindow& w, const DemGrid& region, const Heightfield& overview) {
    const int c0 = std::clamp(int(std::floor(overview.colOf(regionX(region, w.haloCol0)))), 0, overview.width() - 2);
    const int r0 = std::clamp(int(std::floor(overview.rowOf(regionZ(region, w.haloRow0)))), 0, overview.depth() - 2);
    const int c1 =
        std::clamp(int(std::ceil(overview.colOf(regionX(region, w.haloCol0 + w.haloCols - 1)))), c0 + 1, overview.width() - 1);
    const int r1 =
        std::clamp(int(std::ceil(overview.rowOf(regionZ(region, w.haloRow0 + w.haloRows - 1)))), r0 + 1, overview.depth() - 1);
    return {c0, r0, c1 - c0 + 1, r1 - r0 + 1};
}

std::string tileName(const TileSpec& t) {
    char name[32];
    std::snprintf(name, sizeof name, "tile_%03d_%03d", t.iz, t.ix);
    return name;
}

nlohmann::json tileReport(const TileSpec& t, const TileWindow& w, const DemGrid& region) {
    auto xOf = [&](int c) { return float(regionX(region, c)); };
    auto zOf = [&](int r) { return float(regionZ(region, r)); };
    const float x0 = xOf(w.col0), x1 = xOf(w.col0 + w.cols - 1);
    const float z0 = zOf(w.row0), z1 = zOf(w.row0 + w.rows - 1);
    return {{"name", tileName(t)},
            {"contract", kTileContract},
            {"tiles", {t.nx, t.nz}},
            {"index", t.index()},
            {"ix", t.ix},
            {"iz", t.iz},
            {"region_grid", {region.width, region.depth}},
            {"core", {{"col0", w.col0}, {"row0", w.row0}, {"cols", w.cols}, {"rows", w.rows}}},
            {"traced", {{"col0", w.tracedCol0}, {"row0", w.tracedRow0}, {"cols", w.tracedCols}, {"rows", w.tracedRows}}},
            {"halo_window", {{"col0", w.haloCol0}, {"row0", w.haloRow0}, {"cols", w.haloCols}, {"rows", w.haloRows}}},
            {"bounds_m", {{"min", {x0, z0}}, {"max", {x1, z1}}}},
            {"halo_setting_m", t.haloMetres ? nlohmann::json(*t.haloMetres) : nlohmann::json()},
            {"near_halo_setting_m", t.nearHaloMetres ? nlohmann::json(*t.nearHaloMetres) : nlohmann::json()},
            {"near_halo", {{"metres", w.nearMetres}, {"derived", !t.nearHaloMetres}, {"far_from_overview", w.far}}},
            {"halo",
             {{"metres", w.halo.metres},
              {"derived", w.halo.derived},
              {"relief_m", w.halo.relief},
              {"share", kHaloShare},
              {"sun_below_deg", w.halo.sunBelowDeg}}}};
}

}  // namespace terralux

#include "Project.h"

namespace terralux {

namespace {

// The tile's share of the region's cells along x and z.
std::array<double, 2> tileShares(const TileWindow& w) {
    return {double(w.cols - 1) / double(w.regionCols - 1), double(w.rows - 1) / double(w.regionRows - 1)};
}

// Probes along an axis of a tile, the region's n over its span: the first and last on the tile's
// edges.
int tileProbes(int n, double share) { return n <= 1 ? n : std::max(2, int(std::lround((n - 1) * share)) + 1); }

}  // namespace

ReflectionProbeSettings tileReflectionGrid(const ReflectionProbeSettings& share, const TileWindow& w,
                                           const Heightfield& tile) {
    ReflectionProbeSettings r = share;
    const bool eastShared = w.col0 + w.cols < w.regionCols, southShared = w.row0 + w.rows < w.regionRows;
    int& nx = r.gridDims[0];
    int& nz = r.gridDims[1];
    if (!((eastShared && nx > 1) || (southShared && nz > 1))) return r;
    const float spanX = tile.maxX() - tile.minX(), spanZ = tile.maxZ() - tile.minZ();
    // The grid before the cut, as placeReflectionProbes spans the footprint; a spacing must be
    // positive, and an axis of one probe ignores it.
    glm::vec2 spacing(nx > 1 ? spanX / float(nx - 1) : std::max(spanX, 1.0f),
                      nz > 1 ? spanZ / float(nz - 1) : std::max(spanZ, 1.0f));
    const glm::vec2 origin(nx > 1 ? tile.minX() : 0.5f * (tile.minX() + tile.maxX()),
                           nz > 1 ? tile.minZ() : 0.5f * (tile.minZ() + tile.maxZ()));
    if (eastShared && nx > 1) --nx;
    if (southShared && nz > 1) --nz;
    r.spacing = spacing;
    r.origin = origin;
    return r;
}

std::array<int, 2> regionTerrainGridDims(const std::array<int, 2>& tileDims, const TileWindow& w) {
    const std::array<double, 2> share = tileShares(w);
    std::array<int, 2> out{};
    for (int a = 0; a < 2; ++a) {
        const int n = tileDims[size_t(a)];
        // The inverse of tileProbes, then the nearest count whose share is n again.
        int r = n <= 1 ? n : int(std::lround((n - 1) / share[size_t(a)])) + 1;
        while (r > 2 && tileProbes(r, share[size_t(a)]) > n) --r;
        while (tileProbes(r, share[size_t(a)]) < n) ++r;
        out[size_t(a)] = r;
    }
    return out;
}

int tileShareOfProbes(int probes, const TileWindow& w) {
    const std::array<double, 2> share = tileShares(w);
    // Each axis of the region's grid may round up by one probe from the tile's.
    const double side = std::sqrt(double(probes));
    return std::max(4, int(std::floor((side - 1.0) * share[0] * (side - 1.0) * share[1])));
}

void scaleSceneToTile(SceneDescription& scene, const TileWindow& w) {
    const auto [shareX, shareZ] = tileShares(w);
    auto probes = tileProbes;
    auto cells = [](int n, double share) { return std::max(1, int(std::lround(n * share))); };
    auto list = [](std::initializer_list<float> v) {
        std::string out;
        for (float x : v) {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%g", double(x));
            out += (out.empty() ? "[" : ",") + std::string(buf);
        }
        return out + "]";
    };
    for (size_t i = 0; i < scene.probeVolumes.size(); ++i) {
        ProbeVolumeSettings& v = scene.probeVolumes[i];
        if (!v.enabled) continue;
        const std::string at = "probe_volumes[" + std::to_string(i) + "]";
        if (v.origin)
            throw ProjectError(at + ".origin " +
                               (v.placement == ProbePlacement::Terrain ? list({v.origin->x, v.origin->z})
                                                                       : list({v.origin->x, v.origin->y, v.origin->z})) +
                               ": a tiled bake places each tile's probes over its own share of the terrain; leave "
                               "the origin unset");
        if (refinedByError(v.placement) && v.adaptive.size)
            throw ProjectError(at + ".adaptive.size " +
                               list({v.adaptive.size->x, v.adaptive.size->y, v.adaptive.size->z}) +
                               ": a tiled bake places each tile's probes over its own share of the terrain; leave "
                               "the size unset");
        if (v.placement == ProbePlacement::Terrain) {
            v.gridDims[0] = probes(v.gridDims[0], shareX);
            v.gridDims[2] = probes(v.gridDims[2], shareZ);
        } else if (v.placement == ProbePlacement::Box) {
            v.gridDims[0] = cells(v.gridDims[0], shareX);
            v.gridDims[2] = cells(v.gridDims[2], shareZ);
        }
    }
    ReflectionProbeSettings& r = scene.reflectionProbes;
    if (r.enabled) {
        if (r.origin)
            throw ProjectError("reflection_probes.origin " + list({r.origin->x, r.origin->y}) +
                               ": a tiled bake places each tile's probes over its own share of the terrain; leave "
                               "the origin unset");
        r.gridDims[0] = probes(r.gridDims[0], shareX);
        r.gridDims[1] = probes(r.gridDims[1], shareZ);
    }
}

}  // namespace terralux

#include <bit>
#include <cstring>
#include <fstream>

#include "AtomicFile.h"
#include "TerrainLoading.h"

namespace terralux {

namespace {

static_assert(std::endian::native == std::endian::little, "region.f32 holds little-endian floats");

nlohmann::json regionKey(const Project& project) {
    const std::filesystem::path dem = project.demPath();
    nlohmann::json key = {{"format", 1},
                          {"dem", dem.empty() ? std::string("(sample)") : std::filesystem::absolute(dem).string()},
                          {"max_resolution", project.scene.terrain.maxResolution},
                          {"vertical_scale", project.scene.terrain.verticalScale}};
    std::error_code ec;
    if (!dem.empty()) {
        key["size"] = std::filesystem::file_size(dem, ec);
        key["mtime_ns"] = modifiedUnixNanoseconds(dem).value_or(0);  // Unix time, as the report's inputs
    }
    return key;
}

std::optional<RegionSummary> readSummary(const std::filesystem::path& dir, const nlohmann::json& key) {
    std::ifstream in(dir / "region.json");
    if (!in) return std::nullopt;
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
        if (j.at("key") != key) return std::nullopt;
        RegionSummary s;
        const auto& g = j.at("grid");
        s.grid = {g.at("width"), g.at("depth"), g.at("cell_x"), g.at("cell_z"), g.at("min_height"), g.at("max_height"),
                  g.at("streamed")};
        const auto& o = j.at("overview");
        const int w = o.at("width"), d = o.at("depth");
        std::vector<float> h(size_t(w) * size_t(d));
        std::ifstream bin(dir / "region.f32", std::ios::binary);
        if (!bin.read(reinterpret_cast<char*>(h.data()), std::streamsize(h.size() * sizeof(float)))) return std::nullopt;
        s.overview = Heightfield(w, d, o.at("cell_x").get<double>(), o.at("cell_z").get<double>(), std::move(h));
        GeoOrigin& geo = s.overview.geo;
        const auto& gj = o.at("geo");
        geo.easting = gj.at("easting");
        geo.northing = gj.at("northing");
        geo.height = gj.at("height");
        geo.crsWkt = gj.at("crs_wkt");
        geo.crsName = gj.at("crs_name");
        geo.epsg = gj.at("epsg");
        if (!gj.at("latitude_deg").is_null()) geo.latitudeDeg = gj.at("latitude_deg");
        if (!gj.at("longitude_deg").is_null()) geo.longitudeDeg = gj.at("longitude_deg");
        geo.gridConvergenceDeg = gj.at("grid_convergence_deg");
        s.cached = true;
        return s;
    } catch (const std::exception&) {
        return std::nullopt;  // unreadable or from another version: computed again
    }
}

}  // namespace

RegionSummary regionSummary(const Project& project, const std::filesystem::path& cacheDir, bool write) {
    const nlohmann::json key = regionKey(project);
    if (std::optional<RegionSummary> s = readSummary(cacheDir, key)) return std::move(*s);
    RegionSummary s;
    s.grid = loadProjectGrid(project);
    Project overview = project;
    int& maxRes = overview.scene.terrain.maxResolution;
    maxRes = maxRes > 0 ? std::min(maxRes, kRegionOverview) : kRegionOverview;
    s.overview = loadProjectTerrain(overview).heightfield;
    const Heightfield& o = s.overview;
    const GeoOrigin& geo = o.geo;
    auto orNull = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
    const nlohmann::json j = {
        {"key", key},
        {"grid",
         {{"width", s.grid.width}, {"depth", s.grid.depth}, {"cell_x", s.grid.cellX}, {"cell_z", s.grid.cellZ},
          {"min_height", s.grid.minHeight}, {"max_height", s.grid.maxHeight}, {"streamed", s.grid.streamed}}},
        {"overview",
         {{"width", o.width()}, {"depth", o.depth()}, {"cell_x", o.cellSizeX()}, {"cell_z", o.cellSizeZ()},
          {"geo",
           {{"easting", geo.easting}, {"northing", geo.northing}, {"height", geo.height}, {"crs_wkt", geo.crsWkt},
            {"crs_name", geo.crsName}, {"epsg", geo.epsg}, {"latitude_deg", orNull(geo.latitudeDeg)},
            {"longitude_deg", orNull(geo.longitudeDeg)}, {"grid_convergence_deg", geo.gridConvergenceDeg}}}}}};
    if (!write) return s;
    std::error_code ec;
    std::filesystem::create_directories(cacheDir, ec);
    // The heights first: a region.json is only ever beside the heights it describes.
    const auto* bytes = reinterpret_cast<const uint8_t*>(o.heights().data());
    writeFileAtomically(cacheDir / "region.f32", std::span<const uint8_t>(bytes, o.heights().size() * sizeof(float)));
    writeFileAtomically(cacheDir / "region.json", j.dump(1) + "\n");
    return s;
}

}  // namespace terralux
