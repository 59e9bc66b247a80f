#pragma once
// Where the sun stands for a place on the Earth and a civil time: NOAA's solar position
// equations (the NOAA Global Monitoring Laboratory's solar calculator, after Meeus,
// "Astronomical Algorithms", 2nd ed., ch. 25 and 28), stated to about 0.01° for the years
// 1901-2099. docs/lighting.md, "The sun from a date and a time".

#include <optional>
#include <string>

namespace terralux {

struct CivilDate {
    int year = 2000;
    int month = 1;  // 1..12
    int day = 1;    // 1..days in the month
};

// Years the solar position accepts: NOAA states its equations for 1901-2099.
inline constexpr int kSolarFirstYear = 1901;
inline constexpr int kSolarLastYear = 2099;

// "YYYY-MM-DD" (Gregorian) within kSolarFirstYear..kSolarLastYear; nullopt for anything else,
// a 29 February of a common year included.
std::optional<CivilDate> parseCivilDate(const std::string& text);
// What parseCivilDate accepts, as a rule for messages: "a calendar date from 1901-01-01 to ...".
std::string civilDateRule();

struct SolarPosition {
    double azimuthDeg = 0.0;           // clockwise from true north, [0, 360)
    double elevationDeg = 0.0;         // geometric, above the horizon
    double apparentElevationDeg = 0.0; // with the standard atmosphere's refraction (what is seen)
    double declinationDeg = 0.0;
    double equationOfTimeMin = 0.0;    // apparent minus mean solar time, minutes
};

// The sun at `date`, `localHours` after its midnight on a clock `utcOffsetHours` ahead of UTC,
// seen from latitude / longitude in degrees (north and east positive).
SolarPosition solarPosition(const CivilDate& date, double localHours, double utcOffsetHours,
                            double latitudeDeg, double longitudeDeg);

// The atmospheric refraction NOAA adds to a geometric elevation for a standard atmosphere,
// degrees: a series in 1/tan e above 5°, a polynomial in e down to -0.575°, -20.772"/tan e
// below, none above 85°.
double refractionDeg(double elevationDeg);

// The nominal time zone of a longitude: the whole hours nearest longitude / 15.
double nominalUtcOffsetHours(double longitudeDeg);

}  // namespace terralux
