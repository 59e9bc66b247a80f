#include "ParameterTable.h"
#include "KeptPlacement.h"

#include <cctype>
#include <charconv>
#include <cstdlib>

#include "LpvConsoleVariables.h"
#include "Project.h"
#include "SceneLighting.h"
#include "bake/PhysicalSky.h"
#include "bake/ReflectionBake.h"
#include "lpv/Lpv.h"
#include "water/Water.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <type_traits>

namespace terralux {

using nlohmann::json;

namespace {

// ---- Converting fields to and from JSON values that passed their row's checks -------------

template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

double shortest(float f) { return shortestDecimal(f); }

json shortest(const glm::vec3& v) { return json{shortest(v.x), shortest(v.y), shortest(v.z)}; }

template <class T>
json fieldToJson(const T& v, const std::vector<std::string>& choices) {
    if constexpr (IsOptional<T>::value) {
        return v ? fieldToJson(*v, choices) : json(nullptr);
    } else if constexpr (std::is_enum_v<T>) {
        return choices.at(size_t(v));
    } else if constexpr (std::is_same_v<T, glm::vec3>) {
        return shortest(v);
    } else if constexpr (std::is_same_v<T, float>) {
        return shortest(v);
    } else {
        return json(v);
    }
}

template <class T>
T fieldFromJson(const json& v, const std::vector<std::string>& choices) {
    if constexpr (IsOptional<T>::value) {
        if (v.is_null()) return std::nullopt;
        return fieldFromJson<typename T::value_type>(v, choices);
    } else if constexpr (std::is_enum_v<T>) {
        const std::string s = v.get<std::string>();
        for (size_t i = 0; i < choices.size(); ++i)
            if (choices[i] == s) return T(i);
        return T(0);
    } else if constexpr (std::is_same_v<T, glm::vec3>) {
        return glm::vec3(v[0].get<float>(), v[1].get<float>(), v[2].get<float>());
    } else if constexpr (std::is_same_v<T, long long>) {
        return v.is_number_unsigned() ? (long long)v.get<unsigned long long>() : v.get<long long>();
    } else if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
        return T(v.get<double>());
    } else {
        return v.get<T>();
    }
}

// ---- A fluent row builder ---------------------------------------------------------------------

class Row {
public:
    Row(std::string path, ParamType type) {
        s_.path = std::move(path);
        s_.type = type;
        if (type == ParamType::Color) s_.minItems = s_.maxItems = 3;
    }
    Row& range(double lo, double hi) { s_.min = lo; s_.max = hi; return *this; }
    Row& above(double lo, double hi) { s_.min = lo; s_.minExclusive = true; s_.max = hi; return *this; }
    Row& openAbove() { s_.maxExclusive = true; return *this; }
    Row& items(int lo, int hi) { s_.minItems = lo; s_.maxItems = hi; return *this; }
    Row& scalarToo() { s_.scalarAllowed = true; return *this; }
    Row& choices(std::vector<std::string> c) { s_.choices = std::move(c); return *this; }
    Row& pattern(std::string re, std::string rule) { s_.pattern = std::move(re); s_.patternRule = std::move(rule); return *this; }
    Row& autoMeans(std::string m) { s_.autoMeaning = std::move(m); return *this; }
    Row& zeroMeans(std::string m) { s_.zeroText = std::move(m); return *this; }
    Row& unit(std::string u) { s_.unit = std::move(u); return *this; }
    Row& label(std::string l) { s_.label = std::move(l); return *this; }
    Row& about(std::string d) { s_.description = std::move(d); return *this; }
    Row& redoes(unsigned i) { s_.invalidates = i; return *this; }
    Row& bakeUse(BakeUse b) { s_.bake = b; return *this; }
    Row& decimals(int d) { s_.decimals = d; return *this; }
    Row& slider() { s_.slider = true; return *this; }
    Row& colorList() { s_.colorList = true; return *this; }
    Row& noUiRow() { s_.uiRow = false; return *this; }
    Row& count(std::function<int(const SceneDescription&, size_t)> f) { s_.items = std::move(f); return *this; }
    Row& onlyWhen(std::function<bool(const SceneDescription&, size_t)> f) { s_.readWhen = std::move(f); return *this; }

    // A field of a scene section (SceneDescription::sun, ::sky, ...).
    template <class Section, class T>
    Row& field(Section SceneDescription::*section, T Section::*member) {
        s_.get = [=, choices = s_.choices](const SceneDescription& s, size_t) {
            return fieldToJson(s.*section.*member, choices);
        };
        s_.set = [=, choices = s_.choices](SceneDescription& s, size_t, const json& v) {
            s.*section.*member = fieldFromJson<T>(v, choices);
        };
        return *this;
    }
    template <class T>
    Row& volume(T ProbeVolumeSettings::*member) {
        s_.get = [=, choices = s_.choices](const SceneDescription& s, size_t i) {
            return fieldToJson(s.probeVolumes.at(i).*member, choices);
        };
        s_.set = [=, choices = s_.choices](SceneDescription& s, size_t i, const json& v) {
            s.probeVolumes.at(i).*member = fieldFromJson<T>(v, choices);
        };
        return *this;
    }
    template <class T>
    Row& adaptive(T AdaptiveVolumeSettings::*member) {
        s_.get = [=, choices = s_.choices](const SceneDescription& s, size_t i) {
            return fieldToJson(s.probeVolumes.at(i).adaptive.*member, choices);
        };
        s_.set = [=, choices = s_.choices](SceneDescription& s, size_t i, const json& v) {
            s.probeVolumes.at(i).adaptive.*member = fieldFromJson<T>(v, choices);
        };
        return *this;
    }
    template <class T>
    Row& wave(T GerstnerWave::*member) {
        s_.get = [=](const SceneDescription& s, size_t i) { return fieldToJson(s.water.waves.at(i).*member, {}); };
        s_.set = [=](SceneDescription& s, size_t i, const json& v) {
            s.water.waves.at(i).*member = fieldFromJson<T>(v, {});
        };
        return *this;
    }
    template <class T>
    Row& light(T LocalLight::*member) {
        s_.get = [=, choices = s_.choices](const SceneDescription& s, size_t i) {
            return fieldToJson(s.lights.at(i).*member, choices);
        };
        s_.set = [=, choices = s_.choices](SceneDescription& s, size_t i, const json& v) {
            s.lights.at(i).*member = fieldFromJson<T>(v, choices);
        };
        return *this;
    }
    Row& resolvedBy(std::function<json(const SceneDescription&, const Heightfield&, size_t)> f) {
        s_.resolved = std::move(f);
        return *this;
    }
    Row& custom(std::function<json(const SceneDescription&, size_t)> get,
                std::function<void(SceneDescription&, size_t, const json&)> set) {
        s_.get = std::move(get);
        s_.set = std::move(set);
        return *this;
    }

