// `fieldguard inspect --format candump`: SocketCAN frames as candump writes them (protocols.md §7.2): the log
// format of `candump -l` / `candump -L`, "(1621880457.123456) can0 18FEF100#00FF0000FFFFFFFF", and candump's
// default output, "(1621880457.123456)  can0  18FEF100   [8]  00 FF 00 00 FF FF FF FF" (timestamp optional).
// One record per frame; 29-bit ids also as J1939 fields (protocols.md §7.4). A line that is neither form, or a
// form with a bad part, yields no record and is counted by its first bad part.
// J1939 network management and diagnostics get a record of their own after their frame's: each Address Claimed
// (or Cannot Claim) with its NAME's fields ("j1939_address_claim"), each DM1 / DM2 with its lamps and DTCs
// ("j1939_dm1" / "j1939_dm2"), in one frame or reassembled from the broadcast transport protocol (BAM, per
// interface and source), and any other message that BAM completes ("j1939_bam", its PGN and bytes).

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdio>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/output/j1939.hpp"
#include "inspect/inspect_format.hpp"
#include "inspect/json_line.hpp"

namespace fieldguard::app::inspect {
namespace {

constexpr std::size_t kMaxLine = 512;            // an FD frame of 64 bytes in the spaced form with ASCII is ~330
constexpr std::uint32_t kErrFlag = 0x20000000U;  // CAN_ERR_FLAG
constexpr std::uint32_t kEffMask = 0x1FFFFFFFU;
constexpr std::uint32_t kSffMask = 0x7FFU;
constexpr std::size_t kMaxClassicLen = 8;
constexpr std::size_t kMaxFdLen = 64;

enum class LineError : std::uint8_t { BadTimestamp, BadId, BadData, TooLong, BadLine };
constexpr std::array<const char*, 5> kLineErrorNames = {"bad_timestamp", "bad_id", "bad_data", "too_long", "bad_line"};

struct Frame {
  std::optional<double> time_s;
  std::string_view iface;
  std::uint32_t id = 0;  // without flags, except CAN_ERR_FLAG on error frames (as candump prints them)
  bool extended = false;
  bool error_frame = false;
  bool rtr = false;
  bool fd = false;
  std::uint8_t fd_flags = 0;
  std::optional<std::uint8_t> len8_dlc;  // raw DLC 9..15 of an 8-byte classic frame ("_E")
  char dir = 0;                          // 'R' / 'T' (candump -x), 0 if absent
  std::size_t len = 0;
  std::array<std::uint8_t, kMaxFdLen> data{};
};

using Parsed = Expected<Frame, LineError>;

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> t;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) t.push_back(line.substr(start, i - start));
  }
  return t;
}

