// VTG, HDT, THS and parse_sentence() (nmea_test.cpp covers GGA and RMC field by field).

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <variant>

#include "fieldguard/drivers/nmea.hpp"

namespace fieldguard::nmea {
namespace {

std::string framed(const std::string& body) {
  char hex[4];
  std::snprintf(hex, sizeof hex, "%02X", checksum(body));
  return "$" + body + "*" + hex;
}

// protocols.md §4.4: each checksum was recomputed when the document was written.
TEST(NmeaSentence, WorkedExamplesDecode) {
  for (const char* s : {"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47",
                        "$GNGGA,083015.00,3954.12345,N,11623.45678,E,4,18,0.7,52.3,M,-8.4,M,1.0,0123*79",
                        "$GNRMC,083015.00,A,3954.12345,N,11623.45678,E,0.52,87.3,210324,,,R,V*2E",
                        "$GNVTG,87.3,T,,M,0.52,N,0.96,K,R*34", "$GNHDT,271.45,T*1E", "$GNTHS,271.45,A*1C"}) {
    const auto r = parse_sentence(s);
    EXPECT_TRUE(r) << s << ": " << (r ? "" : to_string(r.error()));
  }
}

TEST(NmeaSentence, DispatchesOnTheTypeWhateverTheTalker) {
  for (const char* talker : {"GP", "GN", "GL", "GA", "GB", "BD", "GQ", "HE", "HC", "IN", "GI", "QZ"}) {
    const auto hdt = parse_sentence(framed(std::string(talker) + "HDT,12.5,T"));
    ASSERT_TRUE(hdt) << talker;
    ASSERT_TRUE(std::holds_alternative<Hdt>(*hdt));
    EXPECT_EQ(talker_of(*hdt), talker);
    EXPECT_EQ(type_of(*hdt), "HDT");
    const auto gga =
        parse_sentence(framed(std::string(talker) + "GGA,120000,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"));
    ASSERT_TRUE(gga) << talker;
    EXPECT_EQ(std::get<Gga>(*gga).quality, 1);
  }
}

TEST(NmeaSentence, TypesWeDoNotDecodeAreUnsupported) {
  for (const char* s : {"$GPGSV,3,1,11,15,29,271,37,17,81,131,33,30,27,137,32,28,52,062,28*79",
                        "$GNGSA,A,3,15,17,30,28,01,19,24,11,,,,,1.8,0.9,1.5*2C"}) {
    const auto r = parse_sentence(s);
    ASSERT_FALSE(r) << s;
    EXPECT_EQ(r.error(), Error::Unsupported);
  }
  const auto psti = parse_sentence(framed("PSTI,030,003832.000,A,4404.1271062,N,12118.8438377,W"));
  ASSERT_FALSE(psti);
  EXPECT_EQ(psti.error(), Error::Unsupported);
}

TEST(NmeaVtg, FullAndEmpty) {
  const auto v = parse_vtg("$GNVTG,87.3,T,,M,0.52,N,0.96,K,R*34");
  ASSERT_TRUE(v) << to_string(v.error());
  EXPECT_EQ(v->talker, "GN");
  EXPECT_EQ(v->course_true_deg, 87.3);
  EXPECT_FALSE(v->course_magnetic_deg);
  EXPECT_NEAR(*v->speed_mps, 0.52 * 1852.0 / 3600.0, 1e-12);
  EXPECT_EQ(v->mode, 'R');

  const auto hemi = parse_vtg("$GPVTG,,T,,M,,N,,K,N*2C");  // hemi.log, no fix
  ASSERT_TRUE(hemi) << to_string(hemi.error());
  EXPECT_FALSE(hemi->course_true_deg || hemi->course_magnetic_deg || hemi->speed_mps);
  EXPECT_EQ(hemi->mode, 'N');

  // Only the km/h speed given.
  const auto kmh = parse_vtg(framed("GPVTG,10.0,T,,M,,N,36.0,K"));
  ASSERT_TRUE(kmh);
  EXPECT_NEAR(*kmh->speed_mps, 10.0, 1e-12);
  EXPECT_EQ(kmh->mode, 0);  // NMEA < 2.3: no mode field
}

TEST(NmeaHdtThs, Heading) {
  const auto h = parse_hdt("$GNHDT,271.45,T*1E");
  ASSERT_TRUE(h);
  EXPECT_EQ(h->heading_deg, 271.45);
  const auto t = parse_ths("$GNTHS,271.45,A*1C");
  ASSERT_TRUE(t);
  EXPECT_EQ(t->heading_deg, 271.45);
  EXPECT_EQ(t->mode, 'A');
  const auto invalid = parse_ths(framed("GNTHS,,V"));
  ASSERT_TRUE(invalid);
  EXPECT_FALSE(invalid->heading_deg);
  EXPECT_EQ(invalid->mode, 'V');
  EXPECT_TRUE(parse_hdt(framed("HEHDT,0.0,T")));
  EXPECT_TRUE(parse_hdt(framed("HEHDT,360.0,T")));
}

TEST(NmeaGga, EmptyQualityIsNotZero) {
  const auto g = parse_gga(framed("GPGGA,120000,4807.038,N,01131.000,E,,08,0.9,545.4,M,46.9,M,,"));
  ASSERT_TRUE(g);
  EXPECT_FALSE(g->quality.has_value());
  const auto d =
      parse_gga("$GNGGA,133859.80,4134.50180205,N,09345.03586649,W,4,19,0.7,280.827,M,-31.442,M,5.8,0002*6D");
  ASSERT_TRUE(d);
  EXPECT_EQ(d->dgps_age_s, 5.8);
  EXPECT_EQ(d->dgps_station, "0002");
}

TEST(NmeaRmc, StatusAndMagneticVariation) {
  const auto east = parse_rmc("$GNRMC,133900.00,A,4134.50180323,N,09345.03586581,W,0.008,0.000,180320,11.5982,E,D*31");
  ASSERT_TRUE(east);
  EXPECT_EQ(east->status, 'A');
  EXPECT_EQ(east->magnetic_variation_deg, 11.5982);
  const auto west = parse_rmc(framed("GPRMC,220632,V,3707.8324,N,12139.2864,W,000.0,144.7,111212,013.8,W,D"));
  ASSERT_TRUE(west);
  EXPECT_EQ(west->status, 'V');
  EXPECT_FALSE(west->valid);
  EXPECT_EQ(west->magnetic_variation_deg, -13.8);
  const auto empty = parse_rmc(framed("GPRMC,,,,,,,,,,,,"));
  ASSERT_TRUE(empty);
  EXPECT_EQ(empty->status, 0);
}

TEST(NmeaSentence, UncheckedSentencesOnlyWhenAskedFor) {
  const std::string bare = "$GNHDT,271.45,T";
  const auto strict = parse_sentence(bare);
  ASSERT_FALSE(strict);
  EXPECT_EQ(strict.error(), Error::NoChecksum);
  const auto lenient = parse_sentence(bare, ParseOptions{false});
  ASSERT_TRUE(lenient);
  EXPECT_EQ(std::get<Hdt>(*lenient).heading_deg, 271.45);
  // A wrong checksum stays wrong.
  const auto wrong = parse_sentence("$GNHDT,271.45,T*1F", ParseOptions{false});
  ASSERT_FALSE(wrong);
  EXPECT_EQ(wrong.error(), Error::BadChecksum);
}

struct BadSentence {
  const char* name;
  std::string sentence;
  Error error;
};

class NmeaNewTypesMalformed : public ::testing::TestWithParam<BadSentence> {};

TEST_P(NmeaNewTypesMalformed, GivesTheRightError) {
  const auto r = parse_sentence(GetParam().sentence);
  ASSERT_FALSE(r) << GetParam().sentence;
  EXPECT_EQ(r.error(), GetParam().error) << to_string(r.error());
}

INSTANTIATE_TEST_SUITE_P(
    Sentences, NmeaNewTypesMalformed,
    ::testing::Values(BadSentence{"VtgWrongUnit", framed("GPVTG,87.3,M,,M,0.52,N,0.96,K,A"), Error::BadField},
                      BadSentence{"VtgTooFewFields", framed("GPVTG,87.3,T,,M"), Error::BadField},
                      BadSentence{"VtgCourseOver360", framed("GPVTG,361.0,T,,M,0.52,N,0.96,K,A"), Error::BadField},
                      BadSentence{"VtgSpeedNotANumber", framed("GPVTG,87.3,T,,M,fast,N,0.96,K,A"), Error::BadField},
                      BadSentence{"HdtNegative", framed("GPHDT,-1.0,T"), Error::BadField},
                      BadSentence{"HdtMagnetic", framed("GPHDT,12.0,M"), Error::BadField},
                      BadSentence{"HdtNoFields", framed("GPHDT"), Error::BadField},
                      BadSentence{"ThsTwoLetterMode", framed("GPTHS,12.0,AA"), Error::BadField},
                      BadSentence{"ThsBadHeading", framed("GPTHS,1.2.3,A"), Error::BadField},
                      BadSentence{"HdtBadChecksum", "$GNHDT,271.45,T*1F", Error::BadChecksum},
                      BadSentence{"ThsNoChecksum", "$GNTHS,271.45,A", Error::NoChecksum},
                      BadSentence{"TooLong", framed("GPHDT,1" + std::string(130, '0') + ",T"), Error::TooLong}),
    [](const auto& tp) { return std::string(tp.param.name); });

}  // namespace
}  // namespace fieldguard::nmea
