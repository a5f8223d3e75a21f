#include "fieldguard/output/j1939.hpp"

#include <algorithm>
#include <stdexcept>

namespace fieldguard::output::j1939 {

namespace {

constexpr std::uint8_t kNetworkPriority = 6;  // Address Claimed, Request, Acknowledgement
constexpr std::uint8_t kBam = 32;             // TP.CM control byte: broadcast announce
constexpr double kT1 = 0.75;                  // s, J1939-21: longest wait for the next packet

struct Field {
  const char* name;
  std::uint64_t value;
  unsigned bits;
};

void check_width(std::vector<std::string>& problems, const Field& f) {
  if (f.value >> f.bits != 0U) {
    problems.push_back(std::string(f.name) + ": must fit in " + std::to_string(f.bits) + " bits (0.." +
                       std::to_string((std::uint64_t{1} << f.bits) - 1U) + "), got " + std::to_string(f.value));
  }
}

std::uint8_t lamp_bits(Lamp l) { return static_cast<std::uint8_t>(static_cast<std::uint8_t>(l) & 3U); }

}  // namespace

std::uint64_t Name::value() const {
  std::uint64_t v = 0;
  v |= std::uint64_t{identity_number} & 0x1FFFFFU;
  v |= (std::uint64_t{manufacturer_code} & 0x7FFU) << 21U;
  v |= (std::uint64_t{ecu_instance} & 0x7U) << 32U;
  v |= (std::uint64_t{function_instance} & 0x1FU) << 35U;
  v |= std::uint64_t{function} << 40U;
  v |= (std::uint64_t{vehicle_system} & 0x7FU) << 49U;
  v |= (std::uint64_t{vehicle_system_instance} & 0xFU) << 56U;
  v |= (std::uint64_t{industry_group} & 0x7U) << 60U;
  v |= std::uint64_t{arbitrary_address_capable ? 1U : 0U} << 63U;
  return v;
}

Name Name::from_value(std::uint64_t v) {
  Name n;
  n.identity_number = static_cast<std::uint32_t>(v & 0x1FFFFFU);
  n.manufacturer_code = static_cast<std::uint16_t>((v >> 21U) & 0x7FFU);
  n.ecu_instance = static_cast<std::uint8_t>((v >> 32U) & 0x7U);
  n.function_instance = static_cast<std::uint8_t>((v >> 35U) & 0x1FU);
  n.function = static_cast<std::uint8_t>((v >> 40U) & 0xFFU);
  n.vehicle_system = static_cast<std::uint8_t>((v >> 49U) & 0x7FU);
  n.vehicle_system_instance = static_cast<std::uint8_t>((v >> 56U) & 0xFU);
  n.industry_group = static_cast<std::uint8_t>((v >> 60U) & 0x7U);
  n.arbitrary_address_capable = (v >> 63U) != 0U;
  return n;
}

std::vector<std::string> Name::validate() const {
  std::vector<std::string> problems;
  check_width(problems, {"identity_number", identity_number, 21});
  check_width(problems, {"manufacturer_code", manufacturer_code, 11});
  check_width(problems, {"ecu_instance", ecu_instance, 3});
  check_width(problems, {"function_instance", function_instance, 5});
  check_width(problems, {"vehicle_system", vehicle_system, 7});
  check_width(problems, {"vehicle_system_instance", vehicle_system_instance, 4});
  check_width(problems, {"industry_group", industry_group, 3});
  return problems;
}

std::array<std::uint8_t, 8> name_bytes(std::uint64_t name) {
  std::array<std::uint8_t, 8> b{};
  for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<std::uint8_t>(name >> (8U * i));
  return b;
}

std::uint64_t name_from_bytes(std::span<const std::uint8_t, 8> bytes) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i) v |= std::uint64_t{bytes[i]} << (8U * i);
  return v;
}

CanFrame address_claimed(std::uint64_t name, std::uint8_t address) {
  CanFrame f;
  f.id = j1939_id(kNetworkPriority, kPgnAddressClaimed, address, kGlobalAddress);
  f.len = 8;
  f.data = name_bytes(name);
  return f;
}

CanFrame cannot_claim(std::uint64_t name) { return address_claimed(name, kNullAddress); }

