// nmea::StreamParser: arbitrary chunking, line endings, noise, and a counter for every way a sentence is lost.

#include "fieldguard/drivers/nmea_stream.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

namespace fieldguard::nmea {
namespace {

// Real sentences (gpsd regression logs, see tests/data/PROVENANCE.txt).
const std::string kGga = "$GNGGA,133859.80,4134.50180205,N,09345.03586649,W,4,19,0.7,280.827,M,-31.442,M,5.8,0002*6D";
const std::string kRmc = "$GNRMC,133900.00,A,4134.50180323,N,09345.03586581,W,0.008,0.000,180320,11.5982,E,D*31";
const std::string kVtg = "$GPVTG,,T,,M,,N,,K,N*2C";
const std::string kHdt = "$GNHDT,271.45,T*1E";
const std::string kGsv = "$GPGSV,3,1,11,15,29,271,37,17,81,131,33,30,27,137,32,28,52,062,28*79";

std::string framed(const std::string& body) {
  char hex[4];
  std::snprintf(hex, sizeof hex, "%02X", checksum(body));
  return "$" + body + "*" + hex;
}

struct Result {
  std::vector<Sentence> out;
  StreamCounters counters;
};

Result feed(const std::string& bytes, std::size_t chunk = 0, StreamOptions options = {}) {
  StreamParser p(options);
  Result r;
  if (chunk == 0) chunk = bytes.size() + 1;
  for (std::size_t i = 0; i < bytes.size(); i += chunk) p.push(std::string_view(bytes).substr(i, chunk), r.out);
  p.finish(r.out);
  r.counters = p.counters();
  return r;
}

TEST(NmeaStream, LineEndingsCrLfLfAndCr) {
  for (const char* eol : {"\r\n", "\n", "\r", "\n\r"}) {
    const auto r = feed(kGga + eol + kRmc + eol + kHdt + eol);
    ASSERT_EQ(r.out.size(), 3U) << "eol " << static_cast<int>(eol[0]);
    EXPECT_TRUE(std::holds_alternative<Gga>(r.out[0]));
    EXPECT_TRUE(std::holds_alternative<Rmc>(r.out[1]));
    EXPECT_TRUE(std::holds_alternative<Hdt>(r.out[2]));
    EXPECT_EQ(r.counters.sentences, 3U);
    EXPECT_EQ(r.counters.noise_bytes, 0U);
    EXPECT_EQ(r.counters.rejected(), 0U);
  }
}

TEST(NmeaStream, SentenceOutAsSoonAsItsChecksumIsInAndAtFinishWithoutOne) {
  StreamParser p;
  std::vector<Sentence> out;
  p.push(kHdt.substr(0, kHdt.size() - 1), out);
  EXPECT_TRUE(out.empty());
  p.push(kHdt.substr(kHdt.size() - 1), out);  // no need to wait for the line end
  EXPECT_EQ(out.size(), 1U);
  // Unchecked sentences end at the line end, or at the end of the input.
  StreamParser lenient(StreamOptions{false});
  lenient.push("$GNHDT,271.45,T", out);
  EXPECT_EQ(out.size(), 1U);
  lenient.finish(out);
  EXPECT_EQ(out.size(), 2U);
}

TEST(NmeaStream, EverySplitPointGivesTheSameSentences) {
  const std::string text = "# comment $GPGGA\r\n" + kGga + "\r\n\x01\x02 noise " + kRmc + "\n" + kGsv + "\r\n" + kVtg +
                           "\r\n" + kHdt.substr(0, 9) + "\r\n" + kHdt + "\r\n";
  const auto whole = feed(text);
  ASSERT_EQ(whole.out.size(), 4U);
  for (std::size_t cut = 1; cut < text.size(); ++cut) {
    StreamParser p;
    std::vector<Sentence> out;
    p.push(std::string_view(text).substr(0, cut), out);
    p.push(std::string_view(text).substr(cut), out);
    p.finish(out);
    ASSERT_EQ(out.size(), whole.out.size()) << "cut at " << cut;
    for (std::size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out[i].index(), whole.out[i].index()) << cut;
    const auto& c = p.counters();
    EXPECT_EQ(c.noise_bytes, whole.counters.noise_bytes) << cut;
    EXPECT_EQ(c.unsupported, 1U) << cut;
    EXPECT_EQ(c.no_checksum, 1U) << cut;
  }
  for (std::size_t chunk = 1; chunk < 8; ++chunk) {
    const auto r = feed(text, chunk);
    EXPECT_EQ(r.out.size(), 4U) << "chunk " << chunk;
    EXPECT_EQ(r.counters.noise_bytes, whole.counters.noise_bytes);
  }
}

TEST(NmeaStream, GpsdLogCommentsAreNoiseEvenWithDollarsInThem) {
  const std::string text = "# Non-NMEA compliant: $SNRSTAT, $GYOACC\n#\n" + kHdt + "\n# trailing $GPGGA,1*00\n";
  const auto r = feed(text);
  EXPECT_EQ(r.out.size(), 1U);
  EXPECT_EQ(r.counters.sentences, 1U);
  EXPECT_EQ(r.counters.rejected(), 0U);
  // '#' only starts a comment at the start of a line.
  const auto mid = feed("xx#" + kHdt + "\n");
  EXPECT_EQ(mid.out.size(), 1U);
  EXPECT_EQ(mid.counters.noise_bytes, 3U);
}

TEST(NmeaStream, OverlongInputKeepsMemoryBoundedAndRecovers) {
  // Megabytes without a line end: counted once as too long, and the next sentence still decodes.
  std::string text = "$GPGGA," + std::string(4 << 20, '7') + "\r\n" + kHdt + "\r\n";
  const auto r = feed(text, 4096);
  ASSERT_EQ(r.out.size(), 1U);
  EXPECT_EQ(r.counters.too_long, 1U);
  // Binary garbage with no '$' at all: noise, nothing else.
  std::mt19937 rng(7);
  std::string garbage(1 << 20, '\0');
  for (char& c : garbage) {
    c = static_cast<char>(rng() & 0xFFU);
    if (c == '$') c = '%';
  }
  const auto g = feed(garbage + "\n" + kRmc + "\n", 1000);
  ASSERT_EQ(g.out.size(), 1U);
  EXPECT_EQ(g.counters.sentences, 1U);
}

TEST(NmeaStream, UncheckedSentencesOnRequest) {
  const std::string bare = "$GNHDT,271.45,T\r\n";
  EXPECT_EQ(feed(bare).counters.no_checksum, 1U);
  const auto lenient = feed(bare, 0, StreamOptions{false});
  EXPECT_EQ(lenient.out.size(), 1U);
  EXPECT_EQ(lenient.counters.accepted, 1U);
}

// One kind of damage each: what is left of the input, and which counter must say so.
struct Damage {
  const char* name;
  std::string bytes;
  std::uint64_t StreamCounters::*counter;
  std::uint64_t count;
  std::size_t extra_sentences = 0;  // good sentences inside the damaged bytes
};

class NmeaStreamMalformed : public ::testing::TestWithParam<Damage> {};

TEST_P(NmeaStreamMalformed, IsCountedAndTheNeighboursSurvive) {
  const Damage& d = GetParam();
  // The damaged input between two good sentences, in one piece and byte by byte.
  for (const std::size_t chunk : {std::size_t{0}, std::size_t{1}}) {
    const auto r = feed(kGga + "\r\n" + d.bytes + "\r\n" + kRmc + "\r\n", chunk);
    ASSERT_EQ(r.out.size(), 2U + d.extra_sentences) << d.name;
    EXPECT_TRUE(std::holds_alternative<Gga>(r.out.front()));
    EXPECT_TRUE(std::holds_alternative<Rmc>(r.out.back()));
    EXPECT_EQ(r.counters.*d.counter, d.count) << d.name;
    EXPECT_EQ(r.counters.accepted, 2U + d.extra_sentences);
    // Every other counter stays at zero (noise_bytes aside, which the noise cases set).
    const std::uint64_t others = r.counters.rejected() - (d.counter == &StreamCounters::noise_bytes ? 0 : d.count);
    EXPECT_EQ(others, 0U) << d.name;
  }
}

std::string flip(std::string s, std::size_t i) {
  s[i] = s[i] == '1' ? '2' : '1';
  return s;
}

INSTANTIATE_TEST_SUITE_P(
    Kinds, NmeaStreamMalformed,
    ::testing::Values(
        Damage{"BadChecksum", flip(kGga, 20), &StreamCounters::bad_checksum, 1},
        Damage{"WrongChecksumDigits", kHdt.substr(0, kHdt.size() - 1) + "F", &StreamCounters::bad_checksum, 1},
        Damage{"NoChecksum", kHdt.substr(0, kHdt.size() - 3), &StreamCounters::no_checksum, 1},
        Damage{"OverLong", framed("GPGGA," + std::string(150, '1')), &StreamCounters::too_long, 1},
        Damage{"TwoMergedSentences", kGga.substr(0, kGga.size() - 3) + kRmc.substr(1), &StreamCounters::too_long, 1},
        Damage{"BadField", framed("GPGGA,123519,48x7.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"),
               &StreamCounters::bad_field, 1},
        Damage{"ControlCharacterInside", framed("GPHDT,12\x01.0,T"), &StreamCounters::bad_field, 1},
        Damage{"UnsupportedType", kGsv, &StreamCounters::unsupported, 1},
        Damage{"Proprietary", framed("PSTI,030,003832.000,A"), &StreamCounters::unsupported, 1},
        Damage{"InterruptedByNextSentence", kRmc.substr(0, 30) + kHdt, &StreamCounters::interrupted, 1, 1},
        Damage{"TextNoise", "hello world", &StreamCounters::noise_bytes, 11},
        Damage{"JsonLine", "{\"class\":\"VERSION\"}", &StreamCounters::noise_bytes, 19},
        Damage{"BinaryGarbage", std::string("\xFA\xFF\x36\x00\x80\x7F\x00", 7), &StreamCounters::noise_bytes, 7},
        Damage{"BinaryInsideSentence", std::string("$GPHDT,1\xFF\xFE.0,T*00"), &StreamCounters::bad_checksum, 1}),
    [](const auto& tp) { return std::string(tp.param.name); });

TEST(NmeaStream, SentencesEndAtTheirChecksum) {
  // Glued together without line ends, and text after a checksum: the sentences still come out.
  const auto glued = feed(kHdt + kRmc + kHdt);
  EXPECT_EQ(glued.out.size(), 3U);
  EXPECT_EQ(glued.counters.rejected(), 0U);
  const auto trailing = feed(kHdt + " \x01junk\r\n" + kGga + "\r\n");
  EXPECT_EQ(trailing.out.size(), 2U);
  EXPECT_EQ(trailing.counters.noise_bytes, 6U);
  // An over-long sentence cut off by the next '$' is too long, not interrupted.
  const auto cut = feed("$GPGSV," + std::string(200, '1') + kHdt + "\r\n");
  EXPECT_EQ(cut.out.size(), 1U);
  EXPECT_EQ(cut.counters.too_long, 1U);
  EXPECT_EQ(cut.counters.interrupted, 0U);
}

TEST(NmeaStream, NoiseBetweenSentencesWithoutLineEnds) {
  // Sentences glued to garbage: '$' starts a sentence wherever it is.
  const auto r = feed(std::string("\x00\x01garbage", 9) + kHdt + "\r\nmore garbage" + kHdt + "\r\n");
  EXPECT_EQ(r.out.size(), 2U);
  EXPECT_EQ(r.counters.noise_bytes, 9U + 12U);
}

TEST(NmeaStream, RealLogEveryChunkSize) {
  std::ifstream f(std::string(FIELDGUARD_TEST_DATA) + "/nmea/nmea-rtk.log", std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  const std::string log = s.str();
  ASSERT_FALSE(log.empty());
  const auto whole = feed(log);
  EXPECT_EQ(whole.out.size(), 244U);
  EXPECT_EQ(whole.counters.rejected(), 0U);
  for (const std::size_t chunk : {1U, 2U, 3U, 7U, 64U, 81U, 82U, 83U, 4096U}) {
    const auto r = feed(log, chunk);
    EXPECT_EQ(r.out.size(), 244U) << chunk;
    EXPECT_EQ(r.counters.noise_bytes, whole.counters.noise_bytes) << chunk;
  }
}

}  // namespace
}  // namespace fieldguard::nmea
