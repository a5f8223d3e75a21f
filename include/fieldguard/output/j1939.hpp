#pragma once
// J1939 network management and diagnostics on the wire, pure (no socket, no clock): the 64-bit NAME of
// J1939-81 / ISO 11783-5, the diagnostic messages DM1/DM2 of J1939-73 (lamps and DTCs), and the broadcast
// transport protocol (BAM) of J1939-21 that carries a message longer than 8 bytes.
//
// NAME bits (the Linux UAPI <linux/can/j1939.h> and J1939-81 agree): 0-20 identity number, 21-31 manufacturer
// code, 32-34 ECU instance, 35-39 function instance, 40-47 function, 48 reserved, 49-55 vehicle system, 56-59
// vehicle system instance, 60-62 industry group, 63 arbitrary address capable. On the bus (Address Claimed) it is
// sent least significant byte first; the lower value wins an address contest.
//
// DM1 / DM2 data: byte 0 lamps (bits 8-7 malfunction indicator, 6-5 red stop, 4-3 amber warning, 2-1 protect;
// 00 off, 01 on), byte 1 their flashing (0xFF: no flash information), then 4 bytes per DTC: SPN bits 0-15 (bytes
// 2-3, little-endian), SPN bits 16-18 in the top 3 bits of byte 4 with the FMI in its low 5, and byte 5 the SPN
// conversion method (bit 8, 0 here) and the occurrence count (bits 7-1). No active DTC: one all-zero DTC. At
// least 8 bytes (0xFF after the last DTC); more than one DTC takes the transport protocol.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/output/can_frame.hpp"

namespace fieldguard::output::j1939 {

inline constexpr std::uint32_t kPgnAcknowledgement = 0xE800;  // 59392
inline constexpr std::uint32_t kPgnRequest = 0xEA00;          // 59904
inline constexpr std::uint32_t kPgnTpDt = 0xEB00;             // 60160, transport data
inline constexpr std::uint32_t kPgnTpCm = 0xEC00;             // 60416, transport connection management
inline constexpr std::uint32_t kPgnAddressClaimed = 0xEE00;   // 60928, also Cannot Claim (from the null address)
inline constexpr std::uint32_t kPgnDm1 = 0xFECA;              // 65226, active diagnostic trouble codes
inline constexpr std::uint32_t kPgnDm2 = 0xFECB;              // 65227, previously active
inline constexpr std::uint32_t kPgnSoftwareId = 0xFEDA;       // 65242
inline constexpr std::uint32_t kPgnComponentId = 0xFEEB;      // 65259

inline constexpr std::uint8_t kNullAddress = 0xFE;    // no address (Cannot Claim, a request before a claim)
inline constexpr std::uint8_t kGlobalAddress = 0xFF;  // to everyone
inline constexpr std::uint8_t kMaxUnicastAddress = 0xFD;

inline constexpr std::uint8_t kIndustryGroupAgricultural = 2;

struct Name {
  std::uint32_t identity_number = 0;         // 21 bits: the manufacturer's, unique per unit (a serial number)
  std::uint16_t manufacturer_code = 0;       // 11 bits, assigned by SAE
  std::uint8_t ecu_instance = 0;             // 3 bits
  std::uint8_t function_instance = 0;        // 5 bits
  std::uint8_t function = 0;                 // 8 bits
  std::uint8_t vehicle_system = 0;           // 7 bits
  std::uint8_t vehicle_system_instance = 0;  // 4 bits
  std::uint8_t industry_group = 0;           // 3 bits
  bool arbitrary_address_capable = false;    // may move to another address after losing a contest

  [[nodiscard]] std::uint64_t value() const;  // the fields masked to their widths, reserved bit 0
  [[nodiscard]] static Name from_value(std::uint64_t v);
  // A field wider than its bits, each named; empty when every field fits.
  [[nodiscard]] std::vector<std::string> validate() const;

