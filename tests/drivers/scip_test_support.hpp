#pragma once
// Test scaffolding for the SCIP 2.0 tests: a reply encoder written from protocols.md §3.2-§3.5, independent of
// the library's code (there is no real SCIP capture: realdata/INDEX.txt).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/drivers/scip.hpp"

namespace fieldguard::scip::test {

// (sum of the bytes) & 0x3F + 0x30.
inline char sum(std::string_view s) {
  unsigned t = 0;
  for (char c : s) t += static_cast<unsigned char>(c);
  return static_cast<char>((t & 0x3FU) + 0x30U);
}

// `n` characters of 6 bits each, most significant first, each + 0x30.
inline std::string enc(std::uint32_t v, int n) {
  std::string s;
  for (int i = n - 1; i >= 0; --i) s += static_cast<char>(((v >> (6 * i)) & 0x3FU) + 0x30U);
  return s;
}

// A payload or status line: body, its check character, LF.
inline std::string line(std::string_view body) { return std::string(body) + sum(body) + "\n"; }

// "LABEL:value;S" + LF, S over "LABEL:value" (the captured form) or over "LABEL:value;" (also accepted).
inline std::string info_line(std::string_view label, std::string_view value, bool sum_with_semicolon = false) {
  const std::string body = std::string(label) + ":" + std::string(value);
  return body + ";" + sum(sum_with_semicolon ? body + ";" : body) + "\n";
}

// Data cut into lines of 64 characters, each with its check character and LF.
inline std::string data_lines(std::string_view data) {
  std::string out;
  for (std::size_t i = 0; i < data.size(); i += 64) out += line(data.substr(i, 64));
  return out;
}

// A complete scan reply: echo, status, timestamp, 3-character (or 2-character) values, interleaved with
// intensities when given, then the empty line.
inline std::string scan_reply(std::string_view echo, std::string_view status, std::uint32_t timestamp,
                              const std::vector<std::uint32_t>& ranges,
                              const std::vector<std::uint32_t>& intensities = {}, int width = 3) {
  std::string data;
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    data += enc(ranges[i], width);
    if (!intensities.empty()) data += enc(intensities[i], width);
  }
  return std::string(echo) + "\n" + line(status) + line(enc(timestamp, 4)) + data_lines(data) + "\n";
}

// A reply of status and text lines (for VV, PP, II, BM, QT ...).
inline std::string simple_reply(std::string_view echo, std::string_view status, const std::string& lines = {}) {
  return std::string(echo) + "\n" + line(status) + lines + "\n";
}

// The UTM-30LX-EW's PP reply (protocols.md §3.1, §3.3).
inline std::string utm_pp_reply() {
  return simple_reply("PP", "00",
                      info_line("MODL", "UTM-30LX-EW") + info_line("DMIN", "23") + info_line("DMAX", "60000") +
                          info_line("ARES", "1440") + info_line("AMIN", "0") + info_line("AMAX", "1080") +
                          info_line("AFRT", "540") + info_line("SCAN", "2400"));
}

inline std::string utm_vv_reply() {
  return simple_reply("VV", "00",
                      info_line("VEND", "Hokuyo Automatic Co.,Ltd.") + info_line("PROD", "SOKUIKI Sensor UTM-30LX-EW") +
                          info_line("FIRM", "1.1.02(19/Dec./2012)") + info_line("PROT", "SCIP 2.0") +
                          info_line("SERI", "H1234567"));
}

inline std::string utm_ii_reply() {
  return simple_reply("II", "00",
                      info_line("MODL", "UTM-30LX-EW") + info_line("LASR", "OFF") + info_line("SCSP", "2400") +
                          info_line("MESM", "Idle") + info_line("SBPS", "Ethernet 100 [Mbps]") +
                          info_line("TIME", "0A1B2C") + info_line("STAT", "Stable 000 no error."));
}

// A deterministic 1081-step range pattern with a few error codes (values below DMIN = 23) in it.
inline std::vector<std::uint32_t> range_pattern(std::size_t n, std::uint32_t seed = 7) {
  std::vector<std::uint32_t> r(n);
  for (std::size_t i = 0; i < n; ++i) {
    r[i] = (static_cast<std::uint32_t>(i) * 9973U + seed * 131U) % 65000U;
    if (i % 97 == 3) r[i] = static_cast<std::uint32_t>(i % 23);  // error code
  }
  return r;
}

inline std::vector<Reply> parse_all(ReplyParser& p, std::string_view bytes) {
  std::vector<Reply> out;
  p.push(bytes, out);
  return out;
}

}  // namespace fieldguard::scip::test