CanFrame request(std::uint32_t pgn, std::uint8_t source, std::uint8_t destination) {
  CanFrame f;
  f.id = j1939_id(kNetworkPriority, kPgnRequest, source, destination);
  f.len = 3;
  f.data.fill(0xFF);
  f.data[0] = static_cast<std::uint8_t>(pgn);
  f.data[1] = static_cast<std::uint8_t>(pgn >> 8U);
  f.data[2] = static_cast<std::uint8_t>(pgn >> 16U);
  return f;
}

std::optional<std::uint32_t> requested_pgn(std::span<const std::uint8_t> data) {
  if (data.size() != 3) return std::nullopt;
  const std::uint32_t pgn = std::uint32_t{data[0]} | std::uint32_t{data[1]} << 8U | std::uint32_t{data[2]} << 16U;
  if (pgn > 0x3FFFFU) return std::nullopt;
  return pgn;
}

CanFrame acknowledgement(AckControl control, std::uint32_t pgn, std::uint8_t requester, std::uint8_t source) {
  CanFrame f;
  f.id = j1939_id(kNetworkPriority, kPgnAcknowledgement, source, kGlobalAddress);
  f.len = 8;
  f.data = {static_cast<std::uint8_t>(control),
            0xFF,  // group function value: not a group function
            0xFF,
            0xFF,
            requester,
            static_cast<std::uint8_t>(pgn),
            static_cast<std::uint8_t>(pgn >> 8U),
            static_cast<std::uint8_t>(pgn >> 16U)};
  return f;
}

std::vector<std::uint8_t> encode_diagnostic(const DiagnosticMessage& m) {
  if (m.dtcs.size() > kMaxDtcs) throw std::invalid_argument("DM: more DTCs than the transport protocol carries");
  const Lamps& l = m.lamps;
  std::vector<std::uint8_t> out;
  out.reserve(2 + 4 * std::max<std::size_t>(m.dtcs.size(), 1) + 2);
  out.push_back(static_cast<std::uint8_t>(lamp_bits(l.malfunction) << 6U | lamp_bits(l.red_stop) << 4U |
                                          lamp_bits(l.amber_warning) << 2U | lamp_bits(l.protect)));
  out.push_back(0xFF);
  const auto put = [&out](const Dtc& d) {
    if (d.spn > 0x7FFFFU || d.fmi > 0x1FU || d.occurrences > 0x7FU) {
      throw std::invalid_argument("DM: a DTC field wider than its bits (SPN 19, FMI 5, occurrences 7)");
    }
    out.push_back(static_cast<std::uint8_t>(d.spn));
    out.push_back(static_cast<std::uint8_t>(d.spn >> 8U));
    out.push_back(static_cast<std::uint8_t>((d.spn >> 16U) << 5U | d.fmi));
    out.push_back(d.occurrences);  // conversion method 0
  };
  if (m.dtcs.empty()) {
    put(Dtc{});
  } else {
    for (const Dtc& d : m.dtcs) put(d);
  }
  while (out.size() < 8) out.push_back(0xFF);
  return out;
}

Expected<DiagnosticMessage, DiagnosticError> decode_diagnostic(std::span<const std::uint8_t> data) {
  if (data.size() < 6) return Unexpected{DiagnosticError::TooShort};
  if (data.size() > kMaxTransportBytes) return Unexpected{DiagnosticError::TooLong};
  DiagnosticMessage m;
  const std::uint8_t b = data[0];
  m.lamps = {static_cast<Lamp>(b >> 6U & 3U), static_cast<Lamp>(b >> 4U & 3U), static_cast<Lamp>(b >> 2U & 3U),
             static_cast<Lamp>(b & 3U)};
  std::size_t at = 2;
  for (; at + 4 <= data.size(); at += 4) {
    const auto d = data.subspan(at, 4);
    if (d[0] == 0xFF && d[1] == 0xFF && d[2] == 0xFF && d[3] == 0xFF) break;  // padding
    const Dtc dtc{std::uint32_t{d[0]} | std::uint32_t{d[1]} << 8U | (std::uint32_t{d[2]} >> 5U) << 16U,
                  static_cast<std::uint8_t>(d[2] & 0x1FU), static_cast<std::uint8_t>(d[3] & 0x7FU)};
    if (dtc != Dtc{}) m.dtcs.push_back(dtc);
  }
  // What is left after the last whole DTC must be padding.
  for (std::size_t k = at; k < data.size(); ++k) {
    if (data[k] != 0xFF) return Unexpected{DiagnosticError::Truncated};
  }
  return m;
}