    ParameterSpec s_;
};

std::string number(double d) {
    if (std::isinf(d)) return d > 0 ? "inf" : "-inf";
    if (std::floor(d) == d && std::abs(d) < 1e18) return std::to_string((long long)d);
    std::ostringstream s;
    s.precision(15);
    s << d;
    return s.str();
}

// The rule on a grid's size: each >= 1 and a product within the limit.
void checkProduct(const std::array<int, 3>& d, long long limit) {
    const long long product = (long long)d[0] * d[1] * d[2];
    if (product > limit)
        throw ParameterRejection{"must be >= 1 each with a product <= " + std::to_string(limit) +
                                 " (is " + std::to_string(product) + ")", ""};
}

// Deepest octree: max_cell_size up to min_cell_size x 2^16 (seed 001's own defaults are 2^5).
constexpr int kMaxOctreeLevels = 16;

std::vector<ParameterSpec> buildTable() {
    std::vector<Row> rows;
    // Whether the bake reads the rows that follow (a row may say otherwise): each section sets it.
    BakeUse bake = BakeUse::Reads;
    auto add = [&rows, &bake](Row r) -> Row& {
        r.s_.bake = bake;
        rows.push_back(std::move(r));
        return rows.back();
    };
    using T = ParamType;

    bake = BakeUse::Reads;
    // Terrain.
    add(Row("terrain.dem", T::String)).bakeUse(BakeUse::File).zeroMeans("embedded sample")
        .label("DEM").about("Elevation raster GDAL reads (GeoTIFF, SRTM .hgt, ASCII grid, VRT, /vsizip/...); relative to the project file; empty = the embedded sample")
        .redoes(kReimport).field(&SceneDescription::terrain, &TerrainSettings::dem);
    add(Row("terrain.vertical_scale", T::Number)).above(0.0, 100.0).unit("×").label("Vertical scale")
        .about("Multiplies every height before lighting").redoes(kReimport)
        .field(&SceneDescription::terrain, &TerrainSettings::verticalScale);
    const auto albedoMode = [](AlbedoMode m) {
        return [m](const SceneDescription& s, size_t) { return s.terrain.albedoMode == m; };
    };
    add(Row("terrain.albedo_mode", T::Choice)).choices({"constant", "map", "ramp"}).label("Albedo source")
        .about("constant: terrain.albedo everywhere; map: an RGB image draped over the DEM (terrain.albedo_map); ramp: colours by elevation and slope (terrain.ramp_*)")
        .redoes(kUpload | kRebake).field(&SceneDescription::terrain, &TerrainSettings::albedoMode);
    add(Row("terrain.albedo", T::Color)).range(0.0, 1.0).label("Albedo")
        .about("Lambertian reflectance of the ground, linear RGB; in mode map, where the map does not cover the terrain")
        .redoes(kUpload | kRebake).onlyWhen(std::not_fn(albedoMode(AlbedoMode::Ramp)))
        .field(&SceneDescription::terrain, &TerrainSettings::albedo);
    add(Row("terrain.albedo_map", T::String)).bakeUse(BakeUse::File).label("Albedo map")
        .about("RGB or RGBA raster GDAL reads (orthophoto GeoTIFF, PNG/JPEG with a world file), 8 or 16 bits, sRGB-encoded, for mode map; reprojected onto the DEM; relative to the project file")
        .redoes(kUpload | kRebake).onlyWhen(albedoMode(AlbedoMode::Map))
        .custom([](const SceneDescription& s, size_t) { return json(s.terrain.albedoMap); },
                [](SceneDescription& s, size_t, const json& v) {
                    s.terrain.albedoMap = v.get<std::string>();
                    if (s.terrain.albedoMode == AlbedoMode::Map && s.terrain.albedoMap.empty())
                        throw ParameterRejection{"must name a raster when terrain.albedo_mode is \"map\"", ""};
                });
    const auto ramp = albedoMode(AlbedoMode::Ramp);
    add(Row("terrain.ramp_heights", T::NumberList)).items(2, kMaxRampStops).range(-1.0e4, 1.0e4).unit("m").decimals(0)
        .label("Ramp heights")
        .about("Mode ramp: elevations of the colour stops, metres of DEM elevation (before terrain.vertical_scale), strictly increasing; colours are interpolated between stops and held beyond the first and last")
        .redoes(kUpload | kRebake).onlyWhen(ramp)
        .custom([](const SceneDescription& s, size_t) { return json(s.terrain.ramp.heights); },
                [](SceneDescription& s, size_t, const json& v) {
                    auto& h = s.terrain.ramp.heights;
                    h = v.get<std::vector<double>>();
                    for (size_t i = 1; i < h.size(); ++i)
                        if (!(h[i] > h[i - 1]))
                            throw ParameterRejection{"must be strictly increasing (" + number(h[i]) +
                                                         " follows " + number(h[i - 1]) + ")",
                                                     "[" + std::to_string(i) + "]"};
                });
    add(Row("terrain.ramp_colors", T::NumberList)).items(6, 3 * kMaxRampStops).range(0.0, 1.0).decimals(3)
        .label("Ramp colours").colorList()
        .about("Mode ramp: linear RGB albedo of each stop, three numbers per height in terrain.ramp_heights (r0, g0, b0, r1, ...)")
        .redoes(kUpload | kRebake).onlyWhen(ramp)
        .count([](const SceneDescription& s, size_t) { return 3 * int(s.terrain.ramp.heights.size()); })
        .custom([](const SceneDescription& s, size_t) {
                    json out = json::array();
                    for (const glm::vec3& c : s.terrain.ramp.colors)
                        for (int k = 0; k < 3; ++k) out.push_back(shortest(c[k]));
                    return out;
                },
                [](SceneDescription& s, size_t, const json& v) {
                    auto& colors = s.terrain.ramp.colors;
                    colors.clear();
                    for (size_t i = 0; i + 2 < v.size(); i += 3)
                        colors.emplace_back(v[i].get<float>(), v[i + 1].get<float>(), v[i + 2].get<float>());
                });
    add(Row("terrain.ramp_rock_color", T::Color)).range(0.0, 1.0).label("Rock colour")
        .about("Mode ramp: linear RGB albedo of steep ground, blended in over terrain.ramp_rock_slope")
        .redoes(kUpload | kRebake).onlyWhen(ramp)
        .custom([](const SceneDescription& s, size_t) { return shortest(s.terrain.ramp.rockColor); },
                [](SceneDescription& s, size_t, const json& v) {
                    s.terrain.ramp.rockColor = glm::vec3(v[0].get<float>(), v[1].get<float>(), v[2].get<float>());
                });
    add(Row("terrain.ramp_rock_slope", T::NumberList)).items(2, 2).range(0.0, 90.0).unit("°").decimals(1)
        .label("Rock slope")
        .about("Mode ramp: [start, end] slope from horizontal over which the ground turns to rock (smoothstep); start < end")
        .redoes(kUpload | kRebake).onlyWhen(ramp)
        .custom([](const SceneDescription& s, size_t) {
                    return json{s.terrain.ramp.rockSlopeDeg[0], s.terrain.ramp.rockSlopeDeg[1]};
                },
                [](SceneDescription& s, size_t, const json& v) {
                    auto& r = s.terrain.ramp.rockSlopeDeg;
                    r = {v[0].get<double>(), v[1].get<double>()};
                    if (!(r[1] > r[0]))
                        throw ParameterRejection{"end must be above start (" + number(r[1]) +
                                                     " is not above " + number(r[0]) + ")", "[1]"};
                });
    add(Row("terrain.max_resolution", T::Integer)).range(0, 65536).unit("cells").zeroMeans("source").label("Max resolution")
        .about("Longest side after area-averaged resampling; 0 = the source resolution (1 is not a grid)")
        .redoes(kReimport)
        .custom([](const SceneDescription& s, size_t) { return json(s.terrain.maxResolution); },
                [](SceneDescription& s, size_t, const json& v) {
                    if (v.get<int>() == 1) throw ParameterRejection{"must be 0 (off) or >= 2", ""};
                    s.terrain.maxResolution = v.get<int>();
                });
    add(Row("terrain.skirt", T::Boolean)).label("Ground beyond border")
        .about("The ground continues beyond the footprint at the border height (rays leaving the DEM still meet terrain)")
        .redoes(kRebake).field(&SceneDescription::terrain, &TerrainSettings::skirt);
    add(Row("terrain.roughness", T::Number)).bakeUse(BakeUse::Ignores).range(kRoughnessFloor, 1.0).decimals(2).slider().label("Roughness")
        .about("GGX roughness of the sun's highlight on the ground, before the normal variance widens it (0.25 is the floor)")
        .redoes(kUpload).field(&SceneDescription::terrain, &TerrainSettings::roughness);
    add(Row("terrain.specular_aa", T::Boolean)).bakeUse(BakeUse::Ignores).label("Normal-variance specular")
        .about("Widens the roughness by the variance of the normals a pixel covers (Toksvig 2005): no sparkle from detail smaller than a pixel")
        .redoes(kUpload).field(&SceneDescription::terrain, &TerrainSettings::specularAA);

    // Sun.
    const auto physical = [](const SceneDescription& s, size_t) { return s.sky.mode == SkyMode::Physical; };
    const auto sunFromSky = [](const SceneDescription& s, size_t) {
        return (s.sky.mode == SkyMode::Physical || s.sky.mode == SkyMode::Hdr) && s.sun.followSky;
    };
    // The image's glow is the sun: where it stands, how bright and how large are the image's.
    static constexpr const char* kNotUnderImageSun = "; not read while the sun follows an image sky (sun.follow_sky)";
    const auto placedSun = [](const SceneDescription& s, size_t) { return !sunFromSkyImage(s); };
    const auto manualSun = [](const SceneDescription& s, size_t) { return s.sun.mode == SunMode::Manual && !sunFromSkyImage(s); };
    const auto datedSun = [](const SceneDescription& s, size_t) { return s.sun.mode == SunMode::DateTime && !sunFromSkyImage(s); };
    add(Row("sun.mode", T::Choice)).choices({"manual", "date_time"}).label("Sun position")
        .about("manual: sun.azimuth_deg and sun.elevation_deg; date_time: where the sun stands over the terrain at sun.date and sun.time_h (NOAA's solar position, refracted, turned from true to the DEM grid's north)" + std::string(kNotUnderImageSun))
        .redoes(kUpload | kRebake).onlyWhen(placedSun).field(&SceneDescription::sun, &SunSettings::mode);
    add(Row("sun.azimuth_deg", T::Number)).range(-360.0, 360.0).unit("°").decimals(1).slider()
        .label("Sun azimuth").about(std::string("Direction of the sun, clockwise from north (-Z) toward east (+X)") + kNotUnderImageSun)
        .redoes(kUpload | kRebake).onlyWhen(manualSun).field(&SceneDescription::sun, &SunSettings::azimuthDeg);
    add(Row("sun.elevation_deg", T::Number)).range(-90.0, 90.0).unit("°").decimals(1).slider()
        .label("Sun elevation").about(std::string("Angle of the sun above the horizon") + kNotUnderImageSun)
        .redoes(kUpload | kRebake).onlyWhen(manualSun).field(&SceneDescription::sun, &SunSettings::elevationDeg);
    const std::string dateRule = "must be " + civilDateRule();
    add(Row("sun.date", T::String)).pattern("[0-9]{4}-[0-9]{2}-[0-9]{2}", dateRule).label("Date")
        .about(std::string("Day of the sun's position, Gregorian, on the local clock") + kNotUnderImageSun)
        .redoes(kUpload | kRebake).onlyWhen(datedSun)
        .custom([](const SceneDescription& s, size_t) { return json(s.sun.date); },
                [dateRule](SceneDescription& s, size_t, const json& v) {
                    const std::string text = v.get<std::string>();
                    if (!parseCivilDate(text)) throw ParameterRejection{dateRule, ""};
                    s.sun.date = text;
                });
    add(Row("sun.time_h", T::Number)).range(0.0, 24.0).unit("h").decimals(2).slider().label("Local time")
        .about(std::string("Hours after local midnight on the clock sun.utc_offset_h gives (13.5 is 13:30; 24 is the next midnight)") + kNotUnderImageSun)
        .redoes(kUpload | kRebake).onlyWhen(datedSun).field(&SceneDescription::sun, &SunSettings::timeH);
    // The place the sun is computed for, as sunAnglesOf resolves it.
    const auto placeOf = [](const SceneDescription& s, const Heightfield& hf) -> std::optional<std::array<double, 2>> {
        if (s.sun.latitudeDeg && s.sun.longitudeDeg) return std::array{*s.sun.latitudeDeg, *s.sun.longitudeDeg};
        if (!hf.geo.located()) return std::nullopt;
        return std::array{s.sun.latitudeDeg.value_or(hf.geo.latitudeDeg), s.sun.longitudeDeg.value_or(hf.geo.longitudeDeg)};
    };
    add(Row("sun.utc_offset_h", T::Number)).range(-12.0, 14.0).unit("h").decimals(2).label("UTC offset")
        .autoMeans("the longitude's nominal zone: the whole hours nearest longitude / 15")
        .resolvedBy([placeOf](const SceneDescription& s, const Heightfield& hf, size_t) -> json {
            const auto place = placeOf(s, hf);
            return place ? json(nominalUtcOffsetHours((*place)[1])) : json(nullptr);
        })
        .about(std::string("How far the local clock is ahead of UTC, daylight saving included (Central European Summer Time: 2)") + kNotUnderImageSun)
        .redoes(kUpload | kRebake).onlyWhen(datedSun).field(&SceneDescription::sun, &SunSettings::utcOffsetH);
    // Latitude (axis 0) and longitude (axis 1) of the place, alike but for their range and words.
    const auto placeRow = [&](const char* path, int axis, double limit, const char* label, const char* about,
                              std::optional<double> SunSettings::*member) {
        add(Row(path, T::Number)).range(-limit, limit).unit("°").decimals(4).label(label)
            .autoMeans("the DEM's centre: its footprint centre, from its CRS, in WGS 84")
            .resolvedBy([placeOf, axis](const SceneDescription& s, const Heightfield& hf, size_t) -> json {
                const auto place = placeOf(s, hf);
                return place ? json((*place)[size_t(axis)]) : json(nullptr);
            })
            .about(std::string(about) + kNotUnderImageSun).redoes(kUpload | kRebake).onlyWhen(datedSun).field(&SceneDescription::sun, member);
    };
    placeRow("sun.latitude_deg", 0, 90.0, "Latitude",
             "Where the sun is computed for, north positive; set it (with sun.longitude_deg) for a DEM without a CRS",
             &SunSettings::latitudeDeg);
    placeRow("sun.longitude_deg", 1, 180.0, "Longitude", "Where the sun is computed for, east positive",
             &SunSettings::longitudeDeg);
    const auto skyWithSun = [](const SceneDescription& s, size_t) {
        return s.sky.mode == SkyMode::Physical || s.sky.mode == SkyMode::Hdr;
    };
    add(Row("sun.follow_sky", T::Boolean)).label("Sun from sky")
        .about("Sky mode physical: the sun's colour and illuminance come from the sky model (sun.color and sun.illuminance are not read). "
               "Sky mode hdr: the image's sun is the sun, its glow taken out of the sky the probes see and lit as the directional light: "
               "direction, illuminance, colour and radius from the image (no other sun.* is read; docs/lighting.md, \"The image's sun\"); off, the image lights whole and the authored sun adds to it")
        .redoes(kUpload | kRebake).onlyWhen(skyWithSun).field(&SceneDescription::sun, &SunSettings::followSky);
    add(Row("sun.illuminance", T::Number)).range(0.0, 1.0e7).unit("lx").decimals(0).label("Sun illuminance")
        .about("Illuminance on a surface facing the sun: a clear day's sun is about 100 000 lx, an overcast one 0; "
               "the bake lights with 3e-5 scene units per lux, the unit of the sky's radiance; not read while the sun follows the sky")
        .redoes(kUpload | kRebake).onlyWhen(std::not_fn(sunFromSky))
        .field(&SceneDescription::sun, &SunSettings::illuminance);
    add(Row("sun.color", T::Color)).range(0.0, kUnbounded).label("Sun colour")
        .about("Linear RGB tint of the sun's illuminance; not read while the sun follows the sky").redoes(kUpload | kRebake)
        .onlyWhen(std::not_fn(sunFromSky)).field(&SceneDescription::sun, &SunSettings::color);
    add(Row("sun.angular_radius_deg", T::Number)).range(0.0, Sky::kMaxSunRadiusDeg).unit("°").label("Sun radius")
        .about("Angular radius of the sun's disc (0.27° for the real sun): soft shadow size" + std::string(kNotUnderImageSun))
        .redoes(kUpload | kRebake).onlyWhen(placedSun).field(&SceneDescription::sun, &SunSettings::angularRadiusDeg);

    // Sky.
    const auto hdr = [](const SceneDescription& s, size_t) { return s.sky.mode == SkyMode::Hdr; };
    add(Row("sky.mode", T::Choice)).choices({"uniform", "hdr", "physical"}).label("Sky")
        .about("uniform: one radiance from every direction; hdr: an equirectangular image; physical: a clear sky from the sun's position and the turbidity (Preetham 1999)")
        .redoes(kUpload | kRebake).field(&SceneDescription::sky, &SkySettings::mode);
    const auto uniformSky = [](const SceneDescription& s, size_t) { return s.sky.mode == SkyMode::Uniform; };
    add(Row("sky.color", T::Color)).range(0.0, 1.0).label("Sky colour")
        .about("Linear RGB tint of the uniform sky's luminance")
        .redoes(kUpload | kRebake).onlyWhen(uniformSky).field(&SceneDescription::sky, &SkySettings::color);
    add(Row("sky.luminance", T::Number)).range(0.0, 1.0e7).unit("cd/m²").decimals(0).label("Sky luminance")
        .about("Luminance of the uniform sky, the same from every direction, per channel times its colour: a clear day's "
               "sky is a few thousand cd/m²; with the default sun and colour, a clear day's direct-to-diffuse ratio")
        .redoes(kUpload | kRebake).onlyWhen(uniformSky).field(&SceneDescription::sky, &SkySettings::luminance);
    add(Row("sky.intensity", T::Number)).range(0.0, 1.0e5).label("Sky intensity")
        .about("Multiplies the sky's light (the uniform sky's luminance or the HDR image); in mode physical, the exposure of the whole daylight, sun included")
        .redoes(kUpload | kRebake).field(&SceneDescription::sky, &SkySettings::intensity);
    add(Row("sky.turbidity", T::Number)).range(kMinTurbidity, kMaxTurbidity).label("Turbidity")
        .about("Haze of the physical sky: 2 very clear, 3 clear, 6 and above hazy; a hazier sky is brighter and whiter, its sun dimmer and redder")
        .redoes(kUpload | kRebake).onlyWhen(physical).field(&SceneDescription::sky, &SkySettings::turbidity);
    add(Row("sky.hdr", T::String)).bakeUse(BakeUse::File).label("HDR image")
        .about("Equirectangular HDR or EXR sky, for mode hdr; relative to the project file")
        .redoes(kUpload | kRebake).onlyWhen(hdr)
        .custom([](const SceneDescription& s, size_t) { return json(s.sky.hdr); },
                [](SceneDescription& s, size_t, const json& v) {
                    s.sky.hdr = v.get<std::string>();
                    if (s.sky.mode == SkyMode::Hdr && s.sky.hdr.empty())
                        throw ParameterRejection{"must name an image when sky.mode is \"hdr\"", ""};
                });
    add(Row("sky.rotation_deg", T::Number)).range(-360.0, 360.0).unit("°").decimals(1).slider()
        .label("HDR rotation").about("Turns the HDR sky about +Y").redoes(kUpload | kRebake).onlyWhen(hdr)
        .field(&SceneDescription::sky, &SkySettings::rotationDeg);

    bake = BakeUse::Ignores;  // from here to the probe volumes, what the renderer draws
    // Shadows.
    const auto manualSplits = [](const SceneDescription& s, size_t) {
        return s.shadows.splitMode == SplitMode::Manual && s.shadows.cascades > 1 ? s.shadows.cascades - 1 : -1;
    };
    const auto shadowsOn = [](const SceneDescription& s, size_t) { return s.shadows.enabled; };
    add(Row("shadows.enabled", T::Boolean)).label("Sun shadows")
        .about("Cascaded shadow maps darken the direct sun where the terrain blocks it")
        .redoes(kUpload).field(&SceneDescription::shadows, &ShadowSettings::enabled);
    add(Row("shadows.cascades", T::Integer)).range(1, 4).label("Cascades")
        .about("Shadow maps along the view, each covering a slice of it: more gives sharper near shadows")
        .redoes(kUpload).onlyWhen(shadowsOn).field(&SceneDescription::shadows, &ShadowSettings::cascades);
    add(Row("shadows.split_mode", T::Choice)).choices({"practical", "manual"}).label("Split mode")
        .about("practical: split distances from split_lambda; manual: the distances in splits")
        .redoes(kUpload).onlyWhen(shadowsOn).field(&SceneDescription::shadows, &ShadowSettings::splitMode);
    add(Row("shadows.split_lambda", T::Number)).range(0.0, 1.0).decimals(2).slider().label("Split lambda")
        .about("Practical splits (Zhang et al. 2006): C_i = λ·C_log + (1 − λ)·C_uni; λ weights the logarithmic term: 0 = uniform, 1 = logarithmic")
        .redoes(kUpload)
        .onlyWhen([](const SceneDescription& s, size_t) {
            return s.shadows.enabled && s.shadows.splitMode == SplitMode::Practical && s.shadows.cascades > 1;
        })
        .field(&SceneDescription::shadows, &ShadowSettings::splitLambda);
    add(Row("shadows.max_distance", T::Number)).above(0.0, 1.0e7).unit("m").decimals(0)
        .autoMeans("the farthest terrain in view").label("Shadow distance")
        .about("Distance from the camera where the last cascade ends; farther terrain gets the sun unshadowed, the last "
               "cascade fading into it over its far shadows.cascade_blend")
        .redoes(kUpload).onlyWhen(shadowsOn).field(&SceneDescription::shadows, &ShadowSettings::maxDistance);
    add(Row("shadows.splits", T::NumberList)).items(1, 3).above(0.0, 1.0e7).unit("m").decimals(0)
        .autoMeans("none: practical mode computes them").label("Split distances")
        .about("manual mode: where each cascade but the last ends, metres from the camera, strictly increasing and below the shadow distance")
        .redoes(kUpload).count(manualSplits)
        .custom([](const SceneDescription& s, size_t) {
                    return s.shadows.splits ? json(*s.shadows.splits) : json(nullptr);
                },
                [=](SceneDescription& s, size_t, const json& v) {
                    auto& sp = s.shadows.splits;
                    if (v.is_null()) {
                        sp.reset();
                        if (manualSplits(s, 0) > 0)
                            throw ParameterRejection{"must list " + std::to_string(manualSplits(s, 0)) +
                                                         " distances when split_mode is \"manual\"", ""};
                        return;
                    }
                    sp = v.get<std::vector<double>>();
                    const int n = manualSplits(s, 0);
                    if (n < 0) return;  // kept for a switch back to manual
                    if (int(sp->size()) != n)
                        throw ParameterRejection{"must list cascades - 1 = " + std::to_string(n) +
                                                     " distances (has " + std::to_string(sp->size()) + ")", ""};
                    for (size_t i = 1; i < sp->size(); ++i)
                        if (!((*sp)[i] > (*sp)[i - 1]))
                            throw ParameterRejection{"must be strictly increasing (" + number((*sp)[i]) +
                                                         " follows " + number((*sp)[i - 1]) + ")",
                                                     "[" + std::to_string(i) + "]"};
                    if (s.shadows.maxDistance && !(sp->back() < *s.shadows.maxDistance))
                        throw ParameterRejection{"must end below shadows.max_distance (" +
                                                     number(*s.shadows.maxDistance) + ")",
                                                 "[" + std::to_string(sp->size() - 1) + "]"};
                });
    add(Row("shadows.map_resolution", T::Integer)).range(512, 4096).unit("texels").label("Map resolution")
        .about("Texels along each side of each cascade's shadow map")
        .redoes(kUpload).onlyWhen(shadowsOn).field(&SceneDescription::shadows, &ShadowSettings::mapResolution);
    add(Row("shadows.depth_bias", T::Number)).range(0.0, 100.0).unit("texels").label("Depth bias")
        .about("Moves the receiver toward the sun by this many cascade texels: removes self-shadowing acne")
        .redoes(kUpload).onlyWhen(shadowsOn).field(&SceneDescription::shadows, &ShadowSettings::depthBias);
    add(Row("shadows.normal_bias", T::Number)).range(0.0, 100.0).unit("texels").label("Normal bias")
        .about("Moves the receiver along its normal by this many cascade texels: removes acne on slopes facing away")
        .redoes(kUpload).onlyWhen(shadowsOn).field(&SceneDescription::shadows, &ShadowSettings::normalBias);
    add(Row("shadows.filter", T::Choice))
        .choices({shadowFilterName(ShadowFilter::Pcss), shadowFilterName(ShadowFilter::Pcf), shadowFilterName(ShadowFilter::Hard)}).label("Filter")
        .about("pcss: penumbrae from the sun's size that harden at contact (Fernando 2005); pcf: a fixed soft edge; hard: one comparison")
        .redoes(kUpload).onlyWhen(shadowsOn).field(&SceneDescription::shadows, &ShadowSettings::filter);
    add(Row("shadows.cascade_blend", T::Number)).range(0.0, 0.5).decimals(2).label("Cascade blend")
        .about("Share of each cascade's depth slice, at its far end, over which its shadow blends into the next cascade's, "
               "so the change of texel size leaves no seam, and the last one's into the unshadowed sun where the "
               "shadow distance ends before the terrain; 0 switches at once")
        .redoes(kUpload).onlyWhen(shadowsOn).field(&SceneDescription::shadows, &ShadowSettings::cascadeBlend);
    add(Row("shadows.heightfield", T::Boolean)).label("Terrain horizon")
        .about("Where a cascade's texels lose shadows longer than a DEM cell (0.75 texel of depth slope: "
               "0.75·texel/tan(sun elevation) on level ground), the terrain's own shadow comes from its horizon "
               "toward the sun at every DEM vertex, swept when the sun moves; off: the maps everywhere")
        .redoes(kUpload).onlyWhen(shadowsOn).field(&SceneDescription::shadows, &ShadowSettings::heightfield);

    // Height fog.
    const auto fogOn = [](const SceneDescription& s, size_t) { return s.fog.enabled; };
    add(Row("fog.enabled", T::Boolean)).label("Height fog")
        .about("Exponential height fog over the terrain and the sky")
        .redoes(kUpload).field(&SceneDescription::fog, &FogSettings::enabled);
    add(Row("fog.density", T::Number)).range(0.0, 1.0).unit("1/m").decimals(6).label("Density")
        .about("Extinction coefficient at the base height")
        .redoes(kUpload).onlyWhen(fogOn).field(&SceneDescription::fog, &FogSettings::density);
    add(Row("fog.scale_height", T::Number)).range(0.0, 1.0e6).unit("m").decimals(0)
        .zeroMeans("the same at every height").label("Scale height")
        .about("Height above the base height over which the density falls by e (a haze layer is about 1200 m); 0 = the same at every height")
        .redoes(kUpload).onlyWhen(fogOn).field(&SceneDescription::fog, &FogSettings::scaleHeight);
    add(Row("fog.base_height", T::Number)).range(-1.0e5, 1.0e5).unit("m").decimals(1)
        .autoMeans("the lowest terrain").label("Base height")
        .about("Height where the density is fog.density, engine space")
        .redoes(kUpload).onlyWhen(fogOn).field(&SceneDescription::fog, &FogSettings::baseHeight);
    // The skies the scene alone describes; an HDR sky's mean needs its file, read by the bake.
    const auto resolvedFogOf = [](const SceneDescription& s, const Heightfield& hf) -> std::optional<FogSettings> {
        if (s.sky.mode == SkyMode::Hdr) return std::nullopt;
        Project p;
        p.scene = s;
        return resolvedFog(s.fog, skyOf(p, hf), hf);
    };
    add(Row("fog.color", T::Color)).range(0.0, 1.0).autoMeans("the sky's mean colour").label("Fog colour")
        .about("Linear RGB tint of the light the fog scatters toward the camera from the sky")
        .resolvedBy([resolvedFogOf](const SceneDescription& s, const Heightfield& hf, size_t) -> json {
            const std::optional<FogSettings> f = resolvedFogOf(s, hf);
            if (!f) return nullptr;
            return json{f->color->x, f->color->y, f->color->z};
        })
        .redoes(kUpload).onlyWhen(fogOn).field(&SceneDescription::fog, &FogSettings::color);
    add(Row("fog.luminance", T::Number)).range(0.0, 1.0e7).unit("cd/m²").decimals(0)
        .autoMeans("the sky's mean luminance").label("Fog luminance")
        .about("Luminance of the light the fog scatters toward the camera from the sky, per channel times its colour")
        .resolvedBy([resolvedFogOf](const SceneDescription& s, const Heightfield& hf, size_t) -> json {
            const std::optional<FogSettings> f = resolvedFogOf(s, hf);
            if (!f) return nullptr;
            return json(*f->luminance);
        })
        .redoes(kUpload).onlyWhen(fogOn).field(&SceneDescription::fog, &FogSettings::luminance);
    add(Row("fog.inscatter", T::Number)).range(0.0, 100.0).label("Sun inscatter")
        .about("Scales the sunlight the fog scatters toward the camera")
        .redoes(kUpload).onlyWhen(fogOn).field(&SceneDescription::fog, &FogSettings::inscatter);
    add(Row("fog.anisotropy", T::Number)).range(-0.95, 0.95).slider().label("Anisotropy")
        .about("Henyey–Greenstein g of the sun's inscatter: > 0 glows around the sun, 0 scatters evenly")
        .redoes(kUpload).onlyWhen(fogOn).field(&SceneDescription::fog, &FogSettings::anisotropy);

    // Micro-detail: the viewport and --render only.
    const auto detailOn = [](const SceneDescription& s, size_t) { return s.detail.enabled; };
    add(Row("detail.enabled", T::Boolean)).label("Micro-detail")
        .about("A procedural detail normal and albedo variation near the camera, in the viewport and --render; the bake never sees it")
        .redoes(kUpload).field(&SceneDescription::detail, &DetailSettings::enabled);
    add(Row("detail.normal_strength", T::Number)).range(0.0, 2.0).decimals(2).slider().label("Detail normal")
        .about("Slope of the tiling detail bump; 0 = no detail normal")
        .redoes(kUpload).onlyWhen(detailOn).field(&SceneDescription::detail, &DetailSettings::normalStrength);
    add(Row("detail.scale", T::Number)).range(0.1, 100.0).unit("m").decimals(1).label("Detail repeat")
        .about("Metres per repeat of the detail bump (triplanar, so steep faces are not stretched)")
        .redoes(kUpload).onlyWhen(detailOn).field(&SceneDescription::detail, &DetailSettings::scale);
    add(Row("detail.fade_distance", T::Number)).above(0.0, 1.0e6).unit("m").decimals(0).label("Detail fade")
        .about("Distance from the camera where the detail normal has faded out, linearly from the camera")
        .redoes(kUpload).onlyWhen(detailOn).field(&SceneDescription::detail, &DetailSettings::fadeDistance);
    add(Row("detail.albedo_variation", T::Number)).range(0.0, 0.5).decimals(2).slider().label("Albedo variation")
        .about("The albedo varies by up to ± this share, in noise over 64 m and 9 m; 0 = none")
        .redoes(kUpload).onlyWhen(detailOn).field(&SceneDescription::detail, &DetailSettings::albedoVariation);

    // Horizon ambient occlusion (docs/lighting.md): a render setting, like shadows and fog.
    const auto aoOn = [](const SceneDescription& s, size_t) { return s.ao.enabled; };
    add(Row("ao.enabled", T::Boolean)).label("Ambient occlusion")
        .about("Darkens the sky light, and probe light coarser than the AO, by the terrain's horizon ambient occlusion: the cosine-weighted share of the sky each vertex sees")
        .redoes(kUpload).field(&SceneDescription::ao, &AoSettings::enabled);
    add(Row("ao.directions", T::Integer)).range(8, 64).label("AO directions")
        .about("Azimuths swept for the horizon at each vertex: more are smoother and cost proportionally more")
        .redoes(kUpload).onlyWhen(aoOn).field(&SceneDescription::ao, &AoSettings::directions);
    add(Row("ao.max_distance", T::Number)).above(0.0, 1.0e7).unit("m").decimals(0)
        .autoMeans("unbounded: the whole footprint occludes").label("AO distance")
        .about("How far the horizon search reaches from each vertex; terrain farther away does not occlude")
        .redoes(kUpload).onlyWhen(aoOn).field(&SceneDescription::ao, &AoSettings::maxDistance);
    add(Row("ao.strength", T::Number)).range(0.0, 1.0).decimals(2).slider().label("AO strength")
        .about("How strongly the precomputed AO darkens probe light where probes are coarser than the AO (0 = off, 1 = full)")
        .redoes(kUpload).onlyWhen(aoOn).field(&SceneDescription::ao, &AoSettings::strength);

    // Water (docs/lighting.md, "Water"): the renderer draws it; the bake's probe rays see it
    // (enabled, level, color); the glTF exports it.
    const auto waterOn = [](const SceneDescription& s, size_t) { return s.water.enabled; };
    const auto planar = [](const SceneDescription& s, size_t) {
        return s.water.enabled && s.water.reflection == WaterReflection::Planar;
    };
    add(Row("water.enabled", T::Boolean)).bakeUse(BakeUse::Reads).label("Water")
        .about("A lake or sea: a level plane at water.level with Gerstner waves over the terrain below it; the viewport and --render draw it, the bake's probe rays see it, the glTF exports it")
        .redoes(kUpload | kRebake).field(&SceneDescription::water, &WaterSettings::enabled);
    add(Row("water.level", T::Number)).bakeUse(BakeUse::Reads).range(-1.0e5, 1.0e5).unit("m").decimals(1)
        .autoMeans("the water the DEM shows: its largest flat, lowest surface (none when it shows none)").label("Water level")
        .about("Height of the water at rest, engine space (DEM elevation × terrain.vertical_scale); the water covers the terrain below it")
        .redoes(kUpload | kRebake).onlyWhen(waterOn).field(&SceneDescription::water, &WaterSettings::level);
    add(Row("water.color", T::Color)).bakeUse(BakeUse::Reads).range(0.0, 1.0).label("Scatter colour")
        .about("Deep-water scatter albedo, linear RGB: the share of the light entering the water that the water sends back up, (1 − F)·color·E/π toward a viewer")
        .redoes(kUpload | kRebake).onlyWhen(waterOn).field(&SceneDescription::water, &WaterSettings::color);
    add(Row("water.absorption", T::NumberList)).items(3, 3).range(0.0, 100.0).unit("1/m").decimals(3)
        .label("Absorption")
        .about("Extinction per metre, linear RGB: light crossing d metres of water keeps exp(−absorption·d), so the bed fades with depth; red goes first in clear water")
        .redoes(kUpload).onlyWhen(waterOn).field(&SceneDescription::water, &WaterSettings::absorption);
    add(Row("water.roughness", T::Number)).range(0.02, 1.0).decimals(2).slider().label("Water roughness")
        .about("GGX roughness of the sun's highlight on the waves; the waves' own normals carry their larger slopes")
        .redoes(kUpload).onlyWhen(waterOn).field(&SceneDescription::water, &WaterSettings::roughness);
    add(Row("water.depth_aware", T::Boolean)).label("Depth-aware waves")
        .about("Waves slow down in the shallows: ω² = g·k·tanh(k·h), h the water depth over the DEM; off: deep water everywhere, ω² = g·k")
        .redoes(kUpload).onlyWhen(waterOn).field(&SceneDescription::water, &WaterSettings::depthAware);
    add(Row("water.shore_fade_distance", T::Number)).range(0.0, 1.0e5).unit("m").decimals(1).zeroMeans("no fade")
        .autoMeans("two cells: twice the DEM's larger cell spacing, so the fade ramps over vertices on any DEM")
        .resolvedBy([](const SceneDescription& s, const Heightfield& hf, size_t) {
            return json(water::shoreFadeDistance(s.water, hf));
        })
        .label("Shore fade")
        .about("Distance from the shore (the nearest DEM vertex at or above the level) over which the waves grow from nothing to their full amplitude, smoothstep; 0 = no fade")
        .redoes(kUpload).onlyWhen(waterOn).field(&SceneDescription::water, &WaterSettings::shoreFadeDistance);
    add(Row("water.reflection", T::Choice)).choices({"planar", "sky"}).label("Reflection")
        .about("planar: the terrain and sky mirrored in the level water, drawn in a second pass; sky: the sky alone, from its SH")
        .redoes(kUpload).onlyWhen(waterOn).field(&SceneDescription::water, &WaterSettings::reflection);
    add(Row("water.reflection_scale", T::Number)).range(0.25, 1.0).decimals(2).slider().label("Reflection scale")
        .about("Size of the planar reflection's target relative to the frame, each side")
        .redoes(kUpload).onlyWhen(planar).field(&SceneDescription::water, &WaterSettings::reflectionScale);
    add(Row("water.distortion", T::Number)).range(0.0, 0.2).decimals(3).label("Reflection distortion")
        .about("How far the waves shift the planar reflection: screen-space offset per unit of wave slope")
        .redoes(kUpload).onlyWhen(planar).field(&SceneDescription::water, &WaterSettings::distortion);
    // The waves: a list of objects the Water dock's wave editor edits as a whole.
    add(Row("water.waves[].direction_deg", T::Number)).range(-360.0, 360.0).unit("°").decimals(1)
        .label("Wave direction").about("Where the wave travels, clockwise from north (-Z) toward east (+X)")
        .redoes(kUpload).noUiRow().wave(&GerstnerWave::directionDeg);
    add(Row("water.waves[].wavelength", T::Number)).range(0.1, 1.0e4).unit("m").decimals(2)
        .label("Wavelength").about("Crest to crest, λ; the wave number is k = 2π/λ and the deep-water angular frequency ω = √(g·k)")
        .redoes(kUpload).noUiRow().wave(&GerstnerWave::wavelength);
    add(Row("water.waves[].amplitude", T::Number)).range(0.0, 100.0).unit("m").decimals(3)
        .autoMeans("from steepness: A = steepness / k").label("Amplitude")
        .about("Height of a crest above the level, A; exactly one of amplitude and steepness is set")
        .redoes(kUpload).noUiRow().wave(&GerstnerWave::amplitude);
    add(Row("water.waves[].steepness", T::Number)).range(0.0, 1.0).decimals(3)
        .autoMeans("from amplitude: k·A").label("Steepness")
        .about("k·A, the wave's largest slope; exactly one of amplitude and steepness is set, and the summed k·A of all waves is at most 1 so no crest loops")
        .redoes(kUpload).noUiRow()
        .custom([](const SceneDescription& s, size_t i) { return fieldToJson(s.water.waves.at(i).steepness, {}); },
                [](SceneDescription& s, size_t i, const json& v) {
                    // Read after amplitude (table order), so the pair is checked here.
                    GerstnerWave& w = s.water.waves.at(i);
                    w.steepness = fieldFromJson<std::optional<double>>(v, {});
                    if (w.steepness && w.amplitude)
                        throw ParameterRejection{"must be null when amplitude is set (exactly one of amplitude and steepness)", ""};
                    if (!w.steepness && !w.amplitude)
                        throw ParameterRejection{"must be set when amplitude is null (exactly one of amplitude and steepness)", ""};
                });
    add(Row("water.waves[].phase", T::Number)).range(-100.0, 100.0).unit("rad").decimals(3)
        .label("Phase").about("Phase at t = 0 and the engine origin, radians (periodic in 2π)")
        .redoes(kUpload).noUiRow().wave(&GerstnerWave::phase);

    bake = BakeUse::Reads;
    // Probe volumes: every row below is per volume.
    const auto isBox = [](const SceneDescription& s, size_t i) {
        return s.probeVolumes.at(i).placement == ProbePlacement::Box;
    };
    // Adaptive and surface volumes: refined by error, their adaptive.* settings read.
    const auto isAdaptive = [](const SceneDescription& s, size_t i) {
        return refinedByError(s.probeVolumes.at(i).placement);
    };
    const auto isOctree = [](const SceneDescription& s, size_t i) {
        return s.probeVolumes.at(i).placement == ProbePlacement::Adaptive;
    };
    const auto isSurface = [](const SceneDescription& s, size_t i) {
        return s.probeVolumes.at(i).placement == ProbePlacement::Surface;
    };
    // A terrain or box grid as the bake places it, for the values "auto" resolves to.
    const auto placedGrid = [=](const SceneDescription& s, const Heightfield& hf, size_t i) -> std::optional<ProbeLayout> {
        if (isAdaptive(s, i)) return std::nullopt;
        try {
            return *keptPlacement(s, i, hf);
        } catch (const std::exception&) {
            return std::nullopt;
        }
    };
    add(Row("probe_volumes[].name", T::String))
        .pattern("[A-Za-z0-9_-]{1,64}", "must be 1-64 letters, digits, '_' or '-' (it names the .shprobe file)")
        .label("Name").about("File stem of the volume's .shprobe; unique among volumes")
        .redoes(kNothing).noUiRow().volume(&ProbeVolumeSettings::name);
    add(Row("probe_volumes[].enabled", T::Boolean)).label("Enabled")
        .about("Baked, exported and drawn").redoes(kReplace | kRebake).volume(&ProbeVolumeSettings::enabled);
    add(Row("probe_volumes[].placement", T::Choice)).choices({"terrain", "box", "adaptive", "surface"}).label("Placement")
        .about("terrain: a grid following the ground; box: a 3-D grid of cells; adaptive: an octree, fine near the ground; surface: a quadtree following the ground, fine where the error is")
        .redoes(kReplace | kRebake).volume(&ProbeVolumeSettings::placement);
    add(Row("probe_volumes[].grid_dims", T::IntegerList)).items(2, 3).range(1, kMaxBoxGridProbes)
        .label("Grid (probes)")
        .about("terrain: [nx, nz] probes (product <= 4096); box: [nx, ny, nz] cells (product <= 65536); adaptive and surface volumes ignore it")
        .redoes(kReplace | kRebake)
        .count([=](const SceneDescription& s, size_t i) { return isAdaptive(s, i) ? -1 : isBox(s, i) ? 3 : 2; })
        .custom(
            [=](const SceneDescription& s, size_t i) {
                const ProbeVolumeSettings& v = s.probeVolumes.at(i);
                // Adaptive volumes keep the terrain default, so a document reads back as written.
                const auto& d = isAdaptive(s, i) ? ProbeVolumeSettings{}.gridDims : v.gridDims;
                return isBox(s, i) ? json{d[0], d[1], d[2]} : json{d[0], d[2]};
            },
            [=](SceneDescription& s, size_t i, const json& v) {
                if (isAdaptive(s, i)) return;
                std::array<int, 3> d{1, 1, 1};
                if (isBox(s, i)) {
                    d = {v[0].get<int>(), v[1].get<int>(), v[2].get<int>()};
                    checkProduct(d, kMaxBoxGridProbes);
                } else {
                    d = {v[0].get<int>(), 1, v[1].get<int>()};
                    checkProduct(d, kMaxTerrainGridProbes);
                }
                s.probeVolumes.at(i).gridDims = d;
            });
    add(Row("probe_volumes[].origin", T::NumberList)).items(2, 3).range(-1.0e7, 1.0e7).unit("m")
        .autoMeans("auto-span: the grid spans the terrain footprint (adaptive: its min corner at the lowest terrain)")
        .label("Origin")
        .about("terrain: (x, z) of the first probe; box and adaptive: (x, y, z) of the min corner; engine space; surface volumes cover the footprint and ignore it")
        .redoes(kReplace | kRebake)
        .count([=](const SceneDescription& s, size_t i) { return isSurface(s, i) ? -1 : isBox(s, i) || isAdaptive(s, i) ? 3 : 2; })
        .custom(
            [=](const SceneDescription& s, size_t i) {
                const auto& o = s.probeVolumes.at(i).origin;
                if (!o) return json(nullptr);
                return isBox(s, i) || isAdaptive(s, i) ? shortest(*o) : json{shortest(o->x), shortest(o->z)};
            },
            [=](SceneDescription& s, size_t i, const json& v) {
                auto& o = s.probeVolumes.at(i).origin;
                if (v.is_null()) { o.reset(); return; }
                o = v.size() == 3 ? glm::vec3(v[0].get<float>(), v[1].get<float>(), v[2].get<float>())
                                  : glm::vec3(v[0].get<float>(), 0.0f, v[1].get<float>());
            })
        .resolvedBy([=](const SceneDescription& s, const Heightfield& hf, size_t i) {
            const std::optional<ProbeLayout> L = placedGrid(s, hf, i);
            if (!L || L->positions.empty()) return json(nullptr);
            if (isBox(s, i)) return json{shortest(L->cellOrigin.x), shortest(L->cellOrigin.y), shortest(L->cellOrigin.z)};
            return json{shortest(L->positions[0].x), shortest(L->positions[0].z)};
        });
    add(Row("probe_volumes[].spacing", T::NumberList)).items(2, 2).scalarToo().above(0.0, 1.0e6).unit("m")
        .autoMeans("auto-span: the end probes sit on the terrain edges").label("Spacing")
        .about("terrain: [sx, sz] between probes; box: the cube edge, one number; adaptive and surface volumes ignore it")
        .redoes(kReplace | kRebake)
        .count([=](const SceneDescription& s, size_t i) { return isAdaptive(s, i) ? -1 : isBox(s, i) ? 0 : 2; })
        .custom(
            [=](const SceneDescription& s, size_t i) {
                const auto& sp = s.probeVolumes.at(i).spacing;
                if (!sp || isAdaptive(s, i)) return json(nullptr);
                return isBox(s, i) ? json(shortest(sp->x)) : json{shortest(sp->x), shortest(sp->z)};
            },
            [=](SceneDescription& s, size_t i, const json& v) {
                auto& sp = s.probeVolumes.at(i).spacing;
                if (v.is_null() || isAdaptive(s, i)) { sp.reset(); return; }
                if (v.is_number()) { sp = glm::vec3(v.get<float>()); return; }
                const float x = v[0].get<float>(), z = v[1].get<float>();
                sp = glm::vec3(x, std::min(x, z), z);
            })
        .resolvedBy([=](const SceneDescription& s, const Heightfield& hf, size_t i) {
            const std::optional<ProbeLayout> L = placedGrid(s, hf, i);
            if (!L) return json(nullptr);
            if (isBox(s, i)) return json(shortest(L->cellSize));
            return json{shortest(L->spacing.x), shortest(L->spacing.z)};
        });
    add(Row("probe_volumes[].height_offset", T::Number)).range(-1.0e4, 1.0e4).unit("m").label("Height offset")
        .about("terrain and surface placement: probes sit this far above the triangle surface the bake traces; 0 or less leaves them on or in it, unbaked (surface volumes refuse it)")
        .redoes(kReplace | kRebake).volume(&ProbeVolumeSettings::heightOffset)
        .onlyWhen([](const SceneDescription& s, size_t i) { return followsSurface(s.probeVolumes.at(i).placement); });
    add(Row("probe_volumes[].ray_count", T::Integer)).range(1, 1 << 20).autoMeans("preset: the bake quality preset decides")
        .label("Rays per probe").about("Rays traced per probe by the bake, the same for every probe of the volume").redoes(kRebake)
        .volume(&ProbeVolumeSettings::rayCount);
    add(Row("probe_volumes[].fallback_blend_distance", T::Number)).bakeUse(BakeUse::Ignores).range(0.0, 1.0e7).unit("m").decimals(1)
        .autoMeans("2 × spacing: twice the smallest probe spacing").label("Fallback blend")
        .about("Distance outside the grid over which engines blend the probes to their fallback (the sky)")
        .redoes(kUpload).volume(&ProbeVolumeSettings::fallbackBlendDistance)
        .resolvedBy([=](const SceneDescription& s, const Heightfield& hf, size_t i) {
            const std::optional<ProbeLayout> L = placedGrid(s, hf, i);
            return L ? json(shortest(L->fallbackBlendDistance)) : json(nullptr);
        });
    add(Row("probe_volumes[].adaptive.min_cell_size", T::Number)).above(0.0, 1.0e6).unit("m")
        .autoMeans("auto: the DEM's cell size, or when larger 1/128 of the box's longer horizontal side (surface: half the DEM cell, coarsened until the occupancy grid holds at most 4 Mi cells)").label("Adaptive: min cell")
        .about("Smallest octree cell (surface: quadtree square) and the .shprobe grid spacing").redoes(kReplace | kRebake)
        .adaptive(&AdaptiveVolumeSettings::minCellSize);
    add(Row("probe_volumes[].adaptive.max_cell_size", T::Number)).above(0.0, 1.0e7).unit("m")
        .autoMeans("16 × min: 16 × min_cell_size (surface: the largest min × 2^k within 1/8 of the footprint's longer side)").label("Adaptive: max cell")
        .about("Largest octree cell (surface: quadtree square); must be min_cell_size × 2^k, k in [0, 16]").redoes(kReplace | kRebake)
        .custom([](const SceneDescription& s, size_t i) {
                    const auto& m = s.probeVolumes.at(i).adaptive.maxCellSize;
                    return m ? json(*m) : json(nullptr);
                },
                [](SceneDescription& s, size_t i, const json& v) {
                    AdaptiveVolumeSettings& a = s.probeVolumes.at(i).adaptive;
                    if (v.is_null()) { a.maxCellSize.reset(); return; }
                    const double max = v.get<double>();
                    if (a.minCellSize) {
                        const double ratio = max / *a.minCellSize;
                        const double k = std::round(std::log2(ratio));
                        if (!(ratio >= 1.0) || k > kMaxOctreeLevels || std::abs(ratio - std::exp2(k)) > 1e-9 * ratio)
                            throw ParameterRejection{"must be min_cell_size (" + number(*a.minCellSize) +
                                                         ") times 2^k, k in [0, " + std::to_string(kMaxOctreeLevels) + "]",
                                                     ""};
                    }
                    a.maxCellSize = max;
                });
    add(Row("probe_volumes[].adaptive.height_range", T::Number)).range(0.0, 1.0e5).unit("m").decimals(1)
        .label("Adaptive: above terrain").about("Auto box: from the lowest terrain up to the highest plus this")
        .redoes(kReplace | kRebake).onlyWhen(isOctree).adaptive(&AdaptiveVolumeSettings::heightRange);
    add(Row("probe_volumes[].adaptive.size", T::NumberList)).items(3, 3).above(0.0, 1.0e7).unit("m")
        .autoMeans("the auto box over the terrain footprint").label("Adaptive: box size")
        .about("Explicit box edges (x, y, z) from the origin; grows to whole min cells")
        .redoes(kReplace | kRebake).onlyWhen(isOctree).adaptive(&AdaptiveVolumeSettings::size);
    add(Row("probe_volumes[].adaptive.surface_band", T::Number)).range(0.0, 1.0e6).unit("m")
        .autoMeans("one min cell").label("Adaptive: surface band")
        .about("A cell this close above the surface goes down to the minimum size").redoes(kReplace | kRebake)
        .onlyWhen(isOctree).adaptive(&AdaptiveVolumeSettings::surfaceBand);
    add(Row("probe_volumes[].adaptive.surface_cell_size", T::Number)).above(0.0, 1.0e7).unit("m")
        .autoMeans("min cell: the band is all minimum cells").label("Adaptive: surface cell")
        .about("The size the surface band forces cells down to; below it the error tolerance alone splits them. At least min_cell_size; the largest min_cell_size × 2^k at or below it applies (max_cell_size at most)")
        .redoes(kReplace | kRebake).onlyWhen(isOctree).adaptive(&AdaptiveVolumeSettings::surfaceCellSize);
    add(Row("probe_volumes[].adaptive.tolerance", T::Number)).above(0.0, 1.0).decimals(3)
        .autoMeans("none: geometric refinement only").label("Adaptive: error tolerance")
        .about("Relative interpolation error that splits a leaf (error-driven refinement); unset, a surface volume keeps its largest squares")
        .redoes(kReplace | kRebake).adaptive(&AdaptiveVolumeSettings::tolerance);
    add(Row("probe_volumes[].adaptive.max_probes", T::Integer)).range(1, kMaxVolumeProbes)
        .autoMeans("the limit of 65536").label("Adaptive: max probes")
        .about("Probe budget of the error-driven refinement; no adaptive volume holds more than 65536 valid probes")
        .redoes(kReplace | kRebake).adaptive(&AdaptiveVolumeSettings::maxProbes);
    add(Row("probe_volumes[].adaptive.max_bytes", T::Integer)).range(1, double(1ll << 53)).unit("bytes")
        .autoMeans("no limit").label("Adaptive: max bytes").about(".shprobe size budget of the error-driven refinement")
        .redoes(kReplace | kRebake).noUiRow().adaptive(&AdaptiveVolumeSettings::maxBytes);
    add(Row("probe_volumes[].target_error", T::Number)).above(0.0, 1.0).openAbove().decimals(3)
        .autoMeans("none: grid_dims or adaptive.tolerance stand").label("Target error")
        .about("Relative interpolation error to meet at the error map's 95th percentile: chooses grid_dims (terrain) or adaptive.tolerance (adaptive, surface), replacing them; box volumes refuse it")
        .redoes(kReplace | kRebake).volume(&ProbeVolumeSettings::targetError);
    add(Row("probe_volumes[].adaptive.max_move_share", T::Number)).range(0.0, 0.5).unit("of a cell")
        .label("Adaptive: max move")
        .about("A minimum leaf whose centre is inside the terrain moves its probe up at most this share of its edge")
        .redoes(kReplace | kRebake).onlyWhen(isOctree).adaptive(&AdaptiveVolumeSettings::maxMoveShare);

    // Reflection probes (docs/lighting.md, "Reflection probes"): the preview bakes them again on
    // every edit but strength's, which the renderer applies live.
    const auto reflectionOn = [](const SceneDescription& s, size_t) { return s.reflectionProbes.enabled; };
    add(Row("reflection_probes.enabled", T::Boolean)).label("Reflection probes")
        .about("Bake terrain-local reflection probes, draw them in place of the sky's specular and export them")
        .redoes(kRebake | kUpload).field(&SceneDescription::reflectionProbes, &ReflectionProbeSettings::enabled);
    add(Row("reflection_probes.grid_dims", T::IntegerList)).items(2, 2).range(1, kMaxReflectionProbes)
        .label("Grid").about("[nx, nz] probes, product <= 256; scene order is row-major, x fastest")
        .redoes(kRebake).onlyWhen(reflectionOn)
        .custom([](const SceneDescription& s, size_t) {
                    return json{s.reflectionProbes.gridDims[0], s.reflectionProbes.gridDims[1]};
                },
                [](SceneDescription& s, size_t, const json& v) {
                    checkProduct({v[0].get<int>(), v[1].get<int>(), 1}, kMaxReflectionProbes);
                    s.reflectionProbes.gridDims = {v[0].get<int>(), v[1].get<int>()};
                });
    // What auto-span resolves a reflection grid's (x, z) pair to: that member of its placement.
    const auto resolvedReflection = [](glm::vec2 ReflectionLayout::*member) {
        return [member](const SceneDescription& s, const Heightfield& hf, size_t) {
            try {
                const glm::vec2 v = placeReflectionProbes(s.reflectionProbes, hf).*member;
                return json{shortest(v.x), shortest(v.y)};
            } catch (const std::exception&) {
                return json(nullptr);
            }
        };
    };
    add(Row("reflection_probes.origin", T::NumberList)).items(2, 2).range(-1.0e7, 1.0e7).unit("m")
        .autoMeans("auto-span: the grid spans the terrain footprint").label("Origin")
        .about("(x, z) of the first probe, engine space").redoes(kRebake).onlyWhen(reflectionOn)
        .custom([](const SceneDescription& s, size_t) {
                    const auto& o = s.reflectionProbes.origin;
                    return o ? json{shortest(o->x), shortest(o->y)} : json(nullptr);
                },
                [](SceneDescription& s, size_t, const json& v) {
                    auto& o = s.reflectionProbes.origin;
                    if (v.is_null()) o.reset();
                    else o = glm::vec2(v[0].get<float>(), v[1].get<float>());
                })
        .resolvedBy(resolvedReflection(&ReflectionLayout::origin));
    add(Row("reflection_probes.spacing", T::NumberList)).items(2, 2).above(0.0, 1.0e6).unit("m")
        .autoMeans("auto-span: the end probes sit on the terrain edges").label("Spacing")
        .about("[sx, sz] between probes").redoes(kRebake).onlyWhen(reflectionOn)
        .custom([](const SceneDescription& s, size_t) {
                    const auto& sp = s.reflectionProbes.spacing;
                    return sp ? json{shortest(sp->x), shortest(sp->y)} : json(nullptr);
                },
                [](SceneDescription& s, size_t, const json& v) {
                    auto& sp = s.reflectionProbes.spacing;
                    if (v.is_null()) sp.reset();
                    else sp = glm::vec2(v[0].get<float>(), v[1].get<float>());
                })
        .resolvedBy(resolvedReflection(&ReflectionLayout::spacing));
    add(Row("reflection_probes.height_offset", T::Number)).range(-1.0e4, 1.0e4).unit("m")
        .label("Height offset").about("Probes sit this far above the traced terrain surface").redoes(kRebake).onlyWhen(reflectionOn)
        .field(&SceneDescription::reflectionProbes, &ReflectionProbeSettings::heightOffset);
    add(Row("reflection_probes.ray_count", T::Integer)).range(1, 1 << 20).label("Rays per texel")
        .about("Rays traced per cube texel (the reference comparison traces 16× as many)").redoes(kRebake).onlyWhen(reflectionOn)
        .field(&SceneDescription::reflectionProbes, &ReflectionProbeSettings::rayCount);
    add(Row("reflection_probes.encoding", T::Choice))
        .choices({reflectionEncodingName(ReflectionEncoding::Faces), reflectionEncodingName(ReflectionEncoding::Cubemap)}).label("Encoding")
        .about("faces: six face colours per probe; cubemap: a GGX-prefiltered cube map per probe")
        .redoes(kRebake).onlyWhen(reflectionOn).field(&SceneDescription::reflectionProbes, &ReflectionProbeSettings::encoding);
    add(Row("reflection_probes.resolution", T::Integer)).range(8, 128).unit("texels")
        .label("Cube size").about("Texels a side of each cube face at mip 0: a power of two")
        .redoes(kRebake).onlyWhen(reflectionOn)
        .custom([](const SceneDescription& s, size_t) { return json(s.reflectionProbes.resolution); },
                [](SceneDescription& s, size_t, const json& v) {
                    const int r = v.get<int>();
                    if (!std::has_single_bit(unsigned(r))) throw ParameterRejection{"must be a power of two", ""};
                    s.reflectionProbes.resolution = r;
                });
    add(Row("reflection_probes.ground_color", T::Color)).range(0.0, 1.0).label("Ground albedo")
        .about("Albedo of the ground a probe sees below its horizon where no terrain is traced (past the footprint with the skirt off)")
        .redoes(kRebake).onlyWhen(reflectionOn).field(&SceneDescription::reflectionProbes, &ReflectionProbeSettings::groundColor);
    add(Row("reflection_probes.strength", T::Number)).range(0.0, 1.0).label("Strength").slider()
        .about("How far the probes replace the sky's specular where they cover (0: the sky alone)")
        .redoes(kUpload).onlyWhen(reflectionOn).field(&SceneDescription::reflectionProbes, &ReflectionProbeSettings::strength);
    add(Row("reflection_probes.fallback_blend_distance", T::Number)).range(0.0, 1.0e7).unit("m").decimals(1)
        .autoMeans("2 × spacing: twice the smaller probe spacing").label("Fallback blend")
        .about("Distance outside the grid over which the probes blend to the sky's specular; the box records' blend distance")
        .redoes(kRebake).onlyWhen(reflectionOn).field(&SceneDescription::reflectionProbes, &ReflectionProbeSettings::fallbackBlendDistance)
        .resolvedBy([](const SceneDescription& s, const Heightfield& hf, size_t) {
            try {
                return json(shortest(placeReflectionProbes(s.reflectionProbes, hf).blendDistance));
            } catch (const std::exception&) {
                return json(nullptr);
            }
        });
    add(Row("reflection_probes.simvx_subset", T::IntegerList)).items(0, kSimvxMaxProbes).range(0, kMaxReflectionProbes - 1)
        .label("simvx probes")
        .about("Indices (scene order) of the at most 8 probes the simvx box records carry; empty: the first 8. In the window: the probe inspector's check box")
        .redoes(kNothing).noUiRow().onlyWhen(reflectionOn)
        .custom([](const SceneDescription& s, size_t) { return json(s.reflectionProbes.simvxSubset); },
                [](SceneDescription& s, size_t, const json& v) {
                    std::vector<int> idx = v.get<std::vector<int>>();
                    std::vector<int> sorted = idx;
                    std::sort(sorted.begin(), sorted.end());
                    if (const auto d = std::adjacent_find(sorted.begin(), sorted.end()); d != sorted.end())
                        throw ParameterRejection{"each probe at most once (" + std::to_string(*d) + " appears twice)", ""};
                    s.reflectionProbes.simvxSubset = idx;
                });

    bake = BakeUse::Ignores;  // the viewport computes the LPV live; lpv.ini and the glTF export it
    // Indirect light and light propagation volumes (docs/lighting.md, "Light propagation
    // volumes"). Each lpv row is one console variable of seed 003 (lpv.ini); the LPV dock edits
    // them, its lights table the lights.
    add(Row("lighting.indirect", T::Choice)).choices({"probes", "lpv", "both", "none"}).label("Indirect light")
        .about("Which indirect light the engine, the viewport and --render add to the direct sun and sky: the baked probes (diffuse and reflection), the light propagation volumes (with lpv.enabled), both summed, or none; exported in TERRALUX_lighting")
        .redoes(kUpload).field(&SceneDescription::lighting, &LightingSettings::indirect);
    const auto lpvOn = [](const SceneDescription& s, size_t) { return s.lpv.enabled; };
    add(Row("lpv.enabled", T::Boolean)).label("Light propagation volumes")
        .about("rEx.GI.Method: 1 with LPV on, else 0. On: the bake writes lpv.ini and TERRALUX_lighting.lpv, and the viewport draws the LPV when lighting.indirect is lpv or both")
        .redoes(kUpload).field(&SceneDescription::lpv, &LpvSettings::enabled);
    add(Row("lpv.size", T::Number)).above(0.0, 1.0e6).unit("m").decimals(0)
        .autoMeans("terrain side: cascade 0 spans the terrain's longer side (at least 32 DEM cells, at most 1e6 m), so it can hold the whole footprint")
        .label("LPV size")
        .about("rEx.LPV.Size: edge of the largest cascade (cascade 0), 32 cells across; lpv.ini and the glTF carry the metres")
        .resolvedBy([](const SceneDescription& s, const Heightfield& hf, size_t) {
            return json(*lpv::resolvedOn(s.lpv, hf).size);
        })
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::size);
    add(Row("lpv.fade_range", T::Number)).range(0.0, 16.0).unit("cells").decimals(1).label("Fade range")
        .about("rEx.LPV.FadeRange: cells at each cascade's boundary over which it fades out (to the next coarser cascade, or to nothing)")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::fadeRange);
    add(Row("lpv.propagation_weight", T::Number)).range(0.0, 1.0).decimals(3).label("Propagation weight")
        .about("rEx.LPV.PropagationWeight: per-neighbour propagation strength, compounded over a cascade's 32 cells: each iteration passes on w^(1/32) of the paper's face transfer, so w is the share left after crossing the cascade (1 = energy-conserving, 0.01 = 0.866 per iteration); higher spreads light faster and leaks more")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::propagationWeight);
    add(Row("lpv.propagation_iterations", T::Integer)).range(0, 64).label("Propagation iterations")
        .about("rEx.LPV.PropagationIterations: propagation steps per update, each accumulated; 0 = injected light only")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::propagationIterations);
    add(Row("lpv.update_interval", T::Integer)).range(0, 600).unit("frames").label("Update interval")
        .about("rEx.LPV.UpdateInterval: frames without an update between two full updates (0 = every frame); the viewport counts its own frames, and updates only after a camera or settings change")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::updateInterval);
    add(Row("lpv.cascades", T::Integer)).range(1, 4).label("Cascades")
        .about("rEx.LPV.NumCascades: nested 32^3 volumes, each smaller than the last by the cascade ratio")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::cascades);
    add(Row("lpv.cascade_ratio", T::Number)).above(1.0, 16.0).decimals(2).label("Cascade ratio")
        .about("rEx.LPV.CascadeRatio: size of a cascade / size of the next finer one (the least ratio when auto_cascade_min_size is on)")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::cascadeRatio);
    add(Row("lpv.auto_cascade_min_size", T::Number)).range(0.0, 1.0e6).unit("m").decimals(0).zeroMeans("off")
        .label("Auto min cascade")
        .about("rEx.LPV.AutoCascadeMinSize: > 0 raises the ratio to max(cascade_ratio, (size / this)^(1/(cascades - 1))), so the smallest cascade is at most this size; 0 = off")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::autoCascadeMinSize);
    add(Row("lpv.cascade_forward_offset", T::Number)).range(0.0, 1.0).decimals(2).label("Forward offset")
        .about("rEx.LPV.CascadeForwardOffset: each cascade's centre sits this share of its size ahead of the camera along the view direction (0 = centred on the camera, 0.5 = the camera on its back face); the viewport places them for a viewer at its orbit target")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::cascadeForwardOffset);
    add(Row("lpv.local_lights", T::Boolean)).label("Local lights")
        .about("rEx.LPV.EnableLocalLights: inject the point and spot lights of `lights` (each into its best-fitting cascade); off: the sun only")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::localLights);
    add(Row("lpv.quality", T::Integer)).range(0, 2).label("LPV quality")
        .about("rEx.LPV.Quality: 0 linear SH diffuse; 1 adds ZH3 reconstruction and directional-derivative leak dampening; 2 adds cone-traced specular")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::quality);
    add(Row("lpv.cone_trace_samples", T::Integer)).range(1, 64).label("Cone-trace samples")
        .about("rEx.LPV.ConeTraceSamples: samples along the reflected direction of quality 2's specular (4 short range, 6 balanced, 8 long)")
        .redoes(kUpload)
        .onlyWhen([](const SceneDescription& s, size_t) { return s.lpv.enabled && s.lpv.quality == 2; })
        .field(&SceneDescription::lpv, &LpvSettings::coneTraceSamples);
    add(Row("lpv.indirect_intensity", T::Number)).range(0.0, 100.0).decimals(2).label("Indirect intensity")
        .about("The post-process IndirectLightingIntensity: multiplies the LPV's light (not a console variable: in TERRALUX_lighting, and as a comment in lpv.ini)")
        .redoes(kUpload).onlyWhen(lpvOn).field(&SceneDescription::lpv, &LpvSettings::indirectIntensity);
    // Local lights: a list of objects, read by the LPV only (never by the diffuse bake).
    const auto spot = [](const SceneDescription& s, size_t i) { return s.lights.at(i).type == LocalLightType::Spot; };
    add(Row("lights[].type", T::Choice)).choices({"point", "spot"}).label("Light type")
        .about("point: the same intensity every way; spot: a cone along direction (KHR_lights_punctual's model)")
        .redoes(kUpload).light(&LocalLight::type);
    add(Row("lights[].position", T::NumberList)).items(3, 3).range(-1.0e7, 1.0e7).unit("m").label("Position")
        .about("Engine space (x east, y up, z south)").redoes(kUpload).light(&LocalLight::position);
    add(Row("lights[].direction", T::NumberList)).items(3, 3).range(-1.0, 1.0).decimals(3).label("Direction")
        .about("Spot: where the cone points, engine space; normalised, must not be zero")
        .redoes(kUpload).onlyWhen(spot)
        .custom([](const SceneDescription& s, size_t i) { return fieldToJson(s.lights.at(i).direction, {}); },
                [](SceneDescription& s, size_t i, const json& v) {
                    const glm::vec3 d = fieldFromJson<glm::vec3>(v, {});
                    if (!(d.x * d.x + d.y * d.y + d.z * d.z > 1e-12f))
                        throw ParameterRejection{"must not be the zero vector", ""};
                    s.lights.at(i).direction = d;
                });
    add(Row("lights[].color", T::Color)).range(0.0, 1.0).label("Light colour")
        .about("Linear RGB tint of the intensity").redoes(kUpload).light(&LocalLight::color);
    add(Row("lights[].intensity", T::Number)).range(0.0, 1.0e17).unit("cd").label("Intensity")
        .about("Luminous intensity: the illuminance in lux on a surface facing the light 1 m away (E = intensity / d^2 inside the range), as the sun's illuminance is in lux; exported as it is (KHR_lights_punctual's candela)")
        .redoes(kUpload).light(&LocalLight::intensity);
    add(Row("lights[].range", T::Number)).above(0.0, 1.0e6).unit("m").label("Range")
        .about("Distance where the light ends: its falloff is windowed by clamp(1 - (d/range)^4, 0, 1) (KHR_lights_punctual)")
        .redoes(kUpload).light(&LocalLight::range);
    add(Row("lights[].inner_cone_deg", T::Number)).range(0.0, 90.0).openAbove().unit("°").decimals(1).label("Inner cone")
        .about("Spot: angle from the axis inside which the light is at full intensity")
        .redoes(kUpload).onlyWhen(spot).light(&LocalLight::innerConeDeg);
    add(Row("lights[].outer_cone_deg", T::Number)).above(0.0, 90.0).unit("°").decimals(1).label("Outer cone")
        .about("Spot: angle from the axis where the light has faded to nothing; above inner_cone_deg")
        .redoes(kUpload).onlyWhen(spot)
        .custom([](const SceneDescription& s, size_t i) { return json(s.lights.at(i).outerConeDeg); },
                [](SceneDescription& s, size_t i, const json& v) {
                    // Read after inner_cone_deg (table order), so the pair is checked here.
                    LocalLight& l = s.lights.at(i);
                    l.outerConeDeg = v.get<double>();
                    if (l.type == LocalLightType::Spot && !(l.outerConeDeg > l.innerConeDeg))
                        throw ParameterRejection{"must be above inner_cone_deg (" + number(l.innerConeDeg) + ")", ""};
                });

    bake = BakeUse::Reads;
    // Bake.
    add(Row("bake.quality", T::Choice)).choices({"draft", "standard", "high", "reference"}).label("Quality")
        .about("Preset of each probe's standard error (draft 2 %, standard 0.4 %, high 0.2 %: each probe traces the rays it needs for it, within the preset's range), bounces and irradiance cache; rays and bounces below override it")
        .redoes(kNothing).field(&SceneDescription::bake, &BakeSettings::quality);
    add(Row("bake.rays", T::Integer)).range(1, 1 << 20).autoMeans("preset: each probe traces what the preset's standard error asks").label("Rays per probe")
        .about("Rays traced per probe, the same for every probe").redoes(kNothing).field(&SceneDescription::bake, &BakeSettings::rays);
    add(Row("bake.bounces", T::Integer)).range(0, kMaxBounces).autoMeans("preset: the quality preset decides").label("Bounces")
        .about("Light bounces off the terrain; 0 = sky visibility only").redoes(kNothing)
        .field(&SceneDescription::bake, &BakeSettings::bounces);
    add(Row("bake.target_error", T::Number)).above(0.0, 1.0).openAbove().decimals(3)
        .autoMeans("none: rays and bounces (or the preset) stand").label("Target bake error")
        .about("Relative error to aim at: rays from the probes' Monte Carlo standard error, bounces until the next one changes irradiance by less; replaces rays and bounces")
        .redoes(kNothing).field(&SceneDescription::bake, &BakeSettings::targetError);
    add(Row("bake.sh_encoding", T::Choice)).choices({"radiance", "irradiance"}).label("SH encoding")
        .about("radiance: SH projection of what the probe sees; irradiance: pre-convolved with the cosine lobe")
        .redoes(kRebake).field(&SceneDescription::bake, &BakeSettings::encoding);
    add(Row("bake.deringing", T::Boolean)).label("Deringing")
        .about("Window each probe's SH just enough that its irradiance is nowhere negative")
        .redoes(kRebake).field(&SceneDescription::bake, &BakeSettings::deringing);
    add(Row("bake.error_map_resolution", T::Integer)).range(0, kMaxErrorMapResolution).unit("points").zeroMeans("no map")
        .label("Error map points a side")
        .about("Points along the longer side of each volume's interpolation-error map (debug view interpolation-error); 0 = no map; each costs one probe bake")
        .redoes(kRebake).field(&SceneDescription::bake, &BakeSettings::errorMapResolution);

    bake = BakeUse::Ignores;
    // Camera (edited by the viewport, stored in the project).
    add(Row("camera.target", T::NumberList)).items(3, 3).range(-1.0e7, 1.0e7).unit("m")
        .autoMeans("the footprint centre at the mean terrain height").label("Camera target")
        .about("Point the orbit camera looks at, engine space").redoes(kRedraw).noUiRow()
        .field(&SceneDescription::camera, &CameraSettings::target);
    add(Row("camera.radius", T::Number)).above(0.0, 1.0e8).unit("m").autoMeans("frames the whole footprint")
        .label("Camera distance").about("Distance from the target").redoes(kRedraw).noUiRow()
        .field(&SceneDescription::camera, &CameraSettings::radius);
    add(Row("camera.azimuth_deg", T::Number)).range(-360.0, 360.0).unit("°").label("Camera azimuth")
        .about("Where the camera stands, clockwise from north").redoes(kRedraw).noUiRow()
        .field(&SceneDescription::camera, &CameraSettings::azimuthDeg);
    add(Row("camera.elevation_deg", T::Number)).range(-89.9, 89.9).unit("°").label("Camera elevation")
        .about("Angle of the camera above the target's horizon").redoes(kRedraw).noUiRow()
        .field(&SceneDescription::camera, &CameraSettings::elevationDeg);
    add(Row("camera.fov_deg", T::Number)).range(1.0, 150.0).unit("°").label("Field of view")
        .about("Vertical field of view").redoes(kRedraw).noUiRow()
        .field(&SceneDescription::camera, &CameraSettings::fovDeg);

    const auto metered = [](const SceneDescription& s, size_t) { return s.camera.exposureMode != ExposureMode::Manual; };
    add(Row("camera.exposure_mode", T::Choice))
        .choices({exposureModeName(ExposureMode::Manual), exposureModeName(ExposureMode::Average),
                  exposureModeName(ExposureMode::Histogram)})
        .label("Exposure mode")
        .about("manual: the camera at camera.ev100; average: metered on the geometric mean luminance of the frame; "
               "histogram: metered on the frame's 10th to 90th percentiles of luminance (deep shadow and glints ignored)")
        .redoes(kUpload).field(&SceneDescription::camera, &CameraSettings::exposureMode);
    add(Row("camera.ev100", T::Number)).range(-6.0, 24.0).unit("EV100").decimals(2).label("EV100")
        .about("Manual exposure at ISO 100: a luminance of 1.2 x 2^EV100 cd/m2 displays as white before the tone curve; "
               "15 is a clear day (sunny 16), the default 14.76 the exposure the defaults were set for")
        .redoes(kUpload).onlyWhen(std::not_fn(metered)).field(&SceneDescription::camera, &CameraSettings::ev100);
    add(Row("camera.exposure_ev", T::Number)).range(-16.0, 16.0).unit("EV").decimals(1).slider().label("Exposure")
        .about("Exposure compensation in stops before the ACES tone curve, in every mode: +1 doubles the displayed light")
        .redoes(kUpload).field(&SceneDescription::camera, &CameraSettings::exposureEv);
    add(Row("camera.adaptation_s", T::Number)).range(0.0, 60.0).unit("s").decimals(2).label("Adaptation")
        .about("Metered modes, in the viewport: the time constant with which the exposure follows the meter (0: at once); "
               "renders and exports use the metered exposure itself")
        .redoes(kUpload).onlyWhen(metered).field(&SceneDescription::camera, &CameraSettings::adaptationSeconds);
    add(Row("camera.antialiasing", T::Choice))
        .choices({antialiasingName(Antialiasing::Off), antialiasingName(Antialiasing::Fxaa), antialiasingName(Antialiasing::Ssaa),
                  antialiasingName(Antialiasing::Msaa2), antialiasingName(Antialiasing::Msaa4),
                  antialiasingName(Antialiasing::Msaa8)})
        .label("Anti-aliasing")
        .about("Edges of the picture views: fxaa filters the finished frame along luminance edges (one full-screen pass); "
               "ssaa draws at 2x2 the pixels and averages them (4x the cost); msaa2/4/8 take 2, 4 or 8 coverage samples a "
               "pixel and shade once (the most the device offers up to that; fxaa where it offers none); off: one sample "
               "a pixel. Data views stay exact")
        .redoes(kUpload).field(&SceneDescription::camera, &CameraSettings::antialiasing);

    // Export.
    bake = BakeUse::Reads;  // the exporters' settings; where the files go is not an input
    add(Row("export.out_dir", T::String)).bakeUse(BakeUse::Ignores).pattern(".+", "must name a folder").label("Output folder")
        .about("Where bakes are written; relative to the project file").redoes(kNothing)
        .field(&SceneDescription::exportSettings, &ExportSettings::outDir);
    add(Row("export.gltf", T::Boolean)).label("glTF scene").about("Write scene.gltf with the probe-grid extension")
        .redoes(kNothing).field(&SceneDescription::exportSettings, &ExportSettings::gltf);
    add(Row("export.default_scale", T::Number)).range(-100.0, 100.0).decimals(3).label("SH scale")
        .about("Default SH scale written into each .shprobe; engines multiply the probes by it")
        .redoes(kUpload).field(&SceneDescription::exportSettings, &ExportSettings::defaultScale);
    add(Row("export.default_ambient", T::Number)).range(0.0, 100.0).decimals(3).label("Ambient term")
        .about("Default ambient term written into each .shprobe").redoes(kNothing)
        .field(&SceneDescription::exportSettings, &ExportSettings::defaultAmbient);

    // The console variables in the lpv rows' order (lpv.indirect_intensity is none): the lpv.ini
    // writer's names, so tooltips and lpv.ini cannot drift apart.
    LpvSettings named;
    named.size = 1.0;  // any resolved size: only the names are read
    const auto cvars = lpvConsoleVariables(named);
    size_t cvar = 0;
    for (Row& r : rows)
        if (r.s_.path.rfind("lpv.", 0) == 0 && r.s_.path != "lpv.indirect_intensity" && cvar < cvars.size())
            r.s_.consoleVariable = cvars[cvar++].first;

    // Lighting scenarios: a name, and every sun and sky row again, bound to the scenario's own sun
    // and sky, so a scenario's values meet the same rules as the project's.
    bake = BakeUse::Reads;
    add(Row("scenarios[].name", T::String))
        .pattern("[A-Za-z0-9_-]{1,64}", "must be 1-64 letters, digits, '_' or '-' (it names the scenario's .shprobe files)")
        .label("Scenario").about("Names the scenario's .shprobe files (scenarios/<volume>.<scenario>.shprobe); unique, and not \"default\" (the project's own sun and sky)")
        .redoes(kUpload).noUiRow()
        .custom([](const SceneDescription& s, size_t i) { return json(s.scenarios.at(i).name); },
                [](SceneDescription& s, size_t i, const json& v) { s.scenarios.at(i).name = v.get<std::string>(); });
    const auto lit = [](const SceneDescription& s, size_t i) {
        SceneDescription t;
        t.sun = s.scenarios.at(i).sun;
        t.sky = s.scenarios.at(i).sky;
        return t;
    };
    const size_t lightingRows = rows.size();
    for (size_t r = 0; r < lightingRows; ++r) {
        const ParameterSpec& original = rows[r].s_;
        if (original.path.rfind("sun.", 0) != 0 && original.path.rfind("sky.", 0) != 0) continue;
        ParameterSpec c = original;
        c.path = "scenarios[]." + original.path;
        c.get = [lit, g = original.get](const SceneDescription& s, size_t i) { return g(lit(s, i), 0); };
        c.set = [lit, set = original.set](SceneDescription& s, size_t i, const json& v) {
            SceneDescription t = lit(s, i);
            set(t, 0, v);
            s.scenarios.at(i).sun = t.sun;
            s.scenarios.at(i).sky = t.sky;
        };
        if (original.items)
            c.items = [lit, f = original.items](const SceneDescription& s, size_t i) { return f(lit(s, i), 0); };
        if (original.readWhen)
            c.readWhen = [lit, f = original.readWhen](const SceneDescription& s, size_t i) { return f(lit(s, i), 0); };
        if (original.resolved)
            c.resolved = [lit, f = original.resolved](const SceneDescription& s, const Heightfield& hf, size_t i) {
                return f(lit(s, i), hf, 0);
            };
        Row copy("", T::Number);
        copy.s_ = std::move(c);
        rows.push_back(std::move(copy));
    }

    std::vector<ParameterSpec> table;
    table.reserve(rows.size());
    for (Row& r : rows) {
        // The adaptive section is read by adaptive and surface volumes only (placeAdaptive).
        if (r.s_.path.rfind("probe_volumes[].adaptive.", 0) == 0 && !r.s_.readWhen) r.onlyWhen(isAdaptive);
        table.push_back(std::move(r.s_));
    }
    return table;
}

}  // namespace

