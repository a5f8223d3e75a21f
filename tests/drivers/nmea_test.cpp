#include "fieldguard/drivers/nmea.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace fieldguard::nmea {
namespace {

// Real sentences from ../shared/realdata/nmea-gpsd-regress (gpsd regression logs, BSD-2-Clause). Where a
// comment gives gpsd's decode, it is from the log's .chk file.
// haicom-305N.log: southern hemisphere (Brisbane), no fix yet (status V, quality 0), 2-digit year 07.
constexpr const char* kHaicomRmc = "$GPRMC,095255.810,V,2712.6404,S,15303.1201,E,0.00,0.00,080407,,,A*6E";
constexpr const char* kHaicomGga = "$GPGGA,095257.809,2712.6404,S,15303.1201,E,0,00,00.0,4.0,M,42.2,M,,*7B";
// ublox-zed-f9p-nmea.log: south and east, empty course, NMEA 4.1 navigational status.
// gpsd: lat -45.877567167, lon 170.500111333, 2019-04-12T00:39:56.000Z.
constexpr const char* kUbloxRmc = "$GNRMC,003956.00,A,4552.65403,S,17030.00668,E,0.025,,120419,,,A,V*07";
// nmea-rtk.log: RTK fixed (quality 4), west. gpsd: lat 41.575030034, lon -93.750597775, altMSL 280.827,
// geoidSep -31.442, dgpsAge 5.8.
constexpr const char* kRtkFixedGga =
    "$GNGGA,133859.80,4134.50180205,N,09345.03586649,W,4,19,0.7,280.827,M,-31.442,M,5.8,0002*6D";
// nmea-fuzzy-cases.log: DGPS RMC with magnetic variation. gpsd: lat 41.575030054, lon -93.750597764, speed 0.004.
constexpr const char* kFuzzyRmc =
    "$GNRMC,133900.00,A,4134.50180323,N,09345.03586581,W,0.008,0.000,180320,11.5982,E,D*31";
// skytraq-PX1172RH_DS.log: RTK float (quality 5), mode F. gpsd: lat 44.068785103, lon -121.314063962.
constexpr const char* kRtkFloatGga =
    "$GPGGA,003832.000,4404.1271062,N,12118.8438377,W,5,14,0.8,1127.630,M,-20.300,M,1.000,0000*74";
constexpr const char* kRtkFloatRmc = "$GNRMC,003832.000,A,4404.1271062,N,12118.8438377,W,000.0,171.0,290322,,,F,V*10";
// hemi.log and telit-he910.log: no fix, every field empty.
constexpr const char* kEmptyGga = "$GPGGA,,,,,,0,,,,M,,M,,*66";
constexpr const char* kEmptyRmc = "$GPRMC,,V,,,,,,,,,,N*53";
constexpr const char* kHemiVtg = "$GPVTG,,T,,M,,N,,K,N*2C";
// sirfstarv-nmea.log: GLONASS talker.
constexpr const char* kGlonassGga = "$GLGGA,020935.000,4404.1351,N,12118.8556,W,1,02,0.9,1123.9,M,-19.6,M,,0000*48";

// "$" + body + "*hh" with the right checksum, for hand-made sentences.
std::string framed(const std::string& body) {
  char hex[4];
  std::snprintf(hex, sizeof hex, "%02X", checksum(body));
  return "$" + body + "*" + hex;
}

TEST(NmeaChecksum, WorkedExamples) {
  // protocols.md §4.4
  EXPECT_EQ(checksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), 0x47);
  EXPECT_EQ(checksum("GNHDT,271.45,T"), 0x1E);
  EXPECT_EQ(checksum(""), 0);
}

TEST(NmeaRmc, SouthernHemisphereWithoutFix) {
  const auto r = parse_rmc(kHaicomRmc);
  ASSERT_TRUE(r) << to_string(r.error());
  EXPECT_EQ(r->talker, "GP");
  EXPECT_FALSE(r->valid);  // status V, but the position is still there
  EXPECT_NEAR(*r->utc_seconds_of_day, 9 * 3600 + 52 * 60 + 55.810, 1e-9);
  EXPECT_NEAR(*r->lat_deg, -(27 + 12.6404 / 60), 1e-12);
  EXPECT_NEAR(*r->lon_deg, 153 + 3.1201 / 60, 1e-12);
  EXPECT_EQ(r->speed_mps, 0.0);
  EXPECT_EQ(r->course_deg, 0.0);
  EXPECT_EQ(r->day, 8);
  EXPECT_EQ(r->month, 4);
  EXPECT_EQ(r->year, 2007);
  EXPECT_EQ(r->mode, 'A');
}

