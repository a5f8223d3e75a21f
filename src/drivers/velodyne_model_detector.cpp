// Model detection from the packet stream, and sensor time from the hour offset (protocols.md §1.4, §1.7).
#include <algorithm>
#include <cstdio>

#include "fieldguard/drivers/velodyne_decoder.hpp"

namespace fieldguard::velodyne {

namespace {

constexpr std::uint64_t kHourUs = 3'600'000'000ULL;

// Packet spacing of single-return streams (µs): 12 blocks of 46.08 µs (HDL-32E) or 110.592 µs (VLP-16).
// Dual-return streams send twice as many packets; their spacings are doubled before comparison.
constexpr double kHdl32SpacingUs = 552.96;
constexpr double kVlp16SpacingUs = 1327.104;
constexpr double kSpacingTolerance = 0.08;  // relative
// A longer spacing than this means lost packets (or a pause): it says nothing about the model.
constexpr std::uint32_t kMaxSpacingUs = 1500;
constexpr std::size_t kSpacingsNeeded = 7;

enum class ProductSays : std::uint8_t { Nothing, Hdl32OrEarlyVlp16, Vlp16, Unsupported };

ProductSays product_says(std::uint8_t b) {
  switch (b) {
    case 0x21: return ProductSays::Hdl32OrEarlyVlp16;
    case 0x22:
    case 0x24: return ProductSays::Vlp16;
    case 0x23:
    case 0x28:
    case 0xA1: return ProductSays::Unsupported;
    default: return ProductSays::Nothing;
  }
}

const char* product_name(std::uint8_t b) {
  switch (b) {
    case 0x21: return "HDL-32E";
    case 0x22: return "VLP-16";
    case 0x23: return "VLP-32A/B";
    case 0x24: return "VLP-16 Hi-Res";
    case 0x28: return "VLP-32C";
    case 0xA1: return "VLS-128";
    default: return "unset or unknown";
  }
}

bool near(double value, double nominal) {
  return value > nominal * (1.0 - kSpacingTolerance) && value < nominal * (1.0 + kSpacingTolerance);
}

bool is_dual(const PacketHeader& h) { return h.return_mode == ReturnMode::Dual || h.dual_layout; }

}  // namespace

void ModelDetector::observe(const PacketHeader& header) {
  if (decided_) return;
  if (last_) {
    // Microseconds past the hour: a smaller value than the last one is the roll-over at the top of the hour.
    const std::uint64_t now = header.timestamp_us;
    const std::uint64_t before = last_->timestamp_us;
    const std::uint64_t delta = now >= before ? now - before : now + kHourUs - before;
    if (delta > 0 && delta <= kMaxSpacingUs && is_dual(header) == is_dual(*last_)) {
      spacings_us_.push_back(static_cast<std::uint32_t>(is_dual(header) ? 2 * delta : delta));
    }
  }
  last_ = header;
  if (spacings_us_.size() < kSpacingsNeeded) return;

  std::vector<std::uint32_t> sorted = spacings_us_;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  const char* const mode = is_dual(header) ? "dual return, doubled" : "single return";
  const ProductSays product = product_says(header.product_byte);

  char text[256];
  std::optional<Model> verdict;
  if (product == ProductSays::Unsupported) {
    std::snprintf(text, sizeof text, "product byte 0x%02X (%s) is not a supported model", header.product_byte,
                  product_name(header.product_byte));
  } else if (near(median, kVlp16SpacingUs)) {
    if (product == ProductSays::Hdl32OrEarlyVlp16) {
      std::snprintf(text, sizeof text,
                    "spacing %.0f us (%s) is a VLP-16's (1327.1 us); product byte 0x21 (HDL-32E) is what early "
                    "VLP-16 firmware reports: VLP-16",
                    median, mode);
    } else {
      std::snprintf(text, sizeof text,
                    "spacing %.0f us (%s) is a VLP-16's (1327.1 us), product byte 0x%02X (%s): VLP-16", median, mode,
                    header.product_byte, product_name(header.product_byte));
    }
    verdict = Model::VLP16;
  } else if (near(median, kHdl32SpacingUs)) {
    if (product == ProductSays::Vlp16) {
      std::snprintf(text, sizeof text,
                    "spacing %.0f us (%s) is an HDL-32E's (553.0 us) but product byte 0x%02X says %s: undecided, "
                    "configure the model",
                    median, mode, header.product_byte, product_name(header.product_byte));
    } else {
      std::snprintf(text, sizeof text,
                    "spacing %.0f us (%s) is an HDL-32E's (553.0 us), product byte 0x%02X (%s): HDL-32E", median, mode,
                    header.product_byte, product_name(header.product_byte));
      verdict = Model::HDL32E;
    }
  } else {
    std::snprintf(text, sizeof text,
                  "spacing %.0f us (%s) fits neither an HDL-32E (553.0 us) nor a VLP-16 (1327.1 us); product byte "
                  "0x%02X (%s): undecided",
                  median, mode, header.product_byte, product_name(header.product_byte));
  }
  reason_ = text;
  decided_ = verdict;
  if (!decided_) spacings_us_.erase(spacings_us_.begin());  // keep a sliding window and try again
}

Stamp sensor_time_from_hour_offset(std::uint32_t us_past_hour, Stamp host) {
  constexpr std::int64_t kHourNs = 3'600'000'000'000LL;
  constexpr std::int64_t kHalfHourNs = kHourNs / 2;
  std::int64_t hour_start = host.ns / kHourNs * kHourNs;
  if (host.ns < 0 && host.ns % kHourNs != 0) hour_start -= kHourNs;  // floor, not truncation
  std::int64_t t = hour_start + static_cast<std::int64_t>(us_past_hour) * 1000;
  if (t - host.ns > kHalfHourNs) t -= kHourNs;
  if (host.ns - t > kHalfHourNs) t += kHourNs;
  return Stamp{t};
}

}  // namespace fieldguard::velodyne