double shortestDecimal(float f) {
    char buf[32];
    const auto end = std::to_chars(buf, buf + sizeof buf, f).ptr;
    return std::strtod(std::string(buf, end).c_str(), nullptr);
}

const std::vector<std::string>& objectLists() {
    static const std::vector<std::string> lists{"probe_volumes", "water.waves", "lights", "scenarios"};
    return lists;
}

std::string ParameterSpec::listPath() const {
    for (const std::string& list : objectLists())
        if (path.rfind(list + "[].", 0) == 0) return list;
    return "";
}

std::string ParameterSpec::localPath() const {
    const std::string list = listPath();
    return list.empty() ? path : path.substr(list.size() + 3);
}

bool ParameterSpec::isRead(const SceneDescription& scene, size_t volume) const {
    if (items && items(scene, volume) < 0) return false;
    return !readWhen || readWhen(scene, volume);
}

json ParameterSpec::defaultValue() const {
    SceneDescription scene;  // holds one default probe volume
    if (perWave()) scene.water.waves.emplace_back();
    if (perLight()) scene.lights.emplace_back();
    if (perScenario()) scene.scenarios.emplace_back();
    return get(scene, 0);
}

std::string ParameterSpec::rangeText() const {
    if (type == ParamType::Choice) {
        std::string list;
        for (const auto& c : choices) list += (list.empty() ? "" : " | ") + c;
        return "one of " + list;
    }
    if (std::isinf(max)) return std::string(minExclusive ? "> " : ">= ") + number(min);
    return std::string(minExclusive ? "(" : "[") + number(min) + ", " + number(max) + (maxExclusive ? ")" : "]");
}