TEST(NmeaRmc, SouthEastWithEmptyCourse) {
  const auto r = parse_rmc(kUbloxRmc);
  ASSERT_TRUE(r) << to_string(r.error());
  EXPECT_EQ(r->talker, "GN");
  EXPECT_TRUE(r->valid);
  EXPECT_NEAR(*r->lat_deg, -45.877567167, 1e-9);
  EXPECT_NEAR(*r->lon_deg, 170.500111333, 1e-9);
  EXPECT_NEAR(*r->speed_mps, 0.025 * 0.514444, 1e-6);
  EXPECT_FALSE(r->course_deg.has_value());  // empty, not 0
  EXPECT_EQ(r->year, 2019);
  EXPECT_EQ(r->mode, 'A');
}

TEST(NmeaRmc, WestWithMagneticVariation) {
  const auto r = parse_rmc(kFuzzyRmc);
  ASSERT_TRUE(r) << to_string(r.error());
  EXPECT_NEAR(*r->lat_deg, 41.575030054, 1e-9);
  EXPECT_NEAR(*r->lon_deg, -93.750597764, 1e-9);
  EXPECT_NEAR(*r->speed_mps, 0.0041156, 1e-7);
  EXPECT_EQ(r->course_deg, 0.0);  // "0.000": present and zero
  EXPECT_EQ(r->day, 18);
  EXPECT_EQ(r->month, 3);
  EXPECT_EQ(r->year, 2020);
  EXPECT_EQ(r->mode, 'D');
}

TEST(NmeaRmc, RtkFloatMode) {
  const auto r = parse_rmc(kRtkFloatRmc);
  ASSERT_TRUE(r) << to_string(r.error());
  EXPECT_EQ(r->mode, 'F');
  EXPECT_NEAR(*r->lat_deg, 44.068785103, 1e-9);
  EXPECT_NEAR(*r->lon_deg, -121.314063962, 1e-9);
  EXPECT_EQ(r->course_deg, 171.0);
}

TEST(NmeaRmc, AllFieldsEmpty) {
  const auto r = parse_rmc(kEmptyRmc);
  ASSERT_TRUE(r) << to_string(r.error());
  EXPECT_FALSE(r->valid);
  EXPECT_FALSE(r->utc_seconds_of_day || r->lat_deg || r->lon_deg || r->speed_mps || r->course_deg);
  EXPECT_FALSE(r->day || r->month || r->year);
  EXPECT_EQ(r->mode, 'N');
}

TEST(NmeaRmc, TwoDigitYears) {
  const auto year_of = [](const char* ddmmyy) {
    const auto r = parse_rmc(framed(std::string("GPRMC,120000,A,,,,,,,") + ddmmyy + ",,"));
    return r ? r->year.value_or(-1) : -2;
  };
  EXPECT_EQ(year_of("010180"), 1980);
  EXPECT_EQ(year_of("311299"), 1999);
  EXPECT_EQ(year_of("010100"), 2000);
  EXPECT_EQ(year_of("311279"), 2079);
  EXPECT_EQ(year_of("290224"), 2024);  // leap year
  EXPECT_EQ(year_of("290223"), -2);    // not one
}

TEST(NmeaRmc, LineEndingsAndPaddingAreTolerated) {
  const std::string s = kFuzzyRmc;
  for (const std::string& tail : {std::string("\r\n"), std::string("\n"), std::string("\r\n\0\0\0", 5)}) {
    const auto r = parse_rmc(s + tail);
    ASSERT_TRUE(r) << to_string(r.error());
    EXPECT_NEAR(*r->lat_deg, 41.575030054, 1e-9);
  }
}

TEST(NmeaRmc, LowercaseChecksumIsAccepted) {
  std::string s = kHaicomRmc;
  ASSERT_EQ(s.substr(s.size() - 2), "6E");
  s.back() = 'e';
  EXPECT_TRUE(parse_rmc(s));
}

