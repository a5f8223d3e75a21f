#include "fieldguard/output/dbc.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdio>
#include <stdexcept>
#include <string_view>
#include <utility>
#include <vector>

namespace fieldguard::output {
namespace {

constexpr std::string_view kNode = "FIELDGUARD";
constexpr std::string_view kController = "STEERING_CONTROLLER";
constexpr std::uint32_t kDbcExtendedFlag = 0x80000000U;  // BO_ ids of 29-bit frames (protocols.md §7.3)

// Shortest text that reads back as the same double: the DBC stays stable and exact.
std::string num(double v) {
  std::array<char, 32> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return {buf.data(), r.ptr};
}

std::string hex2(unsigned v) {
  std::array<char, 8> buf{};
  std::snprintf(buf.data(), buf.size(), "0x%02X", v);
  return buf.data();
}

std::string quoted(std::string_view s) {
  if (s.find('"') != std::string_view::npos) throw std::logic_error("dbc: a layout comment contains a double quote");
  return "\"" + std::string(s) + "\"";
}

// The range the DBC declares: the signal's own, widened to every raw value its value table names (a "no obstacle"
// 65535 beyond the distances the encoder sends), so that no tool reads a named value as out of range.
std::pair<double, double> declared_range(const Signal& s) {
  double lo = s.min;
  double hi = s.max;
  for (const ValueName& v : s.values) {
    const double phys = static_cast<double>(v.raw) * s.scale + s.offset;
    lo = std::min(lo, phys);
    hi = std::max(hi, phys);
  }
  return {lo, hi};
}

std::string sg_line(const Signal& s, const std::string& name, const std::string& mux) {
  const auto [lo, hi] = declared_range(s);
  return " SG_ " + name + mux + " : " + std::to_string(s.start_bit) + "|" + std::to_string(s.length) + "@" +
         (s.order == ByteOrder::Intel ? "1" : "0") + (s.is_signed ? "-" : "+") + " (" + num(s.scale) + "," +
         num(s.offset) + ") [" + num(lo) + "|" + num(hi) + "] " + quoted(s.unit) + " " + std::string(kController) +
         "\n";
}

bool multiplexed(const MessageLayout& m, const Signal& s) { return !m.multiplexor.empty() && s.name != m.multiplexor; }

// Every value the multiplexor can take.
unsigned mux_values(const MessageLayout& m) {
  for (const Signal& s : m.signals) {
    if (s.name == m.multiplexor) return 1U << s.length;
  }
  throw std::logic_error("dbc: multiplexor " + std::string(m.multiplexor) + " is not a signal of " +
                         std::string(m.name));
}

std::string view_name(const Signal& s, unsigned v) { return std::string(s.name) + "_" + std::to_string(v); }

// The names a signal has in the DBC: itself, or one per multiplexor value.
std::vector<std::string> dbc_names(const MessageLayout& m, const Signal& s) {
  if (!multiplexed(m, s)) return {std::string(s.name)};
  std::vector<std::string> out;
  for (unsigned v = 0; v < mux_values(m); ++v) out.push_back(view_name(s, v));
  return out;
}

}  // namespace

std::string dbc_text(const CanParams& params) {
  std::string o;
  o += "VERSION \"\"\n\n";
  o += "NS_ :\n\tCM_\n\tBA_DEF_\n\tBA_\n\tVAL_\n\tBA_DEF_DEF_\n\n";
  o += "BS_:\n\n";
  o += "BU_: " + std::string(kNode) + " " + std::string(kController) + "\n\n";

  std::array<std::uint32_t, kMessageCount> dbc_ids{};
  for (const MessageLayout& m : message_layouts()) {
    const std::uint32_t id = message_id(params, m.id) | kDbcExtendedFlag;
    dbc_ids[static_cast<std::size_t>(m.id)] = id;
    o += "BO_ " + std::to_string(id) + " " + std::string(m.name) + ": " + std::to_string(m.dlc) + " " +
         std::string(kNode) + "\n";
    for (const Signal& s : m.signals) {
      if (!multiplexed(m, s)) {
        o += sg_line(s, std::string(s.name), s.name == m.multiplexor ? " M" : "");
        continue;
      }
      for (unsigned v = 0; v < mux_values(m); ++v) o += sg_line(s, view_name(s, v), " m" + std::to_string(v));
    }
    o += "\n";
  }

  o += "CM_ " +
       quoted(
           "fieldguard obstacle detection to the steering controller. Generated from src/output/can_layout.cpp "
           "(tools/fieldguard-dbc); do not edit. 29-bit J1939 identifiers: BO_ ids have bit 31 set (id | "
           "0x80000000). Source address " +
           hex2(params.source_address) + ", steering controller " + hex2(params.controller_address) +
           ". Signals are little-endian (Intel) as J1939 sends multi-byte parameters.") +
       ";\n";
  o += "CM_ BU_ " + std::string(kNode) + " " +
       quoted("The fieldguard daemon, J1939 address " + hex2(params.source_address)) + ";\n";
  o += "CM_ BU_ " + std::string(kController) + " " +
       quoted("Auto-steer controller, J1939 address " + hex2(params.controller_address)) + ";\n";
  for (const MessageLayout& m : message_layouts()) {
    const std::string id = std::to_string(dbc_ids[static_cast<std::size_t>(m.id)]);
    o += "CM_ BO_ " + id + " " + quoted(m.comment) + ";\n";
    for (const Signal& s : m.signals) {
      if (s.comment.empty()) continue;
      for (const std::string& n : dbc_names(m, s)) {
        o += "CM_ SG_ ";
        o += id;
        o += " " + n + " " + quoted(s.comment) + ";\n";
      }
    }
  }

  o += "BA_DEF_ \"ProtocolType\" STRING ;\n";
  o += "BA_DEF_ BO_ \"GenMsgCycleTime\" INT 0 65535;\n";
  o += "BA_DEF_ BO_ \"VFrameFormat\" ENUM \"StandardCAN\",\"ExtendedCAN\",\"reserved\",\"J1939PG\";\n";
  o += "BA_DEF_DEF_ \"ProtocolType\" \"\";\n";
  o += "BA_DEF_DEF_ \"GenMsgCycleTime\" 0;\n";
  o += "BA_DEF_DEF_ \"VFrameFormat\" \"J1939PG\";\n";
  o += "BA_ \"ProtocolType\" \"J1939\";\n";
  for (const MessageLayout& m : message_layouts()) {
    const std::string id = std::to_string(dbc_ids[static_cast<std::size_t>(m.id)]);
    o += "BA_ \"VFrameFormat\" BO_ " + id + " 3;\n";
    if (m.cycle_ms != 0) o += "BA_ \"GenMsgCycleTime\" BO_ " + id + " " + std::to_string(m.cycle_ms) + ";\n";
  }

  for (const MessageLayout& m : message_layouts()) {
    const std::string id = std::to_string(dbc_ids[static_cast<std::size_t>(m.id)]);
    for (const Signal& s : m.signals) {
      if (s.values.empty()) continue;
      for (const std::string& n : dbc_names(m, s)) {
        o += "VAL_ ";
        o += id;
        o += " " + n;
        for (const ValueName& v : s.values) o += " " + std::to_string(v.raw) + " " + quoted(v.name);
        o += " ;\n";
      }
    }
  }
  return o;
}

}  // namespace fieldguard::output