const std::vector<ParameterSpec>& parameterTable() {
    static const std::vector<ParameterSpec> table = buildTable();
    return table;
}

std::string normaliseParameterPath(const std::string& path) {
    std::string out;
    for (size_t i = 0; i < path.size(); ++i) {
        out += path[i];
        if (path[i] == '[') {
            const size_t close = path.find(']', i);
            if (close == std::string::npos) return path;
            i = close;
            out += ']';
        }
    }
    return out;
}

const ParameterSpec* findParameter(const std::string& path) {
    const std::string key = normaliseParameterPath(path);
    for (const auto& p : parameterTable())
        if (p.path == key) return &p;
    return nullptr;
}

unsigned invalidatedBy(const std::string& path) {
    if (path.empty()) return kUpload | kRebake | kReplace | kReimport;
    if (const ParameterSpec* spec = findParameter(path)) return spec->invalidates;
    std::string key = normaliseParameterPath(path);
    // A whole list ("water.waves") is the rows of its elements ("water.waves[].").
    if (std::find(objectLists().begin(), objectLists().end(), key) != objectLists().end()) key += "[]";
    unsigned flags = 0;
    for (const auto& p : parameterTable())
        if (p.path.rfind(key + ".", 0) == 0) flags |= p.invalidates;
    return flags & ~kNothing;
}

