#include "SolarPosition.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace terralux {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

bool leapYear(int y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

int daysIn(int y, int m) {
    static constexpr int days[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    return m == 2 && leapYear(y) ? 29 : days[m - 1];
}

// Julian day at 0 h UT of a Gregorian date (Meeus, eq. 7.1).
double julianDay(const CivilDate& d) {
    int y = d.year, m = d.month;
    if (m <= 2) {
        y -= 1;
        m += 12;
    }
    const int a = y / 100;
    const int b = 2 - a + a / 4;
    return std::floor(365.25 * (y + 4716)) + std::floor(30.6001 * (m + 1)) + d.day + b - 1524.5;
}

double wrap360(double a) {
    a = std::fmod(a, 360.0);
    return a < 0.0 ? a + 360.0 : a;
}

}  // namespace

std::string civilDateRule() {
    return "a calendar date from " + std::to_string(kSolarFirstYear) + "-01-01 to " + std::to_string(kSolarLastYear) +
           "-12-31, YYYY-MM-DD";
}

std::optional<CivilDate> parseCivilDate(const std::string& text) {
    CivilDate d;
    char tail = 0;
    if (text.size() != 10 || text[4] != '-' || text[7] != '-') return std::nullopt;
    for (size_t i : {0u, 1u, 2u, 3u, 5u, 6u, 8u, 9u})
        if (text[i] < '0' || text[i] > '9') return std::nullopt;
    if (std::sscanf(text.c_str(), "%4d-%2d-%2d%c", &d.year, &d.month, &d.day, &tail) != 3) return std::nullopt;
    if (d.year < kSolarFirstYear || d.year > kSolarLastYear) return std::nullopt;
    if (d.month < 1 || d.month > 12 || d.day < 1 || d.day > daysIn(d.year, d.month)) return std::nullopt;
    return d;
}

double refractionDeg(double e) {
    if (e > 85.0) return 0.0;
    const double t = std::tan(e * kDeg);
    double arcsec;
    if (e > 5.0)
        arcsec = 58.1 / t - 0.07 / (t * t * t) + 0.000086 / std::pow(t, 5.0);
    else if (e > -0.575)
        arcsec = 1735.0 + e * (-518.2 + e * (103.4 + e * (-12.79 + e * 0.711)));
    else
        arcsec = -20.772 / t;
    return arcsec / 3600.0;
}

double nominalUtcOffsetHours(double longitudeDeg) { return std::round(longitudeDeg / 15.0); }

SolarPosition solarPosition(const CivilDate& date, double localHours, double utcOffsetHours,
                            double latitudeDeg, double longitudeDeg) {
    const double utcHours = localHours - utcOffsetHours;  // may leave [0, 24): the JD carries on
    const double jd = julianDay(date) + utcHours / 24.0;
    const double T = (jd - 2451545.0) / 36525.0;  // Julian centuries since J2000.0

    // The sun's mean longitude and anomaly, the orbit's eccentricity (Meeus 25.2-25.4).
    const double L0 = wrap360(280.46646 + T * (36000.76983 + T * 0.0003032));
    const double M = 357.52911 + T * (35999.05029 - 0.0001537 * T);
    const double e = 0.016708634 - T * (0.000042037 + 0.0000001267 * T);
    // Equation of the centre, true and apparent longitude (nutation and aberration, 25.8).
    const double Mr = M * kDeg;
    const double C = std::sin(Mr) * (1.914602 - T * (0.004817 + 0.000014 * T)) +
                     std::sin(2.0 * Mr) * (0.019993 - 0.000101 * T) + std::sin(3.0 * Mr) * 0.000289;
    const double omega = (125.04 - 1934.136 * T) * kDeg;
    const double lambda = (L0 + C - 0.00569 - 0.00478 * std::sin(omega)) * kDeg;
    // Obliquity of the ecliptic, corrected (22.2, 25.8).
    const double eps0 = 23.0 + (26.0 + (21.448 - T * (46.815 + T * (0.00059 - T * 0.001813))) / 60.0) / 60.0;
    const double eps = (eps0 + 0.00256 * std::cos(omega)) * kDeg;
    const double decl = std::asin(std::sin(eps) * std::sin(lambda));

    // Equation of time (Meeus 28.3), minutes.
    const double y = std::pow(std::tan(eps / 2.0), 2.0);
    const double L0r = L0 * kDeg;
    const double eot = 4.0 / kDeg *
                       (y * std::sin(2.0 * L0r) - 2.0 * e * std::sin(Mr) +
                        4.0 * e * y * std::sin(Mr) * std::cos(2.0 * L0r) - 0.5 * y * y * std::sin(4.0 * L0r) -
                        1.25 * e * e * std::sin(2.0 * Mr));

    // True solar time and the hour angle, 0 at local noon, positive in the afternoon.
    const double trueSolarMinutes = utcHours * 60.0 + eot + 4.0 * longitudeDeg;
    double hourAngle = wrap360(trueSolarMinutes / 4.0 - 180.0);
    if (hourAngle > 180.0) hourAngle -= 360.0;
    const double H = hourAngle * kDeg, phi = latitudeDeg * kDeg;

    const double sinEl = std::sin(phi) * std::sin(decl) + std::cos(phi) * std::cos(decl) * std::cos(H);
    SolarPosition p;
    p.elevationDeg = std::asin(std::clamp(sinEl, -1.0, 1.0)) / kDeg;
    // Azimuth from the south, westward (Meeus 13.5, multiplied through by cos δ), turned to north.
    const double fromSouth = std::atan2(std::sin(H) * std::cos(decl),
                                        std::cos(H) * std::cos(decl) * std::sin(phi) - std::sin(decl) * std::cos(phi));
    p.azimuthDeg = wrap360(fromSouth / kDeg + 180.0);
    p.apparentElevationDeg = std::min(90.0, p.elevationDeg + refractionDeg(p.elevationDeg));
    p.declinationDeg = decl / kDeg;
    p.equationOfTimeMin = eot;
    return p;
}

}  // namespace terralux