std::optional<std::uint32_t> hex_value(std::string_view s) {
  std::uint32_t v = 0;
  if (s.empty()) return std::nullopt;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v, 16);
  if (r.ec != std::errc{} || r.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

// "(1621880457.123456)": seconds, digits with one optional point.
std::optional<double> timestamp(std::string_view tok) {
  if (tok.size() < 3 || tok.front() != '(' || tok.back() != ')') return std::nullopt;
  const std::string_view inner = tok.substr(1, tok.size() - 2);
  std::size_t points = 0;
  for (const char c : inner) {
    if (c == '.') {
      ++points;
    } else if (c < '0' || c > '9') {
      return std::nullopt;
    }
  }
  if (points > 1 || inner.front() == '.' || inner.back() == '.') return std::nullopt;
  double v = 0.0;
  const auto r = std::from_chars(inner.data(), inner.data() + inner.size(), v);
  if (r.ec != std::errc{} || r.ptr != inner.data() + inner.size()) return std::nullopt;
  return v;
}

// 3 hex digits: an 11-bit id; 8: a 29-bit id, or an error frame when CAN_ERR_FLAG is set (can-utils lib.c).
bool read_id(std::string_view s, Frame& f) {
  const auto v = hex_value(s);
  if (!v) return false;
  if (s.size() == 3) {
    if (*v > kSffMask) return false;
    f.id = *v;
    return true;
  }
  if (s.size() != 8) return false;
  if ((*v & kErrFlag) != 0) {
    if ((*v & ~(kErrFlag | kEffMask)) != 0) return false;
    f.error_frame = true;
  } else if (*v > kEffMask) {
    return false;  // RTR / EFF flag bits are not written into the id text
  } else {
    f.extended = true;
  }
  f.id = *v;
  return true;
}

// Hex pairs, '.' allowed between bytes (can-utils lib.c); at most `max` bytes.
bool read_hex_bytes(std::string_view s, std::size_t max, Frame& f) {
  f.len = 0;
  std::size_t i = 0;
  while (i < s.size()) {
    if (s[i] == '.') {
      ++i;
      continue;
    }
    if (i + 1 >= s.size() || f.len >= max) return false;
    const auto v = hex_value(s.substr(i, 2));
    if (!v) return false;
    f.data[f.len++] = static_cast<std::uint8_t>(*v);
    i += 2;
  }
  return true;
}

bool valid_fd_len(std::size_t n) {
  return n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64;
}

// "ID#DATA", "ID#R", "ID#R5", "ID#DATA_E", "ID##FDATA".
Parsed log_frame(std::string_view tok, Frame f) {
  const std::size_t hash = tok.find('#');
  if (!read_id(tok.substr(0, hash), f)) return Unexpected{LineError::BadId};
  std::string_view rest = tok.substr(hash + 1);
  if (!rest.empty() && rest.front() == '#') {
    f.fd = true;
    const auto flags = hex_value(rest.substr(1, 1));
    if (!flags || !read_hex_bytes(rest.substr(2), kMaxFdLen, f) || !valid_fd_len(f.len)) {
      return Unexpected{LineError::BadData};
    }
    f.fd_flags = static_cast<std::uint8_t>(*flags);
    return f;
  }
  if (!rest.empty() && (rest.front() == 'R' || rest.front() == 'r')) {
    f.rtr = true;
    rest.remove_prefix(1);
    if (rest.empty()) return f;
    if (rest.size() != 1 || rest[0] < '0' || rest[0] > '8') return Unexpected{LineError::BadData};
    f.len = static_cast<std::size_t>(rest[0] - '0');
    return f;
  }
  const std::size_t underscore = rest.find('_');
  if (!read_hex_bytes(rest.substr(0, underscore), kMaxClassicLen, f)) return Unexpected{LineError::BadData};
  if (underscore != std::string_view::npos) {
    const auto dlc = hex_value(rest.substr(underscore + 1));
    if (rest.size() != underscore + 2 || !dlc || *dlc < 9 || f.len != kMaxClassicLen) {
      return Unexpected{LineError::BadData};
    }
    f.len8_dlc = static_cast<std::uint8_t>(*dlc);
  }
  return f;
}

// "[8]" (classic) or "[08]", "[12]" (CAN FD prints two digits).
std::optional<std::size_t> bracket_len(std::string_view tok, bool& fd) {
  if (tok.size() < 3 || tok.size() > 4 || tok.front() != '[' || tok.back() != ']') return std::nullopt;
  std::size_t n = 0;
  for (const char c : tok.substr(1, tok.size() - 2)) {
    if (c < '0' || c > '9') return std::nullopt;
    n = n * 10 + static_cast<std::size_t>(c - '0');
  }
  fd = tok.size() == 4;
  return n;
}

// After the interface: [RX|TX f f] ID [n] bytes... | "remote request" ['ascii'] [ERRORFRAME ...].
// `i` is the token after the interface; the caller checked that the "[n]" token is where it should be.
Parsed spaced_frame(const std::vector<std::string_view>& t, std::size_t i, bool with_dir, Frame f) {
  std::uint8_t flags = 0;
  if (with_dir) {
    f.dir = t[i][0] == 'R' ? 'R' : 'T';
    flags = static_cast<std::uint8_t>((t[i + 1] == "B" ? 0x01 : 0) | (t[i + 2] == "E" ? 0x02 : 0));
    i += 3;
  }
  if (!read_id(t[i], f)) return Unexpected{LineError::BadId};
  const auto n = bracket_len(t[i + 1], f.fd);
  i += 2;
  if (f.fd) f.fd_flags = flags;
  if (!n || *n > (f.fd ? kMaxFdLen : kMaxClassicLen) || (f.fd && !valid_fd_len(*n))) {
    return Unexpected{LineError::BadData};
  }
  if (i + 1 < t.size() && t[i] == "remote" && t[i + 1] == "request") {
    f.rtr = true;
    f.len = *n;
    i += 2;
  } else {
    f.len = 0;
    for (; i < t.size() && f.len < *n; ++i) {
      const auto v = t[i].size() == 2 ? hex_value(t[i]) : std::nullopt;
      if (!v) return Unexpected{LineError::BadData};
      f.data[f.len++] = static_cast<std::uint8_t>(*v);
    }
    if (f.len != *n) return Unexpected{LineError::BadData};
  }
  if (i < t.size() && t[i].front() != '\'' && t[i] != "ERRORFRAME") return Unexpected{LineError::BadData};
  return f;
}

bool is_bracket(std::string_view tok) {
  bool fd = false;
  return bracket_len(tok, fd).has_value();
}

Parsed parse_line(std::string_view line) {
  const auto t = split(line);
  std::size_t i = 0;
  const bool timed = !t.empty() && t[0].front() == '(';
  if (timed) i = 1;
  // Which form: "IFACE ID#..." [R|T], or "IFACE [RX|TX f f] ID [n] ...".
  const bool log_form = t.size() >= i + 2 && t.size() <= i + 3 && t[i + 1].find('#') != std::string_view::npos &&
                        (t.size() == i + 2 || t[i + 2] == "R" || t[i + 2] == "T");
  const bool with_dir =
      !log_form && t.size() >= i + 6 && (t[i + 1] == "RX" || t[i + 1] == "TX") && is_bracket(t[i + 5]);
  const bool spaced_form = with_dir || (!log_form && t.size() >= i + 3 && is_bracket(t[i + 2]));
  if (!log_form && !spaced_form) return Unexpected{LineError::BadLine};
  Frame f;
  if (timed) {
    f.time_s = timestamp(t[0]);
    if (!f.time_s) return Unexpected{LineError::BadTimestamp};
  }
  f.iface = t[i];
  if (spaced_form) return spaced_frame(t, i + 1, with_dir, f);
  if (t.size() == i + 3) f.dir = t[i + 2][0];
  return log_frame(t[i + 1], f);
}

std::string hex_id(const Frame& f) {
  std::array<char, 16> buf{};
  std::snprintf(buf.data(), buf.size(), f.extended || f.error_frame ? "%08X" : "%03X", unsigned{f.id});
  return buf.data();
}

std::string record(const Frame& f) {
  const std::string data = f.rtr ? std::string() : hex_upper(std::span<const std::uint8_t>(f.data.data(), f.len));
  JsonLine j;
  j.field("type", f.error_frame ? "can_error" : "can").field("time", f.time_s);
  j.field("iface", f.iface).field("id", hex_id(f));
  if (f.error_frame) {
    j.field("error_class", f.id & kEffMask);
  } else {
    j.boolean("extended", f.extended);
  }
  j.field("dlc", f.len).field("data", data);
  if (f.extended) {
    // J1939 (protocols.md §7.4): priority 28-26, EDP 25, DP 24, PF 23-16, PS 15-8, SA 7-0.
    const std::uint32_t pf = (f.id >> 16) & 0xFFU;
    const std::uint32_t ps = (f.id >> 8) & 0xFFU;
    const std::uint32_t pgn = (((f.id >> 24) & 0x3U) << 16) | (pf << 8) | (pf >= 240 ? ps : 0U);
    j.field("priority", (f.id >> 26) & 0x7U).field("pgn", pgn);
    if (pf < 240) j.field("da", ps);
    j.field("sa", f.id & 0xFFU);
  }
  if (f.rtr) j.boolean("rtr", true);
  if (f.fd) j.boolean("fd", true).field("fd_flags", f.fd_flags);
  if (f.len8_dlc) j.field("len8_dlc", *f.len8_dlc);
  if (f.dir != 0) j.letter("dir", f.dir);
  return std::move(j).str();
}

namespace j1939 = output::j1939;

JsonLine j1939_head(const char* type, const Frame& f, std::uint8_t source) {
  JsonLine j;
  j.field("type", type).field("time", f.time_s).field("iface", f.iface).field("sa", source);
  return j;
}

std::string claim_record(const Frame& f, std::uint8_t source, std::uint64_t v) {
  const j1939::Name n = j1939::Name::from_value(v);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llX", static_cast<unsigned long long>(v));
  JsonLine j = j1939_head("j1939_address_claim", f, source);
  j.boolean("cannot_claim", source == j1939::kNullAddress).field("name", std::string_view(hex));
  j.field("identity_number", n.identity_number).field("manufacturer_code", n.manufacturer_code);
  j.field("ecu_instance", n.ecu_instance).field("function_instance", n.function_instance);
  j.field("function", n.function).field("vehicle_system", n.vehicle_system);
  j.field("vehicle_system_instance", n.vehicle_system_instance).field("industry_group", n.industry_group);
  j.boolean("arbitrary_address_capable", n.arbitrary_address_capable);
  return std::move(j).str();
}

// A DM1 / DM2 record, or nullopt when its bytes do not decode (counted by the caller).
std::optional<std::string> diagnostic_record(const Frame& f, std::uint8_t source, std::uint32_t pgn,
                                             std::span<const std::uint8_t> data, bool transport) {
  const auto d = j1939::decode_diagnostic(data);
  if (!d) return std::nullopt;
  JsonLine j = j1939_head(pgn == j1939::kPgnDm1 ? "j1939_dm1" : "j1939_dm2", f, source);
  JsonLine lamps;
  lamps.field("malfunction", j1939::to_string(d->lamps.malfunction))
      .field("red_stop", j1939::to_string(d->lamps.red_stop))
      .field("amber_warning", j1939::to_string(d->lamps.amber_warning))
      .field("protect", j1939::to_string(d->lamps.protect));
  j.object("lamps", std::move(lamps));
  JsonLine::Json dtcs = JsonLine::Json::array();
  for (const j1939::Dtc& t : d->dtcs) dtcs.push_back({{"spn", t.spn}, {"fmi", t.fmi}, {"occurrences", t.occurrences}});
  j.value("dtcs", std::move(dtcs)).boolean("transport", transport);
  return std::move(j).str();
}

// The J1939 records a frame gives (none for most), and their counts.
class J1939Reader {
 public:
  void take(const Frame& f, Output& out, Summary& summary) {
    if (!f.extended || f.error_frame || f.rtr || f.fd || f.len > 8) return;
    output::CanFrame c;
    c.id = f.id & kEffMask;
    c.len = static_cast<std::uint8_t>(f.len);
    std::copy_n(f.data.begin(), f.len, c.data.begin());
    const output::J1939Fields id = output::j1939_fields(c.id);
    const std::span<const std::uint8_t> data(c.data.data(), c.len);
    if (id.pgn == j1939::kPgnAddressClaimed && c.len == 8) {
      out.line(claim_record(f, id.source, j1939::name_from_bytes(std::span<const std::uint8_t, 8>(c.data))));
      ++summary.kinds["j1939_address_claim"];
    } else if ((id.pgn == j1939::kPgnDm1 || id.pgn == j1939::kPgnDm2) && c.len == 8) {
      diagnostic(f, id.source, id.pgn, data, false, out, summary);
    }
    auto& rx = receivers_[std::string(f.iface)];
    if (auto m = rx.feed(c, f.time_s.value_or(0.0))) {
      if (m->pgn == j1939::kPgnDm1 || m->pgn == j1939::kPgnDm2) {
        diagnostic(f, m->source, m->pgn, m->data, true, out, summary);
      } else {
        JsonLine j = j1939_head("j1939_bam", f, m->source);
        j.field("pgn", m->pgn).field("size", m->data.size()).field("data", hex_upper(m->data));
        out.line(std::move(j).str());
        ++summary.kinds["j1939_bam"];
      }
    }
  }

  void finish(Summary& summary) const {
    j1939::BamReceiver::Counters c;
    for (const auto& [iface, rx] : receivers_) {
      c.completed += rx.counters().completed;
      c.dropped_sequence += rx.counters().dropped_sequence;
      c.dropped_restart += rx.counters().dropped_restart;
      c.dropped_timeout += rx.counters().dropped_timeout;
      c.bad_announcements += rx.counters().bad_announcements;
    }
    summary.extra.emplace_back("bam_completed", c.completed);
    summary.rejections.emplace_back("bam_out_of_sequence", c.dropped_sequence);
    summary.rejections.emplace_back("bam_announced_again", c.dropped_restart);
    summary.rejections.emplace_back("bam_timed_out", c.dropped_timeout);
    summary.rejections.emplace_back("bam_bad_announcement", c.bad_announcements);
    summary.rejections.emplace_back("j1939_bad_diagnostic", bad_diagnostic_);
  }

 private:
  void diagnostic(const Frame& f, std::uint8_t source, std::uint32_t pgn, std::span<const std::uint8_t> data,
                  bool transport, Output& out, Summary& summary) {
    if (auto r = diagnostic_record(f, source, pgn, data, transport)) {
      out.line(*r);
      ++summary.kinds[pgn == j1939::kPgnDm1 ? "j1939_dm1" : "j1939_dm2"];
    } else {
      ++bad_diagnostic_;
    }
  }

  std::map<std::string, j1939::BamReceiver> receivers_;
  std::uint64_t bad_diagnostic_ = 0;
};

std::string_view trim_cr(std::string_view line) {
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.remove_suffix(1);
  return line;
}

bool blank(std::string_view line) {
  return std::all_of(line.begin(), line.end(), [](char c) { return c == ' ' || c == '\t' || c == '\r'; });
}

}  // namespace