std::string editLabel(const std::string& path, const nlohmann::json& doc) {
    // The element a path is inside ("probe_volumes[2]" -> volume 'name'), and the section's words.
    static const std::pair<const char*, const char*> kSections[] = {
        {"terrain", "terrain"}, {"sun", "sun"}, {"sky", "sky"}, {"probe_volumes", "probe volumes"},
        {"reflection_probes", "reflection probes"}, {"bake", "bake"}, {"camera", "camera"},
        {"export", "export"}, {"shadows", "shadows"}, {"fog", "fog"}, {"detail", "detail"},
        {"ao", "ambient occlusion"}, {"water", "water"}, {"lpv", "LPV"}, {"lighting", "lighting"},
        {"lights", "lights"}, {"scenarios", "scenarios"}};
    std::string element;
    for (const std::string& list : objectLists()) {
        if (path.rfind(list + "[", 0) != 0) continue;
        const size_t close = path.find(']', list.size());
        if (close == std::string::npos) break;
        const std::string digits = path.substr(list.size() + 1, close - list.size() - 1);
        size_t i = 0;
        try {
            i = size_t(std::stoul(digits));
        } catch (const std::exception&) {
            break;
        }
        if (list == "probe_volumes") {
            const nlohmann::json* v = nullptr;
            if (doc.contains("probe_volumes") && doc["probe_volumes"].is_array() && i < doc["probe_volumes"].size())
                v = &doc["probe_volumes"][i];
            element = v && v->is_object() && v->contains("name") && (*v)["name"].is_string()
                          ? "volume '" + (*v)["name"].get<std::string>() + "'"
                          : "volume " + std::to_string(i + 1);
        } else if (list == "scenarios") {
            const nlohmann::json* v = nullptr;
            if (doc.contains("scenarios") && doc["scenarios"].is_array() && i < doc["scenarios"].size())
                v = &doc["scenarios"][i];
            element = v && v->is_object() && v->contains("name") && (*v)["name"].is_string()
                          ? "scenario '" + (*v)["name"].get<std::string>() + "'"
                          : "scenario " + std::to_string(i + 1);
        } else {
            element = (list == "lights" ? "light " : "wave ") + std::to_string(i + 1);
        }
        if (close + 1 == path.size()) return element;
        break;
    }
    if (const ParameterSpec* spec = findParameter(path); spec && !spec->label.empty()) {
        if (!element.empty()) return spec->label + " of " + element;
        const std::string section = path.substr(0, path.find('.'));
        std::string lower = spec->label;
        for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
        for (const auto& [key, words] : kSections)
            if (section == key && path != section)
                // "Sun elevation" says its section already; "Density" does not.
                return lower.find(words) != std::string::npos ? spec->label : spec->label + " (" + words + ")";
        return spec->label;
    }
    for (const auto& [key, words] : kSections)
        if (path == key) return std::string(key == std::string("sun") ? "the " : "") + words;
    return path;
}