  friend bool operator==(const Name&, const Name&) = default;
};

[[nodiscard]] std::array<std::uint8_t, 8> name_bytes(std::uint64_t name);  // least significant byte first
[[nodiscard]] std::uint64_t name_from_bytes(std::span<const std::uint8_t, 8> bytes);

// The frames of the network management PGNs. An Address Claimed from `address` (priority 6, to global); Cannot
// Claim is the same from kNullAddress.
[[nodiscard]] CanFrame address_claimed(std::uint64_t name, std::uint8_t address);
[[nodiscard]] CanFrame cannot_claim(std::uint64_t name);
// A Request (3 data bytes: the requested PGN) from `source` to `destination` (kGlobalAddress: everyone).
[[nodiscard]] CanFrame request(std::uint32_t pgn, std::uint8_t source, std::uint8_t destination);
// The requested PGN of a Request's data; nullopt when not 3 bytes or more than 18 bits.
[[nodiscard]] std::optional<std::uint32_t> requested_pgn(std::span<const std::uint8_t> data);

enum class AckControl : std::uint8_t { Ack = 0, Nack = 1, AccessDenied = 2, CannotRespond = 3 };
// Acknowledgement (PGN 59392) of a request for `pgn` from `requester`, sent to global as J1939-21 asks.
[[nodiscard]] CanFrame acknowledgement(AckControl control, std::uint32_t pgn, std::uint8_t requester,
                                       std::uint8_t source);

struct Dtc {
  std::uint32_t spn = 0;         // 19 bits: suspect parameter number
  std::uint8_t fmi = 0;          // 5 bits: failure mode identifier
  std::uint8_t occurrences = 0;  // 7 bits (126 = 126 or more; 127 not available)

  friend bool operator==(const Dtc&, const Dtc&) = default;
};

enum class Lamp : std::uint8_t { Off = 0, On = 1, Reserved = 2, NotAvailable = 3 };

struct Lamps {
  Lamp malfunction = Lamp::Off;
  Lamp red_stop = Lamp::Off;
  Lamp amber_warning = Lamp::Off;
  Lamp protect = Lamp::Off;

  friend bool operator==(const Lamps&, const Lamps&) = default;
};

struct DiagnosticMessage {  // DM1 or DM2
  Lamps lamps;
  std::vector<Dtc> dtcs;  // the no-DTC placeholder (all zero) is not listed
};

inline constexpr std::size_t kMaxDtcs = 445;  // (1785 - 2) / 4: what the transport protocol carries

// The data bytes (8 or more); throws std::invalid_argument for a field wider than its bits or more than kMaxDtcs.
[[nodiscard]] std::vector<std::uint8_t> encode_diagnostic(const DiagnosticMessage& m);

// Under 6 bytes; a partial DTC (not 0xFF); longer than the transport protocol carries (1785 bytes).
enum class DiagnosticError : std::uint8_t { TooShort, Truncated, TooLong };
[[nodiscard]] Expected<DiagnosticMessage, DiagnosticError> decode_diagnostic(std::span<const std::uint8_t> data);
[[nodiscard]] const char* to_string(DiagnosticError e);
[[nodiscard]] const char* to_string(Lamp l);

// Broadcast transport (BAM): the TP.CM announcement then the TP.DT packets (sequence 1.., 7 bytes each, the last
// padded with 0xFF), all from `source` to global at `priority` (7 is usual). 9..1785 bytes; J1939-21 wants 50 to
// 200 ms between the packets, which the sender spaces. Throws std::invalid_argument outside that size.
inline constexpr std::size_t kMaxTransportBytes = 1785;
[[nodiscard]] std::vector<CanFrame> bam_frames(std::uint8_t priority, std::uint32_t pgn, std::uint8_t source,
                                               std::span<const std::uint8_t> data);

// The receiving end of BAM, per source address: an announcement opens a message, its packets fill it, the last
// one completes it. A packet out of sequence or a new announcement before the end drops the message under way
// (counted); so does a packet more than 750 ms (J1939-21's T1) after the one before it.
class BamReceiver {
 public:
  struct Message {
    std::uint32_t pgn = 0;
    std::uint8_t source = 0;
    std::vector<std::uint8_t> data;  // the announced size
  };
  struct Counters {
    std::uint64_t completed = 0;
    std::uint64_t dropped_sequence = 0;  // a packet out of order, or one without an announcement
    std::uint64_t dropped_restart = 0;   // announced again before the last packet
    std::uint64_t dropped_timeout = 0;
    std::uint64_t bad_announcements = 0;  // size or packet count impossible
  };

  // Any frame: only TP.CM BAM and TP.DT to global are taken; the rest is ignored. A completed message, or nothing.
  std::optional<Message> feed(const CanFrame& f, double time_s);
  [[nodiscard]] const Counters& counters() const { return counters_; }

 private:
  struct Open {
    bool active = false;
    std::uint32_t pgn = 0;
    std::uint16_t size = 0;
    std::uint8_t packets = 0;
    std::uint8_t next = 1;
    double last_s = 0.0;
    std::vector<std::uint8_t> data;
  };
  std::array<Open, 256> open_{};
  Counters counters_;
};

}  // namespace fieldguard::output::j1939
