#pragma once
// Private: the NMEA 0183 frame ($ address , fields * checksum) and field conversions, shared by every
// sentence type nmea.cpp decodes. A new sentence type is a frame() call plus field reads.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/drivers/nmea.hpp"

namespace fieldguard::nmea::detail {

// Longest sentence accepted: nmea::kMaxSentenceLength (nmea.hpp), which says why.
using nmea::kMaxSentenceLength;
// More fields than any sentence we decode has (RMC in NMEA 4.1: 13); the rest of a longer sentence is one field.
inline constexpr std::size_t kMaxFields = 24;

struct Frame {
  std::string_view talker;                            // "GP", "GN", ... (empty for a proprietary or odd address)
  std::string_view type;                              // "RMC", "GGA", ...
  std::array<std::string_view, kMaxFields> fields{};  // fields[0] = first field after the address
  std::size_t field_count = 0;

  // Field i (0-based, after the address), blanks trimmed; "" if the sentence has fewer fields.
  [[nodiscard]] std::string_view field(std::size_t i) const { return i < field_count ? fields[i] : std::string_view{}; }
};

// Checks start, length and checksum and splits the sentence. Trailing CR, LF and NUL are ignored.
// With require_checksum false, a sentence without "*hh" is accepted unchecked (a wrong "*hh" is still an error).
[[nodiscard]] Expected<Frame, Error> frame(std::string_view text, bool require_checksum = true);

// Field conversions. Each returns nullopt for an empty field and Error::BadField for a malformed one.
template <typename T>
using Field = Expected<std::optional<T>, Error>;

[[nodiscard]] Field<double> decimal(std::string_view f);      // [-+]digits[.digits]
[[nodiscard]] Field<int> integer(std::string_view f);         // digits
[[nodiscard]] Field<char> letter(std::string_view f);         // one upper-case letter
[[nodiscard]] Field<double> time_of_day(std::string_view f);  // hhmmss[.s...] -> seconds of the day
[[nodiscard]] Field<double> latitude(std::string_view value, std::string_view hemisphere);   // ddmm.m, N/S
[[nodiscard]] Field<double> longitude(std::string_view value, std::string_view hemisphere);  // dddmm.m, E/W

struct Date {
  int day = 0, month = 0, year = 0;
};
[[nodiscard]] Field<Date> date_ddmmyy(std::string_view f);  // 2-digit years 80..99 -> 19xx, else 20xx

// Reads fields one after the other and keeps the first error, so a decoder reads like the field table.
class FieldReader {
 public:
  template <typename T>
  std::optional<T> operator()(const Field<T>& f) {
    if (f) return *f;
    if (!error) error = f.error();
    return std::nullopt;
  }
  std::optional<Error> error;
};

}  // namespace fieldguard::nmea::detail
