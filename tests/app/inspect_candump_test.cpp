// `fieldguard inspect` on candump logs: a slice of a real J1939 truck log (tests/data/can/, CSS Electronics
// CANedge, see tests/data/PROVENANCE.txt) with its J1939 fields, every frame form of protocols.md §7.2, candump's
// default (spaced) output, and malformed lines counted by reason.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "io/pcap_builder.hpp"

namespace fieldguard {
namespace {

using testing::Json;
using testing::run_fieldguard;
using testing::summary_number;
using testing::TempDir;

const std::string kSlice = std::string(FIELDGUARD_TEST_DATA) + "/can/j1939_truck_idle_first300.log";

std::string write(const TempDir& dir, const std::string& name, const std::string& text) {
  return "'" + dir.write(name, testing::Bytes(text.begin(), text.end())) + "'";
}

TEST(InspectCandump, RealJ1939TruckLog) {
  const auto run = run_fieldguard("inspect '" + kSlice + "'");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("candump (guessed)"), std::string::npos) << run.output;
  std::size_t bad = 0;
  const auto r = testing::json_lines(run.output, &bad);
  EXPECT_EQ(bad, 0U);
  ASSERT_EQ(r.size(), 301U);  // a record per frame, and the DM1 its BAM carried
  EXPECT_EQ(summary_number(run.output, "can"), 300);
  EXPECT_EQ(summary_number(run.output, "j1939_dm1"), 1);
  EXPECT_EQ(summary_number(run.output, "j1939_address_claim"), 0);  // none in this log
  EXPECT_EQ(summary_number(run.output, "bam_completed"), 1);
  EXPECT_EQ(summary_number(run.output, "rejected"), 0);
  EXPECT_EQ(summary_number(run.output, "extended"), 300);

  // The first line: (1635188455.020850) can0 18F00E00#821639C4FFFFFFFF
  EXPECT_EQ(r[0].at("type").get<std::string>(), "can");
  EXPECT_EQ(r[0].at("time").get<double>(), 1635188455.020850);
  EXPECT_EQ(r[0].at("iface").get<std::string>(), "can0");
  EXPECT_EQ(r[0].at("id").get<std::string>(), "18F00E00");
  EXPECT_TRUE(r[0].at("extended").get<bool>());
  EXPECT_EQ(r[0].at("dlc").get<long long>(), 8);
  EXPECT_EQ(r[0].at("data").get<std::string>(), "821639C4FFFFFFFF");

