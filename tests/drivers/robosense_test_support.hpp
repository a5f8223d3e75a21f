#pragma once
// Test scaffolding for the RoboSense RS-32 tests: MSOP and DIFOP packet builders written from protocols.md §2
// (big-endian), independent of the decoder's own code. There is no real RS-32 capture (realdata/INDEX.txt).

#include <cmath>
#include <cstdint>
#include <ctime>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/drivers/robosense.hpp"

namespace fieldguard::robosense::test {

// The bench table of one real unit from ros_rslidar rs_lidar_32/angle.csv (protocols.md §2.4; an example,
// not a spec), channel 0..31, degrees.
inline constexpr std::array<double, kChannels> kExampleVertDeg = {
    -10.26, 0.30,  -6.41,  -0.02, 2.28,  -0.33, 3.30,  -0.67, 4.61,  1.68,  7.02,  1.30,  10.30, 1.00,  15.02, 0.70,
    -25.00, -2.28, -14.64, -2.67, -7.91, -3.02, -5.41, -3.30, -3.65, -1.02, -4.05, -1.33, -4.39, -1.63, -4.65, -1.98};

inline Calibration example_calibration() {
  Calibration c;
  c.vert_deg = kExampleVertDeg;
  for (std::size_t i = 0; i < kChannels; ++i)
    c.horiz_deg[i] = (i % 2 == 0 ? 1.0 : -1.0) * 0.05 * static_cast<double>(i % 5);
  return c;
}

inline void put16(std::vector<std::uint8_t>& b, std::size_t off, std::uint16_t v) {
  b[off] = static_cast<std::uint8_t>(v >> 8);
  b[off + 1] = static_cast<std::uint8_t>(v & 0xFF);
}

// The 10-byte YMD time of a UTC instant (microseconds since the epoch), through the C library's gmtime_r.
inline void put_time(std::vector<std::uint8_t>& b, std::size_t off, std::int64_t unix_us) {
  const std::time_t s = static_cast<std::time_t>(unix_us / 1'000'000);
  const auto sub = static_cast<int>(unix_us % 1'000'000);
  std::tm tm{};
  gmtime_r(&s, &tm);
  b[off] = static_cast<std::uint8_t>(tm.tm_year - 100);
  b[off + 1] = static_cast<std::uint8_t>(tm.tm_mon + 1);
  b[off + 2] = static_cast<std::uint8_t>(tm.tm_mday);
  b[off + 3] = static_cast<std::uint8_t>(tm.tm_hour);
  b[off + 4] = static_cast<std::uint8_t>(tm.tm_min);
  b[off + 5] = static_cast<std::uint8_t>(tm.tm_sec);
  put16(b, off + 6, static_cast<std::uint16_t>(sub / 1000));
  put16(b, off + 8, static_cast<std::uint16_t>(sub % 1000));
}

// 2024-03-21 08:30:15.123456 UTC, the worked example of protocols.md §2.6.
inline constexpr std::int64_t kExampleUnixUs = 1'711'009'815'123'456;

// A 1248-byte MSOP packet: magic, the example time, every block flagged FF EE, azimuths and channels zero.
class MsopBuilder {
 public:
  MsopBuilder() : b_(kPacketSize, 0) {
    const std::array<std::uint8_t, 8> magic = {0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0};
    std::copy(magic.begin(), magic.end(), b_.begin());
    for (std::size_t k = 0; k < kBlocksPerPacket; ++k) {
      b_[block(k)] = 0xFF;
      b_[block(k) + 1] = 0xEE;
    }
    time_us(kExampleUnixUs);
    b_[1246] = 0x00;
    b_[1247] = 0xFF;
  }
  static std::size_t block(std::size_t k) { return 42 + 100 * k; }
  MsopBuilder& time_us(std::int64_t unix_us) {
    put_time(b_, 20, unix_us);
    return *this;
  }
  MsopBuilder& azimuth(std::size_t k, std::uint16_t cdeg) {
    put16(b_, block(k) + 2, cdeg);
    return *this;
  }
  // Block k at first + step * (k, or k / 2 with pairs), modulo 36000.
  MsopBuilder& azimuths(int first, int step, bool pairs = false) {
    for (std::size_t k = 0; k < kBlocksPerPacket; ++k) {
      const int i = pairs ? static_cast<int>(k / 2) : static_cast<int>(k);
      azimuth(k, static_cast<std::uint16_t>(((first + step * i) % 36000 + 36000) % 36000));
    }
    return *this;
  }
  MsopBuilder& channel(std::size_t k, std::size_t slot, std::uint16_t raw, std::uint8_t reflectivity) {
    put16(b_, block(k) + 4 + 3 * slot, raw);
    b_[block(k) + 4 + 3 * slot + 2] = reflectivity;
    return *this;
  }
  MsopBuilder& all_channels(std::uint16_t raw, std::uint8_t reflectivity) {
    for (std::size_t k = 0; k < kBlocksPerPacket; ++k) {
      for (std::size_t s = 0; s < kChannels; ++s) channel(k, s, raw, reflectivity);
    }
    return *this;
  }
  std::vector<std::uint8_t>& bytes() { return b_; }
  [[nodiscard]] ByteSpan span() const { return b_; }