bool isParameterSection(const std::string& path) {
    const std::string key = normaliseParameterPath(path) + ".";
    for (const auto& p : parameterTable())
        if (p.path.rfind(key, 0) == 0) return true;
    return false;
}

}  // namespace terralux

namespace terralux {

namespace {

std::string typeName(const ParameterSpec& s) {
    switch (s.type) {
        case ParamType::Number: return "number";
        case ParamType::Integer: return "integer";
        case ParamType::Boolean: return "boolean";
        case ParamType::String: return "string";
        case ParamType::Choice: return "choice";
        case ParamType::Color: return "RGB";
        case ParamType::NumberList:
        case ParamType::IntegerList: {
            const std::string what = s.type == ParamType::NumberList ? " numbers" : " integers";
            return s.minItems == s.maxItems ? std::to_string(s.minItems) + what
                   : s.maxItems == s.minItems + 1
                       ? std::to_string(s.minItems) + " or " + std::to_string(s.maxItems) + what
                       : std::to_string(s.minItems) + " to " + std::to_string(s.maxItems) + what;
        }
    }
    return "";
}

void bounds(json& out, const ParameterSpec& s) {
    if (!std::isinf(s.min)) out[s.minExclusive ? "exclusiveMinimum" : "minimum"] = s.min;
    if (!std::isinf(s.max)) out[s.maxExclusive ? "exclusiveMaximum" : "maximum"] = s.max;
}

json leafSchema(const ParameterSpec& s) {
    json out;
    switch (s.type) {
        case ParamType::Number:
        case ParamType::Integer:
            out["type"] = s.type == ParamType::Integer ? "integer" : "number";
            bounds(out, s);
            break;
        case ParamType::Boolean: out["type"] = "boolean"; break;
        case ParamType::String:
            out["type"] = "string";
            if (!s.pattern.empty()) out["pattern"] = "^(" + s.pattern + ")$";
            break;
        case ParamType::Choice: out["enum"] = s.choices; break;
        case ParamType::Color:
        case ParamType::NumberList:
        case ParamType::IntegerList: {
            json item = {{"type", s.type == ParamType::IntegerList ? "integer" : "number"}};
            bounds(item, s);
            out = {{"type", "array"}, {"items", item}, {"minItems", s.minItems}, {"maxItems", s.maxItems}};
            if (s.scalarAllowed) out = {{"anyOf", json::array({item, out})}};
            break;
        }
    }
    if (s.nullable()) out = {{"anyOf", json::array({out, {{"type", "null"}}})}};
    std::string d = s.description;
    if (!s.unit.empty()) d += " [" + s.unit + "]";
    if (s.nullable()) d += ". null: " + *s.autoMeaning;
    out["title"] = s.label;
    out["description"] = d;
    out["default"] = s.defaultValue();
    return out;
}

json objectSchema() {
    return {{"type", "object"}, {"additionalProperties", false}, {"properties", json::object()}};
}

// Inserts `leaf` at the dotted `path` of an object schema, making sections on the way.
void insert(json& schema, const std::string& path, json leaf) {
    const size_t dot = path.find('.');
    json& props = schema["properties"];
    if (dot == std::string::npos) {
        props[path] = std::move(leaf);
        return;
    }
    const std::string head = path.substr(0, dot);
    if (!props.contains(head)) props[head] = objectSchema();
    insert(props[head], path.substr(dot + 1), std::move(leaf));
}

std::string invalidationText(unsigned i) {
    if (i & kNothing) return "bake only";
    if (i & kReimport) return "re-import";
    if (i & kReplace) return "re-place";
    if (i & kRebake) return "preview bake";
    if (i & kUpload) return "upload";
    return "redraw";
}

std::string cell(std::string s) {
    std::string out;
    for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out;
}

}  // namespace

ParameterDock parameterDock(const ParameterSpec& spec) {
    const std::string section = spec.path.substr(0, spec.path.find_first_of(".["));
    // The terrain's surface (its colour and shading) has a dock of its own; the Terrain dock keeps
    // what shapes the heightfield.
    const bool surface = spec.path.rfind("terrain.albedo", 0) == 0 || spec.path.rfind("terrain.ramp_", 0) == 0 ||
                         spec.path == "terrain.roughness" || spec.path == "terrain.specular_aa";
    if (section == "terrain" && !surface) return {"dock.terrain", "Terrain"};
    if (section == "sun" || section == "sky" || section == "scenarios") return {"dock.sunSky", "Sun & Sky"};
    if (section == "probe_volumes") return {"dock.probeVolumes", "Probe Volumes"};
    if (section == "bake" || section == "export") return {"dock.bakeExport", "Bake & Export"};
    if (section == "shadows") return {"dock.shadows", "Shadows"};
    if (section == "detail" || surface) return {"dock.surface", "Surface"};
    // The camera's settings that form the picture (its placement has no row).
    const bool picture = spec.path == "camera.exposure_mode" || spec.path == "camera.ev100" ||
                         spec.path == "camera.exposure_ev" || spec.path == "camera.adaptation_s" ||
                         spec.path == "camera.antialiasing";
    if (section == "fog" || picture) return {"dock.atmosphere", "Atmosphere"};
    if (section == "ao") return {"dock.ao", "Ambient Occlusion"};
    if (section == "water") return {"dock.water", "Water"};
    if (section == "reflection_probes") return {"dock.reflectionProbes", "Reflection Probes"};
    if (section == "lpv" || section == "lights" || spec.path == "lighting.indirect") return {"dock.lpv", "LPV"};
    return {"", ""};
}

std::string uiObjectName(const ParameterSpec& spec) {
    if (spec.perVolume()) return "param.volume." + spec.localPath();
    if (spec.perLight()) return "param.light." + spec.localPath();
    if (spec.perScenario()) return "param.scenario." + spec.localPath();
    return "param." + spec.path;
}

double uiMinimum(const ParameterSpec& spec) {
    return spec.minExclusive ? spec.min + std::pow(10.0, -spec.decimals) : spec.min;
}

std::string autoShort(const ParameterSpec& spec) {
    if (!spec.autoMeaning) return "";
    const std::string& m = *spec.autoMeaning;
    return m.substr(0, m.find(':'));
}

json projectSchema() {
    json schema = objectSchema();
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema";
    schema["$id"] = "urn:terralux:project:1";
    schema["title"] = "Terralux project";
    schema["description"] =
        "A Terralux project file. Every key is optional: an absent key takes its default; an unknown key is an error.";
    auto& props = schema["properties"];
    props["$schema"] = {{"type", "string"}, {"description", "The schema an editor checks this file against"}};
    props["format"] = {{"const", "terralux-project"}, {"description", "Marks the file as a Terralux project"}, {"default", "terralux-project"}};
    props["version"] = {{"type", "integer"}, {"minimum", 1}, {"maximum", kProjectVersion},
                        {"description", "Project format version; older versions are migrated on reading"},
                        {"default", kProjectVersion}};
    json volume = objectSchema(), wave = objectSchema(), light = objectSchema(), scenario = objectSchema();
    for (const auto& s : parameterTable()) {
        if (s.perVolume()) insert(volume, s.localPath(), leafSchema(s));
        else if (s.perWave()) insert(wave, s.localPath(), leafSchema(s));
        else if (s.perLight()) insert(light, s.localPath(), leafSchema(s));
        else if (s.perScenario()) insert(scenario, s.localPath(), leafSchema(s));
        else insert(schema, s.path, leafSchema(s));
    }
    props["probe_volumes"] = {{"type", "array"},
                              {"description", "Probe volumes, each baked into its own .shprobe"},
                              {"items", volume},
                              {"default", json::array({json::object()})}};
    insert(schema, "water.waves",
           {{"type", "array"},
            {"maxItems", WaterSettings::kMaxWaves},
            {"description", "Gerstner waves on the water, each with exactly one of amplitude and steepness; their summed steepness k·A is at most 1"},
            {"items", wave},
            {"default", json::array()}});
    props["lights"] = {{"type", "array"},
                       {"maxItems", kMaxLocalLights},
                       {"description", "Point and spot lights: injected into the light propagation volumes and exported as KHR_lights_punctual; the diffuse bake leaves them out"},
                       {"items", light},
                       {"default", json::array()}};
    props["scenarios"] = {{"type", "array"},
                          {"maxItems", kMaxScenarios},
                          {"description", "Lighting scenarios: a name and a sun and sky of their own, each baked into its own .shprobe set with the project's probe layout"},
                          {"items", scenario},
                          {"default", json::array()}};
    return schema;
}

namespace {
// Elements of a row's list in `scene` (1 for a row outside lists).
size_t elementCount(const SceneDescription& scene, const ParameterSpec& spec) {
    if (spec.perVolume()) return scene.probeVolumes.size();
    if (spec.perWave()) return scene.water.waves.size();
    if (spec.perLight()) return scene.lights.size();
    if (spec.perScenario()) return scene.scenarios.size();
    return 1;
}

// The JSON pointer of a row's value: "/sun/elevation_deg", "/probe_volumes/2/adaptive/size".
json::json_pointer valuePointer(const ParameterSpec& spec, size_t element) {
    std::string local = spec.inList() ? spec.localPath() : spec.path;
    std::string pointer;
    if (spec.inList()) {
        std::string list = spec.listPath();
        std::replace(list.begin(), list.end(), '.', '/');
        pointer = "/" + list + "/" + std::to_string(element);
    }
    std::replace(local.begin(), local.end(), '.', '/');
    return json::json_pointer(pointer + "/" + local);
}
}  // namespace

json bakeReadSettings(const SceneDescription& scene,
                      const std::function<json(const ParameterSpec&, const std::string&)>& identity) {
    json settings = json::object(), files = json::object();
    for (const ParameterSpec& spec : parameterTable()) {
        if (spec.bake == BakeUse::Ignores) continue;
        for (size_t e = 0; e < elementCount(scene, spec); ++e) {
            if (!spec.isRead(scene, e)) continue;
            const json value = spec.get(scene, e);
            if (spec.bake == BakeUse::File)
                files[spec.inList() ? spec.listPath() + "[" + std::to_string(e) + "]." + spec.localPath() : spec.path] =
                    value.is_string() && !value.get<std::string>().empty()
                                       ? identity(spec, value.get<std::string>())
                                       : json(spec.zeroText);
            else
                settings[valuePointer(spec, e)] = value;
        }
    }
    return {{"settings", settings}, {"files", files}};
}

std::vector<ParameterReferenceRow> parameterReferenceRows() {
    std::vector<ParameterReferenceRow> rows;
    for (const auto& s : parameterTable()) {
        ParameterReferenceRow r;
        r.section = s.inList() ? s.listPath() + "[]" : s.path.substr(0, s.path.find('.'));
        r.path = s.path;
        r.type = typeName(s);
        r.defaultValue = s.defaultValue().dump();
        if (s.type == ParamType::Choice) r.allowed = s.rangeText();
        else if (s.type == ParamType::String) r.allowed = s.patternRule.empty() ? "any" : s.patternRule;
        else if (s.type != ParamType::Boolean) r.allowed = (s.type == ParamType::Color || s.type == ParamType::NumberList || s.type == ParamType::IntegerList ? "each " : "") + s.rangeText();
        r.unit = s.unit;
        r.edit = invalidationText(s.invalidates);
        r.bake = s.bake == BakeUse::Reads ? "reads" : s.bake == BakeUse::File ? "reads the file" : "ignores";
        r.autoMeaning = s.autoMeaning.value_or("");
        r.description = s.description;
        rows.push_back(std::move(r));
    }
    return rows;
}

std::string parameterReferenceMarkdown() {
    std::ostringstream md;
    md << "# Project parameters\n\n"
          "Generated from the parameter table (`app/ParameterTable.cpp`) by\n"
          "`terralux --print-reference`; do not edit by hand. Every parameter is reachable by\n"
          "`--set PATH=VALUE`; rows under `probe_volumes[]`, `water.waves[]` and `lights[]` take an index\n"
          "(`probe_volumes[0].grid_dims`), and a whole list is one JSON array (`--set water.waves=[...]`).\n"
          "`null` means \"auto\" where the last column says what auto does. \"Edit redoes\" is the\n"
          "work an edit in the authoring window costs: redraw < upload < preview bake < re-place <\n"
          "re-import; \"bake only\" parameters change nothing on screen. \"Bake\" says whether a bake\n"
          "reads the parameter: an edit of one it ignores leaves a finished bake current.\n";
    std::string section;
    for (const ParameterReferenceRow& r : parameterReferenceRows()) {
        if (r.section != section) {
            section = r.section;
            md << "\n## `" << section << "`\n\n"
               << "| parameter | type | default | allowed | unit | edit redoes | bake | null (auto) | description |\n"
               << "|---|---|---|---|---|---|---|---|---|\n";
        }
        md << "| `" << r.path << "` | " << r.type << " | `" << cell(r.defaultValue) << "` | " << cell(r.allowed)
           << " | " << cell(r.unit) << " | " << r.edit << " | " << r.bake << " | " << cell(r.autoMeaning) << " | "
           << cell(r.description) << " |\n";
    }
    return md.str();
}

std::string uiObjectNamesMarkdown() {
    std::ostringstream out;
    out << "| dock | parameter editors |\n|---|---|\n";
    std::vector<std::pair<ParameterDock, std::vector<std::string>>> docks;
    std::vector<std::string> special;
    for (const ParameterSpec& spec : parameterTable()) {
        if (!spec.uiRow) continue;
        const ParameterDock dock = parameterDock(spec);
        auto it = std::find_if(docks.begin(), docks.end(),
                               [&](const auto& d) { return d.first.objectName == dock.objectName; });
        if (it == docks.end()) it = docks.insert(docks.end(), {dock, {}});
        const std::string name = uiObjectName(spec);
        std::string entry = "`" + name + "`";
        switch (spec.type) {
        case ParamType::Color: entry += " (colour button)"; break;
        case ParamType::Choice: entry += " (combo)"; break;
        case ParamType::Boolean: entry += " (check box)"; break;
        case ParamType::String: entry += " (line edit)"; break;
        case ParamType::NumberList:
        case ParamType::IntegerList:
            entry = "`" + name + ".0`";
            for (int k = 1; k < (spec.colorList ? spec.maxItems / 3 : spec.maxItems); ++k)
                entry += " / `." + std::to_string(k) + "`";
            if (spec.colorList) entry += " (colour buttons, one per stop)";
            if (spec.nullable()) entry += " + `.auto` (check box)";
            break;
        default:
            if (spec.slider) entry += " (+ `.slider`)";
            break;
        }
        it->second.push_back(entry);
        const bool number = spec.type == ParamType::Number || spec.type == ParamType::Integer;
        if (spec.nullable() && number)
            special.push_back("`" + name + "` shows \"" + autoShort(spec) + "\" one step below its minimum for null");
        else if (!spec.zeroText.empty() && number)
            special.push_back("`" + name + "` shows \"" + spec.zeroText + "\" at 0");
        else if (!spec.zeroText.empty())
            special.push_back("`" + name + "` shows \"" + spec.zeroText + "\" when empty");
    }
    for (const auto& [dock, names] : docks) {
        out << "| " << dock.title << " (`" << dock.objectName << "`) | ";
        for (size_t k = 0; k < names.size(); ++k) out << (k ? ", " : "") << names[k];
        out << " |\n";
    }
    out << "\nSpecial values are shown as words: ";
    for (size_t k = 0; k < special.size(); ++k) out << (k ? ", " : "") << special[k];
    out << ".\n";
    return out.str();
}

}  // namespace terralux
