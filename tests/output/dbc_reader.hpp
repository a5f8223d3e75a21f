#pragma once
// A small DBC reader for tests only. It shares no code with src/output (the layouts, the packer, the DBC
// printer): decoding our frames through it is what shows that config/fieldguard.dbc and the encoder agree.
// Reads BO_, SG_ (@1 Intel / @0 Motorola, + / -, multiplexor M and multiplexed mN), CM_ BO_,
// BA_ "GenMsgCycleTime" and VAL_; ignores the rest.

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace fieldguard::test::dbc {

struct Signal {
  std::string name;
  unsigned start_bit = 0;
  unsigned length = 0;
  bool little_endian = true;
  bool is_signed = false;
  double factor = 1.0;
  double offset = 0.0;
  double min = 0.0;
  double max = 0.0;
  std::string unit;
  std::map<std::int64_t, std::string> values;
  bool multiplexor = false;           // M
  std::optional<unsigned> mux_value;  // mN: present only when the multiplexor's raw value is N
};

struct Message {
  std::uint32_t dbc_id = 0;  // as written: bit 31 set for extended ids
  std::string name;
  unsigned dlc = 0;
  std::string transmitter;
  std::string comment;
  std::optional<unsigned> cycle_ms;
  std::vector<Signal> signals;

  [[nodiscard]] bool extended() const { return (dbc_id & 0x80000000U) != 0; }
  [[nodiscard]] std::uint32_t can_id() const { return dbc_id & 0x1FFFFFFFU; }
  [[nodiscard]] const Signal& signal(std::string_view n) const;  // throws std::out_of_range
};

struct Database {
  std::vector<Message> messages;
  [[nodiscard]] const Message* by_can_id(std::uint32_t id) const;
  [[nodiscard]] const Message& by_name(std::string_view n) const;  // throws std::out_of_range
};

// Throws std::runtime_error "line N: ..." on a BO_/SG_/VAL_ line it cannot read.
[[nodiscard]] Database parse(std::string_view text);
[[nodiscard]] Database parse_file(const std::string& path);

[[nodiscard]] std::uint64_t raw_value(const Signal& s, std::span<const std::uint8_t> data);
[[nodiscard]] double physical_value(const Signal& s, std::span<const std::uint8_t> data);
// Every signal of `m` in `data`, physical values by name (of multiplexed signals, those of the multiplexor's value).
[[nodiscard]] std::map<std::string, double> decode(const Message& m, std::span<const std::uint8_t> data);

}  // namespace fieldguard::test::dbc