TEST(NmeaRmc, BlanksInsideFieldsAreTrimmed) {
  // protocols.md §4.3: "…,2.703, ,200417, , ,A*64" seen in the wild.
  const auto r = parse_rmc(framed("GPRMC,092751.000,A,5321.6802,N,00630.3371,W,0.06,31.66, 280511 , , ,A"));
  ASSERT_TRUE(r) << to_string(r.error());
  EXPECT_EQ(r->day, 28);
}

TEST(NmeaGga, RtkFixed) {
  const auto g = parse_gga(kRtkFixedGga);
  ASSERT_TRUE(g) << to_string(g.error());
  EXPECT_EQ(g->talker, "GN");
  EXPECT_NEAR(*g->utc_seconds_of_day, 13 * 3600 + 38 * 60 + 59.8, 1e-9);
  EXPECT_NEAR(*g->lat_deg, 41.575030034, 1e-9);
  EXPECT_NEAR(*g->lon_deg, -93.750597775, 1e-9);
  EXPECT_EQ(g->quality, 4);
  EXPECT_EQ(g->satellites, 19);
  EXPECT_EQ(g->hdop, 0.7);
  EXPECT_EQ(g->alt_m, 280.827);
  EXPECT_EQ(g->geoid_sep_m, -31.442);
}

TEST(NmeaGga, RtkFloat) {
  const auto g = parse_gga(kRtkFloatGga);
  ASSERT_TRUE(g) << to_string(g.error());
  EXPECT_EQ(g->quality, 5);
  EXPECT_EQ(g->satellites, 14);
  EXPECT_NEAR(*g->alt_m + *g->geoid_sep_m, 1107.33, 1e-9);  // gpsd altHAE
}

TEST(NmeaGga, WorkedExampleRtkFixed) {
  // protocols.md §4.4
  const auto g = parse_gga("$GNGGA,083015.00,3954.12345,N,11623.45678,E,4,18,0.7,52.3,M,-8.4,M,1.0,0123*79\r\n");
  ASSERT_TRUE(g) << to_string(g.error());
  EXPECT_NEAR(*g->lat_deg, 39.90205750, 1e-8);
  EXPECT_NEAR(*g->lon_deg, 116.39094633, 1e-8);
  EXPECT_EQ(g->satellites, 18);
}

TEST(NmeaGga, EmptyFieldsAreNotZeros) {
  const auto empty = parse_gga(kEmptyGga);
  ASSERT_TRUE(empty) << to_string(empty.error());
  EXPECT_EQ(empty->quality, 0);
  EXPECT_FALSE(empty->utc_seconds_of_day || empty->lat_deg || empty->lon_deg || empty->satellites || empty->hdop ||
               empty->alt_m || empty->geoid_sep_m);

  const auto zeros = parse_gga(kHaicomGga);  // "0,00,00.0": no fix, but the fields are there
  ASSERT_TRUE(zeros) << to_string(zeros.error());
  EXPECT_EQ(zeros->quality, 0);
  EXPECT_EQ(zeros->satellites, 0);
  EXPECT_EQ(zeros->hdop, 0.0);
  EXPECT_NEAR(*zeros->lat_deg, -(27 + 12.6404 / 60), 1e-12);
  EXPECT_EQ(zeros->alt_m, 4.0);
}

// A position-only DGPS receiver: quality 2 and a position, every optional field empty. A valid fix whose
// optional fields are absent, not a bad field. And a real one (gpsd regress, telit-he910.log) with the geoid
// separation empty.
TEST(NmeaGga, PositionOnlyFixHasItsOptionalFieldsAbsent) {
  const auto dgps = parse_gga("$GPGGA,123519.00,4807.0380,N,01131.0000,E,2,,,,,,,,*7E");
  ASSERT_TRUE(dgps) << to_string(dgps.error());
  EXPECT_EQ(dgps->quality, 2);
  EXPECT_NEAR(*dgps->lat_deg, 48 + 7.038 / 60, 1e-12);
  EXPECT_NEAR(*dgps->lon_deg, 11 + 31.0 / 60, 1e-12);
  EXPECT_FALSE(dgps->satellites || dgps->hdop || dgps->alt_m || dgps->geoid_sep_m || dgps->dgps_age_s);

  const auto telit = parse_gga("$GPGGA,105153.71,5050.4122,N,00420.8266,E,1,04,2.25,109.44,M,,M,,*77");
  ASSERT_TRUE(telit) << to_string(telit.error());
  EXPECT_EQ(telit->satellites, 4);
  EXPECT_EQ(telit->alt_m, 109.44);
  EXPECT_FALSE(telit->geoid_sep_m);
}