bool looks_like_candump(ByteSpan head) {
  // The first non-blank line is a frame in one of the two forms (a line cut by the end of the head is not judged,
  // unless it is the whole head: a one-line file).
  std::size_t start = 0;
  while (start < head.size()) {
    const auto nl = std::find(head.begin() + static_cast<std::ptrdiff_t>(start), head.end(), std::uint8_t{'\n'});
    const std::string line(head.begin() + static_cast<std::ptrdiff_t>(start), nl);
    if (nl == head.end() && start > 0) return false;
    if (!blank(line)) return line.size() <= kMaxLine && parse_line(trim_cr(line)).has_value();
    start = static_cast<std::size_t>(nl - head.begin()) + 1;
  }
  return false;
}

void inspect_candump(Capture& in, Output& out, Summary& summary) {
  summary.kinds["can"] = 0;
  summary.kinds["can_error"] = 0;
  for (const char* k : {"j1939_address_claim", "j1939_dm1", "j1939_dm2", "j1939_bam"}) summary.kinds[k] = 0;
  std::array<std::uint64_t, kLineErrorNames.size()> errors{};
  std::uint64_t lines = 0;
  std::uint64_t blank_lines = 0;
  std::uint64_t standard = 0;
  std::uint64_t extended = 0;
  std::string line;
  bool too_long = false;
  J1939Reader j1939;
  const auto take = [&] {
    ++lines;
    if (too_long) {
      ++errors[static_cast<std::size_t>(LineError::TooLong)];
    } else if (blank(line)) {
      ++blank_lines;
    } else if (const auto f = parse_line(trim_cr(line))) {
      ++summary.kinds[f->error_frame ? "can_error" : "can"];
      if (!f->error_frame) ++(f->extended ? extended : standard);
      out.line(record(*f));
      j1939.take(*f, out, summary);
    } else {
      ++errors[static_cast<std::size_t>(f.error())];
    }
    line.clear();
    too_long = false;
  };
  in.for_each_chunk([&](ByteSpan chunk) {
    for (const std::uint8_t b : chunk) {
      if (b == '\n') {
        take();
      } else if (line.size() >= kMaxLine) {
        too_long = true;
      } else {
        line += static_cast<char>(b);
      }
    }
  });
  if (!line.empty() || too_long) take();  // the last line, without its newline
  for (std::size_t k = 0; k < errors.size(); ++k) summary.rejections.emplace_back(kLineErrorNames[k], errors[k]);
  summary.extra = {{"lines", lines}, {"blank_lines", blank_lines}, {"standard", standard}, {"extended", extended}};
  j1939.finish(summary);
}

}  // namespace fieldguard::app::inspect