  std::size_t eec1 = 0;
  std::size_t ccvs1 = 0;
  std::size_t dm1 = 0;
  for (const auto& f : r) {
    if (f.at("type").get<std::string>() == "j1939_dm1") {
      // The engine's DM1 by BAM (lines 178-252): right after the frame that completed it, at its time.
      ++dm1;
      EXPECT_EQ(f.at("time").get<double>(), 1635188455.718900);
      EXPECT_EQ(f.at("sa").get<long long>(), 0x00);
      EXPECT_TRUE(f.at("transport").get<bool>());
      EXPECT_EQ(f.at("lamps").at("malfunction").get<std::string>(), "on");
      EXPECT_EQ(f.at("lamps").at("protect").get<std::string>(), "not available");
      const auto& d = f.at("dtcs");
      ASSERT_EQ(d.size(), 4U);
      EXPECT_EQ(d[0].at("spn").get<long long>(), 980);
      EXPECT_EQ(d[0].at("fmi").get<long long>(), 9);
      EXPECT_EQ(d[0].at("occurrences").get<long long>(), 126);
      EXPECT_EQ(d[1].at("spn").get<long long>(), 3216);
      EXPECT_EQ(d[1].at("fmi").get<long long>(), 20);
      EXPECT_EQ(d[3].at("spn").get<long long>(), 609);
      EXPECT_EQ(d[3].at("fmi").get<long long>(), 12);
      continue;
    }
    if (f.at("id").get<std::string>() == "0CF00400") {  // EEC1, 100 Hz while the engine idles
      ++eec1;
      EXPECT_EQ(f.at("pgn").get<long long>(), 61444);  // 0xF004
      EXPECT_EQ(f.at("sa").get<long long>(), 0x00);
      EXPECT_EQ(f.at("priority").get<long long>(), 3);
      EXPECT_FALSE(f.contains("da"));                          // PDU2: PF 0xF0 >= 240
    } else if (f.at("id").get<std::string>() == "0CFEF100") {  // CCVS1 at priority 3
      ++ccvs1;
      EXPECT_EQ(f.at("pgn").get<long long>(), 65265);  // 0xFEF1
      EXPECT_EQ(f.at("sa").get<long long>(), 0x00);
      EXPECT_EQ(f.at("priority").get<long long>(), 3);
    } else if (f.at("id").get<std::string>() == "1CECFF00") {  // TP.CM, PDU1 to the global address
      EXPECT_EQ(f.at("pgn").get<long long>(), 0xEC00);
      EXPECT_EQ(f.at("da").get<long long>(), 0xFF);
    }
  }
  EXPECT_EQ(eec1, 84U);
  EXPECT_EQ(ccvs1, 9U);
  EXPECT_EQ(dm1, 1U);
}

// Address claims with their NAME's fields (a vendor's claim printed in its manual, 18EEFF21; a Cannot Claim from the
// null address), a DM1 in one frame, and a DM1 whose bytes do not decode (counted, no record).
TEST(InspectCandump, J1939AddressClaimsAndDiagnostics) {
  TempDir dir;
  const std::string text =
      "(1.000000) can0 18EEFF21#3F426F1A00823CC0\n"
      "(1.100000) can0 18EEFFFE#3F426F1A00823CC0\n"
      "(1.200000) can1 18FECA80#04FF00FFFF01FFFF\n"
      "(1.300000) can1 18FECA80#04FF0102030405FF\n";
  const auto run = run_fieldguard("inspect --format candump " + write(dir, "j1939.log", text));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto r = testing::json_lines(run.output);
  ASSERT_EQ(r.size(), 7U) << run.output;  // 4 frames, 2 claims, 1 DM1
  const auto& claim = r[1];
  EXPECT_EQ(claim.at("type").get<std::string>(), "j1939_address_claim");
  EXPECT_EQ(claim.at("sa").get<long long>(), 0x21);
  EXPECT_FALSE(claim.at("cannot_claim").get<bool>());
  EXPECT_EQ(claim.at("name").get<std::string>(), "C03C82001A6F423F");
  EXPECT_EQ(claim.at("identity_number").get<long long>(), 999999);
  EXPECT_EQ(claim.at("manufacturer_code").get<long long>(), 211);
  EXPECT_EQ(claim.at("function").get<long long>(), 130);
  EXPECT_EQ(claim.at("vehicle_system").get<long long>(), 30);
  EXPECT_EQ(claim.at("industry_group").get<long long>(), 4);
  EXPECT_TRUE(claim.at("arbitrary_address_capable").get<bool>());
  EXPECT_TRUE(r[3].at("cannot_claim").get<bool>());
  const auto& dm1 = r[5];
  EXPECT_EQ(dm1.at("type").get<std::string>(), "j1939_dm1");
  EXPECT_EQ(dm1.at("iface").get<std::string>(), "can1");
  EXPECT_EQ(dm1.at("sa").get<long long>(), 0x80);
  EXPECT_FALSE(dm1.at("transport").get<bool>());
  EXPECT_EQ(dm1.at("lamps").at("amber_warning").get<std::string>(), "on");
  ASSERT_EQ(dm1.at("dtcs").size(), 1U);
  EXPECT_EQ(dm1.at("dtcs")[0].at("spn").get<long long>(), 0x7FF00);
  EXPECT_EQ(dm1.at("dtcs")[0].at("fmi").get<long long>(), 31);
  EXPECT_EQ(summary_number(run.output, "j1939_address_claim"), 2);
  EXPECT_EQ(summary_number(run.output, "j1939_dm1"), 1);
  EXPECT_EQ(summary_number(run.output, "j1939_bad_diagnostic"), 1);
}

TEST(InspectCandump, EveryFrameFormOfTheLogFormat) {
  const std::string text =
      "(1621880457.123456) can0 18FEF100#00FF0000FFFFFFFF\n"      // CCVS1, priority 6
      "(1621880457.123457) can0 0CEF2680#0102\n"                  // Proprietary A to 0x26 from 0x80
      "(1621880457.123458) vcan1 0C820E0F#\n"                     // PGN 33280, DA 0x0E, SA 0x0F; no data
      "(1621880457.123459) can0 123#DEADBEEF\n"                   // 11-bit
      "(1621880457.123460) can0 123#R\n"                          // RTR, length 0
      "(1621880457.123461) can0 7FF#R5 T\n"                       // RTR, length 5, sent (-x)
      "(1621880457.123462) can0 123#11.22.33.44.55.66.77.88_E\n"  // len 8, raw DLC 14
      "(1621880457.123463) can0 123##1112233\n"                   // CAN FD, BRS, 3 bytes
      "(1621880457.123464) can0 20000040#0000000000000000\n"      // error frame: bus-off
      "(1621880457.123465) can0 1FFFFFFF#00 R\r\n";               // CRLF, received (-x)
  TempDir dir;
  const auto run = run_fieldguard("inspect " + write(dir, "forms.log", text));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto r = testing::json_lines(run.output);
  ASSERT_EQ(r.size(), 10U) << run.output;

  EXPECT_EQ(r[0].at("pgn").get<long long>(), 65265);
  EXPECT_EQ(r[0].at("priority").get<long long>(), 6);
  EXPECT_EQ(r[0].at("sa").get<long long>(), 0);
  EXPECT_EQ(r[1].at("pgn").get<long long>(), 0xEF00);
  EXPECT_EQ(r[1].at("da").get<long long>(), 0x26);
  EXPECT_EQ(r[1].at("sa").get<long long>(), 0x80);
  EXPECT_EQ(r[1].at("dlc").get<long long>(), 2);
  EXPECT_EQ(r[2].at("iface").get<std::string>(), "vcan1");
  EXPECT_EQ(r[2].at("pgn").get<long long>(), 33280);
  EXPECT_EQ(r[2].at("da").get<long long>(), 0x0E);
  EXPECT_EQ(r[2].at("sa").get<long long>(), 0x0F);
  EXPECT_EQ(r[2].at("dlc").get<long long>(), 0);
  EXPECT_EQ(r[2].at("data").get<std::string>(), "");

  EXPECT_EQ(r[3].at("id").get<std::string>(), "123");
  EXPECT_FALSE(r[3].at("extended").get<bool>());
  EXPECT_FALSE(r[3].contains("pgn"));
  EXPECT_EQ(r[3].at("data").get<std::string>(), "DEADBEEF");
  EXPECT_TRUE(r[4].at("rtr").get<bool>());
  EXPECT_EQ(r[4].at("dlc").get<long long>(), 0);
  EXPECT_EQ(r[5].at("id").get<std::string>(), "7FF");
  EXPECT_EQ(r[5].at("dlc").get<long long>(), 5);
  EXPECT_EQ(r[5].at("data").get<std::string>(), "");
  EXPECT_EQ(r[5].at("dir").get<std::string>(), "T");
  EXPECT_EQ(r[6].at("data").get<std::string>(), "1122334455667788");
  EXPECT_EQ(r[6].at("len8_dlc").get<long long>(), 14);
  EXPECT_TRUE(r[7].at("fd").get<bool>());
  EXPECT_EQ(r[7].at("fd_flags").get<long long>(), 1);
  EXPECT_EQ(r[7].at("data").get<std::string>(), "112233");
  EXPECT_EQ(r[8].at("type").get<std::string>(), "can_error");
  EXPECT_EQ(r[8].at("id").get<std::string>(), "20000040");
  EXPECT_EQ(r[8].at("error_class").get<long long>(), 0x40);
  EXPECT_EQ(r[9].at("id").get<std::string>(), "1FFFFFFF");
  EXPECT_EQ(r[9].at("dir").get<std::string>(), "R");
  EXPECT_EQ(r[9].at("priority").get<long long>(), 7);
  EXPECT_EQ(summary_number(run.output, "can"), 9);
  EXPECT_EQ(summary_number(run.output, "can_error"), 1);
  EXPECT_EQ(summary_number(run.output, "standard"), 5);
  EXPECT_EQ(summary_number(run.output, "extended"), 4);
}

TEST(InspectCandump, DefaultSpacedOutput) {
  const std::string text =
      "  can0  18FEF100   [8]  00 FF 00 00 FF FF FF FF\n"
      " (1621880457.123456)  can1  123   [4]  DE AD BE EF   '....'\n"
      "  can0  7FF   [3]  remote request\n"
      "  can0  RX B -  0CF00400  [12]  01 02 03 04 05 06 07 08 09 0A 0B 0C\n"
      "  can0  123   [3]  01 02\n"  // one byte short: bad_data
      "\n";
  TempDir dir;
  const auto run = run_fieldguard("inspect " + write(dir, "spaced.txt", text));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("candump (guessed)"), std::string::npos) << run.output;
  const auto r = testing::json_lines(run.output);
  ASSERT_EQ(r.size(), 4U) << run.output;
  EXPECT_TRUE(r[0].at("time").is_null());
  EXPECT_EQ(r[0].at("pgn").get<long long>(), 65265);
  EXPECT_EQ(r[0].at("data").get<std::string>(), "00FF0000FFFFFFFF");
  EXPECT_EQ(r[1].at("time").get<double>(), 1621880457.123456);
  EXPECT_EQ(r[1].at("iface").get<std::string>(), "can1");
  EXPECT_EQ(r[1].at("data").get<std::string>(), "DEADBEEF");
  EXPECT_TRUE(r[2].at("rtr").get<bool>());
  EXPECT_EQ(r[2].at("dlc").get<long long>(), 3);
  EXPECT_TRUE(r[3].at("fd").get<bool>());
  EXPECT_EQ(r[3].at("fd_flags").get<long long>(), 1);
  EXPECT_EQ(r[3].at("dlc").get<long long>(), 12);
  EXPECT_EQ(r[3].at("pgn").get<long long>(), 61444);
  EXPECT_EQ(r[3].at("dir").get<std::string>(), "R");
  EXPECT_EQ(summary_number(run.output, "bad_data"), 1);
  EXPECT_EQ(summary_number(run.output, "blank_lines"), 1);
}

