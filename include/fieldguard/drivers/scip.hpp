#pragma once
// Hokuyo SCIP 2.0, client side (../shared/docs/protocols.md §3): the character encodings, the check code, the
// commands the client sends, and a push-style reply parser (bytes from TCP in arbitrary chunks in, replies out).
// Pure: no I/O, threads or logging; bad input is a counted Error and the parser resynchronises.
// Decoding the contents of a reply is in scip_data.hpp, the client's protocol state machine in scip_client.hpp.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/core/bytes.hpp"

namespace fieldguard::scip {

// ---- Character encoding (§3.2): 6 bits a character, char - 0x30, '0' (0x30) .. 'o' (0x6F), MSB group first.
inline constexpr char kMinDataChar = 0x30;
inline constexpr char kMaxDataChar = 0x6F;
// nullopt if `chars` is empty, longer than 4, or holds a character outside '0'..'o'.
[[nodiscard]] std::optional<std::uint32_t> decode_chars(std::string_view chars);
// Appends `value` as `width` characters (1..4); the value is taken modulo 2^(6*width).
void encode_chars(std::uint32_t value, std::size_t width, std::string& out);

// ---- Check code (§3.3): (sum of the bytes) & 0x3F + 0x30.
[[nodiscard]] char check_code(std::string_view bytes);

// ---- Commands.
enum class Command : std::uint8_t {
  Unknown = 0,
  Scip20,  // "SCIP2.0": switch a SCIP 1.1 sensor to 2.0
  VV,
  PP,
  II,  // version, parameters, state
  BM,
  QT,
  RS,
  RT,
  RB,  // laser on, laser off / stop, reset, partial reset, reboot
  TM,  // time-sync mode (TM0 / TM1 / TM2)
  MD,
  ME,
  MS,  // continuous scans: 3-char ranges, ranges + intensities, 2-char ranges
  GD,
  GE,
  GS,  // single scans
};
[[nodiscard]] std::string_view to_string(Command c);
// The command an echo line names, if the echo has exactly that command's form (fixed-width digits, then an
// optional ";tag" of at most 16 characters): Unknown otherwise. This is the parser's "plausible echo".
[[nodiscard]] Command command_of_echo(std::string_view echo);

inline constexpr std::size_t kMaxTagLength = 16;

// Parameters of MD/ME/MS (all five) and GD/GE/GS (steps and cluster).
struct ScanRequest {
  std::uint16_t first_step = 0;  // 0..9999 on the wire; the UTM-30LX-EW has 0..1080
  std::uint16_t last_step = 1080;
  std::uint8_t cluster = 1;   // 0..99 adjacent steps merged into one value (0 and 1 both mean none)
  std::uint8_t interval = 0;  // 0..9 scans skipped between two sent
  std::uint8_t scans = 0;     // 0..99 scans to send, 0 = until QT
  friend bool operator==(const ScanRequest&, const ScanRequest&) = default;
};

// Command lines, LF-terminated, with ";tag" when `tag` is not empty. Throw std::invalid_argument for misuse:
// a parameter out of its field's range, last_step < first_step, a tag longer than 16 characters or holding a
// character that is not printable ASCII or is ';'.
[[nodiscard]] std::string encode_command(Command c, std::string_view tag = {});  // SCIP2.0 VV PP II BM QT RS RT RB
[[nodiscard]] std::string encode_scan(Command c, const ScanRequest& r, std::string_view tag = {});  // MD ME MS GD GE GS
[[nodiscard]] std::string encode_tm(int mode, std::string_view tag = {});                           // TM0 / TM1 / TM2

// ---- Status codes (§3.4; SCIP 2.0 spec C-42-03320B; hokuyolx statuses.py for the generic ones).
enum class StatusCategory : std::uint8_t {
  Ok,               // 00
  DataFollows,      // 99: a scan of MD/ME/MS
  ParameterError,   // 01..09: meaning depends on the command (BM: 01 laser not lit, 02 already on)
  CommandRejected,  // 0D 0E 0F 0G 0H 0L 0M 10: too long, not defined, not supported, tag too long, too short,
                    // abnormal state, unstable, denied
  Stopped,          // 21..49: processing stopped to verify an error
  HardwareTrouble,  // 50..97: laser, motor ... malfunction
  Resumed,          // 98: resumed after the laser was found working again
  Scip11Ok,         // "0": the one-character status of a SCIP 1.1 sensor (reply to SCIP2.0)
};
[[nodiscard]] std::string_view to_string(StatusCategory c);
// nullopt for a code that is none of the above (the parser counts it as UnknownStatus).
[[nodiscard]] std::optional<StatusCategory> classify_status(std::string_view code);
// Human text of a status for a command ("laser could not be lit", "end step out of range", ...).
[[nodiscard]] std::string_view status_text(Command c, std::string_view code);

// ---- Errors, counted by whoever meets them (parser: framing; decoders: contents).
enum class Error : std::uint8_t {
  BadCheckCode,   // a line's check character does not match
  MalformedLine,  // an echo that is no known command, a status line of the wrong length, a missing status
  UnknownStatus,  // a well-formed status that is no known code
  LineTooLong,    // a line longer than any legal one (kMaxLineLength)
  ReplyTooLong,   // a reply longer than the longest legal ME reply (kMaxReplyBytes)
  NotThisReply,   // decoding a reply as what it is not (a scan from an MD acknowledgement, PP from VV...)
  BadEcho,        // the echo's fixed-width parameters are not numbers
  BadCharacter,   // a data character outside '0'..'o'
  BadDataLength,  // data lines not 64 characters, length not a whole number of values, wrong number of values
  BadField,       // a VV/PP/II line that is not LABEL:value, or a PP field missing or not a number
};
[[nodiscard]] std::string_view to_string(Error e);
inline constexpr std::size_t kErrorCount = 10;

// ---- Replies.
inline constexpr std::size_t kDataCharsPerLine = 64;
inline constexpr std::size_t kMaxSteps = 1081;
// Longest legal line without its LF: II/VV/PP text lines are the longest (tens of characters); 128 leaves room.
inline constexpr std::size_t kMaxLineLength = 128;
// Longest legal reply in bytes, LFs included: ME over kMaxSteps with a 16-character tag (protocols.md §3.5).
[[nodiscard]] constexpr std::size_t max_reply_bytes() {
  const std::size_t echo = 15 + 1 + kMaxTagLength + 1;
  const std::size_t status = 4;
  const std::size_t timestamp = 6;
  const std::size_t data = kMaxSteps * 6;
  const std::size_t lines = (data + kDataCharsPerLine - 1) / kDataCharsPerLine;
  return echo + status + timestamp + data + 2 * lines + 1;
}
inline constexpr std::size_t kMaxReplyBytes = max_reply_bytes();

struct Reply {
  std::string echo;  // the command line as echoed (without LF)
  Command command = Command::Unknown;
  std::string status;  // "00", "99", "0E", ... ("0" for a SCIP 1.1 sensor)
  StatusCategory category = StatusCategory::Ok;
  std::vector<std::string> lines;  // payload lines, check character verified and removed
};

struct ParserCounters {
  std::uint64_t replies = 0;
  std::array<std::uint64_t, kErrorCount> errors{};  // framing errors only (BadCheckCode .. ReplyTooLong)
  std::uint64_t discarded_bytes = 0;                // bytes dropped while resynchronising
  [[nodiscard]] std::uint64_t rejected() const;
};

// Push-style reply parser. A reply is: echo LF, status (2 chars + check) LF, payload lines (each with its check
// character) LF, an empty line. The check character of a "LABEL:value;S" line may cover "LABEL:value" or
// "LABEL:value;": both are accepted (urg_c does the same). After an error the parser drops bytes until an empty
// line or a line that is a plausible echo. Memory is bounded by kMaxReplyBytes. One producer: not thread-safe.
class ReplyParser {
 public:
  void push(ByteSpan bytes, std::vector<Reply>& out);
  void push(std::string_view bytes, std::vector<Reply>& out);
  // Forgets a partial reply (after a reconnect).
  void reset();
  [[nodiscard]] const ParserCounters& counters() const { return counters_; }

 private:
  enum class State : std::uint8_t { Echo, Status, Payload, Discard };
  void on_line(std::vector<Reply>& out);
  void fail(Error e);

  State state_ = State::Echo;
  std::string line_;
  bool line_overflow_ = false;
  std::size_t reply_bytes_ = 0;
  Reply current_;
  ParserCounters counters_;
};

}  // namespace fieldguard::scip
