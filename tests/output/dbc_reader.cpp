#include "output/dbc_reader.hpp"

#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace fieldguard::test::dbc {
namespace {

const std::regex kBo(R"re(^BO_\s+(\d+)\s+(\w+)\s*:\s*(\d+)\s+(\w+)\s*$)re");
// SG_ name [M | mN] : start|len@order sign (factor,offset) [min|max] "unit" receivers
const std::regex kSg(
    R"re(^\s*SG_\s+(\w+)\s*(?:(M|m\d+)\s*)?:\s*(\d+)\|(\d+)@([01])([+-])\s*\(([^,]+),([^)]+)\)\s*\[([^|]+)\|([^\]]+)\]\s*"([^"]*)".*$)re");
const std::regex kVal(R"re(^VAL_\s+(\d+)\s+(\w+)\s+(.*);\s*$)re");
const std::regex kValPair(R"re((-?\d+)\s+"([^"]*)")re");
const std::regex kCmBo(R"re(^CM_\s+BO_\s+(\d+)\s+"([^"]*)"\s*;\s*$)re");
const std::regex kCycle(R"re(^BA_\s+"GenMsgCycleTime"\s+BO_\s+(\d+)\s+(\d+)\s*;\s*$)re");

Message* find(std::vector<Message>& ms, std::uint32_t dbc_id) {
  for (auto& m : ms) {
    if (m.dbc_id == dbc_id) return &m;
  }
  return nullptr;
}

std::uint32_t to_u32(const std::string& s) { return static_cast<std::uint32_t>(std::stoul(s)); }

bool bit_at(std::span<const std::uint8_t> data, unsigned byte, unsigned bit) {
  if (byte >= data.size()) throw std::out_of_range("dbc: signal reaches past the frame's data");
  return ((data[byte] >> bit) & 1U) != 0;
}

}  // namespace

const Signal& Message::signal(std::string_view n) const {
  for (const auto& s : signals) {
    if (s.name == n) return s;
  }
  throw std::out_of_range("dbc: no signal " + std::string(n) + " in " + name);
}

const Message* Database::by_can_id(std::uint32_t id) const {
  for (const auto& m : messages) {
    if (m.can_id() == id) return &m;
  }
  return nullptr;
}

const Message& Database::by_name(std::string_view n) const {
  for (const auto& m : messages) {
    if (m.name == n) return m;
  }
  throw std::out_of_range("dbc: no message " + std::string(n));
}

Database parse(std::string_view text) {
  Database db;
  std::istringstream in{std::string(text)};
  std::string line;
  int line_no = 0;
  Message* current = nullptr;
  const auto fail = [&](const std::string& what) {
    throw std::runtime_error("line " + std::to_string(line_no) + ": " + what + ": " + line);
  };
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::smatch m;
    if (line.rfind("BO_ ", 0) == 0) {
      if (!std::regex_match(line, m, kBo)) fail("unreadable BO_");
      Message msg;
      msg.dbc_id = to_u32(m[1]);
      msg.name = m[2];
      msg.dlc = to_u32(m[3]);
      msg.transmitter = m[4];
      db.messages.push_back(msg);
      current = &db.messages.back();
    } else if (const auto first = line.find_first_not_of(" \t");
               first != std::string::npos && line.compare(first, 4, "SG_ ") == 0) {
      if (current == nullptr) fail("SG_ outside a BO_");
      if (!std::regex_match(line, m, kSg)) fail("unreadable SG_");
      Signal s;
      s.name = m[1];
      s.multiplexor = m[2] == "M";
      if (m[2].length() > 1) s.mux_value = to_u32(m[2].str().substr(1));
      s.start_bit = to_u32(m[3]);
      s.length = to_u32(m[4]);
      s.little_endian = m[5] == "1";
      s.is_signed = m[6] == "-";
      s.factor = std::stod(m[7]);
      s.offset = std::stod(m[8]);
      s.min = std::stod(m[9]);
      s.max = std::stod(m[10]);
      s.unit = m[11];
      current->signals.push_back(s);
    } else if (line.rfind("VAL_ ", 0) == 0) {
      if (!std::regex_match(line, m, kVal)) fail("unreadable VAL_");
      Message* msg = find(db.messages, to_u32(m[1]));
      if (msg == nullptr) fail("VAL_ for an unknown message");
      Signal* sig = nullptr;
      for (auto& s : msg->signals) {
        if (s.name == m[2]) sig = &s;
      }
      if (sig == nullptr) fail("VAL_ for an unknown signal");
      const std::string pairs = m[3];
      for (std::sregex_iterator it(pairs.begin(), pairs.end(), kValPair), end; it != end; ++it) {
        sig->values[std::stoll((*it)[1])] = (*it)[2];
      }
    } else if (std::regex_match(line, m, kCmBo)) {
      if (Message* msg = find(db.messages, to_u32(m[1]))) msg->comment = m[2];
    } else if (std::regex_match(line, m, kCycle)) {
      if (Message* msg = find(db.messages, to_u32(m[1]))) msg->cycle_ms = to_u32(m[2]);
    } else if (line.empty()) {
      current = nullptr;  // a message's signals end at the blank line after them
    }
  }
  return db;
}

Database parse_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read " + path);
  std::stringstream ss;
  ss << f.rdbuf();
  return parse(ss.str());
}

std::uint64_t raw_value(const Signal& s, std::span<const std::uint8_t> data) {
  std::uint64_t raw = 0;
  if (s.little_endian) {
    // Bit i of the value is bit (start + i) of the frame, counting byte 0's LSB as 0.
    for (unsigned i = 0; i < s.length; ++i) {
      const unsigned pos = s.start_bit + i;
      if (bit_at(data, pos / 8, pos % 8)) raw |= std::uint64_t{1} << i;
    }
    return raw;
  }
  // Big-endian: renumber bits MSB-first across the frame (byte 0 bit 7 = 0); the signal is then the
  // contiguous run of `length` bits starting at its MSB.
  const unsigned msb = (s.start_bit / 8) * 8 + (7 - s.start_bit % 8);
  for (unsigned k = msb; k < msb + s.length; ++k) raw = (raw << 1U) | (bit_at(data, k / 8, 7 - k % 8) ? 1U : 0U);
  return raw;
}

double physical_value(const Signal& s, std::span<const std::uint8_t> data) {
  const std::uint64_t raw = raw_value(s, data);
  double v = static_cast<double>(raw);
  if (s.is_signed && raw >= (std::uint64_t{1} << (s.length - 1)))
    v = static_cast<double>(raw) - static_cast<double>(std::uint64_t{1} << s.length);
  return v * s.factor + s.offset;
}

std::map<std::string, double> decode(const Message& m, std::span<const std::uint8_t> data) {
  std::optional<std::uint64_t> mux;
  for (const auto& s : m.signals) {
    if (s.multiplexor) mux = raw_value(s, data);
  }
  std::map<std::string, double> out;
  for (const auto& s : m.signals) {
    if (s.mux_value && (!mux || *s.mux_value != *mux)) continue;  // another multiplexor value's signal
    out[s.name] = physical_value(s, data);
  }
  return out;
}

}  // namespace fieldguard::test::dbc