 private:
  std::vector<std::uint8_t> b_;
};

// A 1248-byte DIFOP packet: magic, 600 rpm, new firmware, strongest return, the example time, and the angle
// table of `cal` (0.001 degree records), tail 0F F0.
class DifopBuilder {
 public:
  explicit DifopBuilder(const Calibration& cal = example_calibration()) : b_(kPacketSize, 0) {
    const std::array<std::uint8_t, 8> magic = {0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};
    std::copy(magic.begin(), magic.end(), b_.begin());
    rpm(600);
    put16(b_, 32, 0);
    put16(b_, 34, 36000);
    firmware({0x09, 0x23, 0x09, 0x06, 0xA1});  // T9R23V6-like top board (ros_rslidar: not an old-firmware value)
    return_mode(1);
    put_time(b_, 303, kExampleUnixUs);
    for (std::size_t i = 0; i < 6; ++i) b_[292 + i] = static_cast<std::uint8_t>(0x10 + i);
    angles(cal);
    b_[1246] = 0x0F;
    b_[1247] = 0xF0;
  }
  DifopBuilder& rpm(std::uint16_t v) {
    put16(b_, 8, v);
    return *this;
  }
  DifopBuilder& firmware(std::array<std::uint8_t, 5> top) {
    std::copy(top.begin(), top.end(), b_.begin() + 40);
    return *this;
  }
  DifopBuilder& return_mode(std::uint8_t v) {
    b_[300] = v;
    return *this;
  }
  DifopBuilder& triplet(std::size_t offset, std::size_t ch, std::uint8_t sign, std::uint16_t magnitude) {
    b_[offset + 3 * ch] = sign;
    put16(b_, offset + 3 * ch + 1, magnitude);
    return *this;
  }
  DifopBuilder& angles(const Calibration& cal) {
    for (std::size_t c = 0; c < kChannels; ++c) {
      for (auto [offset, deg] :
           {std::pair{std::size_t{468}, cal.vert_deg[c]}, std::pair{std::size_t{564}, cal.horiz_deg[c]}}) {
        const long m = std::lround(deg * 1000.0);
        triplet(offset, c, m < 0 ? 0x01 : 0x00, static_cast<std::uint16_t>(m < 0 ? -m : m));
      }
    }
    return *this;
  }
  DifopBuilder& fill_table(std::size_t offset, std::uint8_t v) {
    std::fill(b_.begin() + static_cast<std::ptrdiff_t>(offset), b_.begin() + static_cast<std::ptrdiff_t>(offset + 96),
              v);
    return *this;
  }
  std::vector<std::uint8_t>& bytes() { return b_; }
  [[nodiscard]] ByteSpan span() const { return b_; }

 private:
  std::vector<std::uint8_t> b_;
};

}  // namespace fieldguard::robosense::test