struct BadLine {
  const char* name;
  std::string line;
  const char* reason;
};

TEST(InspectCandump, MalformedLinesAreCountedByReason) {
  const std::vector<BadLine> bad = {
      {"letters_in_time", "(16218x0457.1) can0 123#00", "bad_timestamp"},
      {"two_points", "(1621880457.1.2) can0 123#00", "bad_timestamp"},
      {"date_form", "(2021-05-24) can0 123#00", "bad_timestamp"},
      {"four_digit_id", "(1.5) can0 1234#00", "bad_id"},
      {"eleven_bit_too_big", "(1.5) can0 800#00", "bad_id"},
      {"not_hex", "(1.5) can0 12G#00", "bad_id"},
      {"eff_flag_in_text", "(1.5) can0 98FEF100#00", "bad_id"},
      {"odd_digits", "(1.5) can0 123#0", "bad_data"},
      {"nine_bytes", "(1.5) can0 123#001122334455667788", "bad_data"},
      {"len8_dlc_short", "(1.5) can0 123#0011_E", "bad_data"},
      {"len8_dlc_low", "(1.5) can0 123#0011223344556677_8", "bad_data"},
      {"fd_bad_len", "(1.5) can0 123##0001122334455667788", "bad_data"},
      {"rtr_len_9", "(1.5) can0 123#R9", "bad_data"},
      {"too_long", "(1.5) can0 123#" + std::string(600, '0'), "too_long"},
      {"prose", "hello world", "bad_line"},
      {"no_frame", "(1.5) can0", "bad_line"},
  };
  std::string text = "(1621880457.123456) can0 123#00\n";  // one good line first, so that the guess is candump
  for (const auto& b : bad) text += b.line + "\n";
  TempDir dir;
  const auto run = run_fieldguard("inspect " + write(dir, "bad.log", text));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(testing::json_lines(run.output).size(), 1U) << run.output;
  EXPECT_EQ(summary_number(run.output, "bad_timestamp"), 3);
  EXPECT_EQ(summary_number(run.output, "bad_id"), 4);
  EXPECT_EQ(summary_number(run.output, "bad_data"), 6);
  EXPECT_EQ(summary_number(run.output, "too_long"), 1);
  EXPECT_EQ(summary_number(run.output, "bad_line"), 2);
  EXPECT_EQ(summary_number(run.output, "lines"), static_cast<long long>(bad.size() + 1));

  // Each alone, given explicitly: rejected for its own reason.
  for (const auto& b : bad) {
    const auto one = run_fieldguard("inspect --format candump " + write(dir, std::string(b.name) + ".log", b.line));
    EXPECT_EQ(one.exit_code, 0) << b.name;
    EXPECT_EQ(summary_number(one.output, b.reason), 1) << b.name << "\n" << one.output;
    EXPECT_EQ(summary_number(one.output, "records"), 0) << b.name;
  }
}

}  // namespace
}  // namespace fieldguard