TEST(NmeaGga, AnyTalker) {
  const auto gl = parse_gga(kGlonassGga);
  ASSERT_TRUE(gl) << to_string(gl.error());
  EXPECT_EQ(gl->talker, "GL");
  EXPECT_EQ(gl->quality, 1);
  const auto gb = parse_gga(framed("GBGGA,120000.00,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"));
  ASSERT_TRUE(gb) << to_string(gb.error());
  EXPECT_EQ(gb->talker, "GB");
}

TEST(NmeaGga, ShortDecimals) {
  const auto g = parse_gga(framed("GPGGA,123519,4807.038,N,01131.000,E,1,08,.9,545.,M,-0.5,M,,"));
  ASSERT_TRUE(g) << to_string(g.error());
  EXPECT_EQ(g->hdop, 0.9);
  EXPECT_EQ(g->alt_m, 545.0);
  EXPECT_EQ(g->geoid_sep_m, -0.5);
}

struct Bad {
  const char* name;
  std::string sentence;
  bool rmc;  // parse_rmc, else parse_gga
  Error error;
};

std::string without_checksum(std::string s) { return s.substr(0, s.rfind('*')); }

std::string flip_one_char(std::string s) {
  s[20] = s[20] == '1' ? '2' : '1';  // inside the latitude; checksum left as it was
  return s;
}

std::string wrong_checksum(std::string s) {
  s.back() = s.back() == '0' ? '1' : '0';
  return s;
}

class NmeaMalformed : public ::testing::TestWithParam<Bad> {};

TEST_P(NmeaMalformed, GivesTheRightError) {
  const Bad& b = GetParam();
  if (b.rmc) {
    const auto r = parse_rmc(b.sentence);
    ASSERT_FALSE(r) << b.sentence;
    EXPECT_EQ(r.error(), b.error) << to_string(r.error());
  } else {
    const auto g = parse_gga(b.sentence);
    ASSERT_FALSE(g) << b.sentence;
    EXPECT_EQ(g.error(), b.error) << to_string(g.error());
  }
}