const char* to_string(DiagnosticError e) {
  switch (e) {
    case DiagnosticError::TooShort: return "shorter than lamps and one DTC";
    case DiagnosticError::Truncated: return "a partial DTC at the end";
    case DiagnosticError::TooLong: return "longer than the transport protocol carries";
  }
  return "?";
}

const char* to_string(Lamp l) {
  switch (l) {
    case Lamp::Off: return "off";
    case Lamp::On: return "on";
    case Lamp::Reserved: return "reserved";
    case Lamp::NotAvailable: return "not available";
  }
  return "?";
}

std::vector<CanFrame> bam_frames(std::uint8_t priority, std::uint32_t pgn, std::uint8_t source,
                                 std::span<const std::uint8_t> data) {
  if (data.size() < 9 || data.size() > kMaxTransportBytes) {
    throw std::invalid_argument("BAM: 9 to 1785 bytes (8 or fewer go in one frame)");
  }
  const auto packets = static_cast<std::uint8_t>((data.size() + 6) / 7);
  std::vector<CanFrame> out;
  out.reserve(1U + packets);
  CanFrame cm;
  cm.id = j1939_id(priority, kPgnTpCm, source, kGlobalAddress);
  cm.len = 8;
  cm.data = {kBam,
             static_cast<std::uint8_t>(data.size()),
             static_cast<std::uint8_t>(data.size() >> 8U),
             packets,
             0xFF,
             static_cast<std::uint8_t>(pgn),
             static_cast<std::uint8_t>(pgn >> 8U),
             static_cast<std::uint8_t>(pgn >> 16U)};
  out.push_back(cm);
  for (std::uint8_t p = 0; p < packets; ++p) {
    CanFrame dt;
    dt.id = j1939_id(priority, kPgnTpDt, source, kGlobalAddress);
    dt.len = 8;
    dt.data.fill(0xFF);
    dt.data[0] = static_cast<std::uint8_t>(p + 1U);
    const std::size_t from = std::size_t{p} * 7U;
    const std::size_t n = std::min<std::size_t>(7, data.size() - from);
    std::copy_n(data.begin() + static_cast<std::ptrdiff_t>(from), n, dt.data.begin() + 1);
    out.push_back(dt);
  }
  return out;
}

std::optional<BamReceiver::Message> BamReceiver::feed(const CanFrame& f, double time_s) {
  const J1939Fields j = j1939_fields(f.id);
  if (j.destination != kGlobalAddress || f.len != 8) return std::nullopt;
  Open& o = open_[j.source];
  if (o.active && time_s - o.last_s > kT1) {
    o.active = false;
    ++counters_.dropped_timeout;
  }
  if (j.pgn == kPgnTpCm) {
    if (f.data[0] != kBam) return std::nullopt;  // a connection (RTS/CTS) to someone, not a broadcast
    const auto size = static_cast<std::uint16_t>(f.data[1] | f.data[2] << 8U);
    const std::uint8_t packets = f.data[3];
    if (size < 9 || size > kMaxTransportBytes || packets != (size + 6) / 7) {
      ++counters_.bad_announcements;
      o.active = false;
      return std::nullopt;
    }
    if (o.active) ++counters_.dropped_restart;
    o.active = true;
    o.pgn = std::uint32_t{f.data[5]} | std::uint32_t{f.data[6]} << 8U | std::uint32_t{f.data[7]} << 16U;
    o.size = size;
    o.packets = packets;
    o.next = 1;
    o.last_s = time_s;
    o.data.clear();
    return std::nullopt;
  }
  if (j.pgn != kPgnTpDt) return std::nullopt;
  if (!o.active || f.data[0] != o.next) {
    if (o.active) o.active = false;
    ++counters_.dropped_sequence;
    return std::nullopt;
  }
  o.last_s = time_s;
  const std::size_t n = std::min<std::size_t>(7, o.size - o.data.size());
  o.data.insert(o.data.end(), f.data.begin() + 1, f.data.begin() + 1 + static_cast<std::ptrdiff_t>(n));
  if (o.next++ < o.packets) return std::nullopt;
  o.active = false;
  ++counters_.completed;
  return Message{o.pgn, j.source, std::move(o.data)};
}

}  // namespace fieldguard::output::j1939