INSTANTIATE_TEST_SUITE_P(
    Sentences, NmeaMalformed,
    ::testing::Values(
        Bad{"WrongChecksum", wrong_checksum(kRtkFixedGga), false, Error::BadChecksum},
        Bad{"CorruptedByte", flip_one_char(kRtkFixedGga), false, Error::BadChecksum},
        Bad{"OneChecksumDigit", without_checksum(kFuzzyRmc) + "*3", true, Error::BadChecksum},
        Bad{"NotHexChecksum", without_checksum(kFuzzyRmc) + "*G1", true, Error::BadChecksum},
        Bad{"TextAfterChecksum", std::string(kFuzzyRmc) + " x", true, Error::BadChecksum},
        Bad{"NoChecksum", without_checksum(kFuzzyRmc), true, Error::NoChecksum},
        Bad{"NoChecksumGga", without_checksum(kRtkFixedGga) + "\r\n", false, Error::NoChecksum},
        Bad{"NoDollar", std::string(kFuzzyRmc).substr(1), true, Error::NoStart}, Bad{"Empty", "", true, Error::NoStart},
        Bad{"OnlyLineEnd", "\r\n", false, Error::NoStart},
        Bad{"TwoMerged", without_checksum(kRtkFixedGga) + kFuzzyRmc, true, Error::TooLong},
        Bad{"GgaAsRmc", kRtkFixedGga, true, Error::Unsupported}, Bad{"VtgAsGga", kHemiVtg, false, Error::Unsupported},
        Bad{"RmcAsGga", kFuzzyRmc, false, Error::Unsupported},
        Bad{"DollarInside", framed("GPRMC,1200$00,A,,,,,,,010120,,"), true, Error::BadField},
        Bad{"ControlChar", framed("GPRMC,120000,A,,,,,,,010120,,\x01"), true, Error::BadField},
        Bad{"TooFewFields", framed("GPRMC,120000,A,4807.038,N,01131.000,E"), true, Error::BadField},
        Bad{"LatNotANumber", framed("GPRMC,120000,A,48x7.038,N,01131.000,E,,,010120,,"), true, Error::BadField},
        Bad{"MinutesOver60", framed("GPRMC,120000,A,4867.038,N,01131.000,E,,,010120,,"), true, Error::BadField},
        Bad{"LatOver90", framed("GPRMC,120000,A,9100.000,N,01131.000,E,,,010120,,"), true, Error::BadField},
        Bad{"NoHemisphere", framed("GPRMC,120000,A,4807.038,,01131.000,E,,,010120,,"), true, Error::BadField},
        Bad{"WrongHemisphere", framed("GPRMC,120000,A,4807.038,E,01131.000,E,,,010120,,"), true, Error::BadField},
        Bad{"BadStatus", framed("GPRMC,120000,X,4807.038,N,01131.000,E,,,010120,,"), true, Error::BadField},
        Bad{"Hour24", framed("GPRMC,240000,A,4807.038,N,01131.000,E,,,010120,,"), true, Error::BadField},
        Bad{"ShortTime", framed("GPRMC,12000,A,4807.038,N,01131.000,E,,,010120,,"), true, Error::BadField},
        Bad{"Month13", framed("GPRMC,120000,A,4807.038,N,01131.000,E,,,011320,,"), true, Error::BadField},
        Bad{"FourDigitYear", framed("GPRMC,120000,A,4807.038,N,01131.000,E,,,01012020,,"), true, Error::BadField},
        Bad{"DoubleSign", framed("GPRMC,120000,A,4807.038,N,01131.000,E,--1,,010120,,"), true, Error::BadField},
        Bad{"Exponent", framed("GPRMC,120000,A,4807.038,N,01131.000,E,1e3,,010120,,"), true, Error::BadField},
        Bad{"BadVariationSide", framed("GPRMC,120000,A,,,,,,,010120,1.0,N"), true, Error::BadField},
        Bad{"BadMode", framed("GPRMC,120000,A,,,,,,,010120,,,AB"), true, Error::BadField},
        Bad{"QualityLetter", framed("GPGGA,123519,4807.038,N,01131.000,E,A,08,0.9,545.4,M,46.9,M,,"), false,
            Error::BadField},
        Bad{"Quality10", framed("GPGGA,123519,4807.038,N,01131.000,E,10,08,0.9,545.4,M,46.9,M,,"), false,
            Error::BadField},
        Bad{"NegativeSatellites", framed("GPGGA,123519,4807.038,N,01131.000,E,1,-8,0.9,545.4,M,46.9,M,,"), false,
            Error::BadField},
        Bad{"HugeSatellites", framed("GPGGA,123519,4807.038,N,01131.000,E,1,99999999999,0.9,545.4,M,46.9,M,,"), false,
            Error::BadField},
        Bad{"TruncatedGga", framed("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M"), false, Error::BadField}),
    [](const auto& tp) { return std::string(tp.param.name); });

TEST(NmeaRmc, LongestAcceptedSentence) {
  // 120 characters from '$' to the checksum (real receivers exceed the standard's 80); 121 is too long.
  std::string body = "GPRMC,120000,A,,,,,,,010120,,,A,";
  body += std::string(120 - 4 - body.size() - 1, ' ');  // blanks trim away
  body += "V";                                          // the 13th field (navigational status) is not read
  const std::string ok = framed(body);
  ASSERT_EQ(ok.size(), 120U);
  EXPECT_TRUE(parse_rmc(ok));
  const auto too_long = parse_rmc(framed(body + "x"));
  ASSERT_FALSE(too_long);
  EXPECT_EQ(too_long.error(), Error::TooLong);
}

TEST(NmeaError, Names) {
  EXPECT_EQ(to_string(Error::BadChecksum), "bad_checksum");
  EXPECT_EQ(to_string(Error::NoChecksum), "no_checksum");
  EXPECT_EQ(to_string(Error::TooLong), "too_long");
}

}  // namespace
}  // namespace fieldguard::nmea
