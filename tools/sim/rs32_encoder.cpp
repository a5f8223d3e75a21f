#include "sim/rs32_encoder.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "sim/rs32.hpp"

namespace fieldguard::sim::rs32 {

namespace {

constexpr std::array<std::uint8_t, 8> kMsopMagic{0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0};
constexpr std::array<std::uint8_t, 8> kDifopMagic{0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};
constexpr std::array<std::uint8_t, 5> kTopFirmware{0x00, 0x19, 0x06, 0x21, 0x00};
constexpr std::array<std::uint8_t, 5> kBottomFirmware{0x00, 0x19, 0x06, 0x21, 0x01};
constexpr std::array<std::uint8_t, 6> kSerial{'F', 'G', 'S', 'I', 'M', '1'};
constexpr std::size_t kHeaderSize = 42;
constexpr std::size_t kVerticalTable = 468;
constexpr std::size_t kHorizontalTable = 564;

void put16(PacketBytes& b, std::size_t off, std::uint16_t v) {
  b[off] = static_cast<std::uint8_t>(v >> 8U);
  b[off + 1] = static_cast<std::uint8_t>(v & 0xFFU);
}

// The 10-byte Y-M-D time, UTC, to the microsecond.
void put_time(PacketBytes& b, std::size_t off, std::int64_t unix_ns) {
  using namespace std::chrono;
  const sys_time<nanoseconds> t{nanoseconds{unix_ns}};
  const sys_days day = floor<days>(t);
  const year_month_day ymd{day};
  const hh_mm_ss<microseconds> hms{floor<microseconds>(t - day)};
  b[off] = static_cast<std::uint8_t>(static_cast<int>(ymd.year()) - 2000);
  b[off + 1] = static_cast<std::uint8_t>(static_cast<unsigned>(ymd.month()));
  b[off + 2] = static_cast<std::uint8_t>(static_cast<unsigned>(ymd.day()));
  b[off + 3] = static_cast<std::uint8_t>(hms.hours().count());
  b[off + 4] = static_cast<std::uint8_t>(hms.minutes().count());
  b[off + 5] = static_cast<std::uint8_t>(hms.seconds().count());
  const auto us = static_cast<std::uint32_t>(hms.subseconds().count());
  put16(b, off + 6, static_cast<std::uint16_t>(us / 1000));
  put16(b, off + 8, static_cast<std::uint16_t>(us % 1000));
}

void put_angles(PacketBytes& b, std::size_t off, const std::array<double, kChannels>& deg) {
  for (std::size_t c = 0; c < kChannels; ++c) {
    const long millideg = std::lround(deg[c] * 1000.0);
    b[off + 3 * c] = millideg < 0 ? 0x01 : 0x00;
    put16(b, off + 3 * c + 1, static_cast<std::uint16_t>(std::labs(millideg)));
  }
}

}  // namespace

PacketBytes encode_msop(const PacketBlocks& blocks, std::int64_t first_firing_unix_ns) {
  PacketBytes out(kPacketSize);
  std::copy(kMsopMagic.begin(), kMsopMagic.end(), out.begin());
  put_time(out, 20, first_firing_unix_ns);
  out[30] = 0x02;  // lidar model: RS-LiDAR-32 (the "31st byte"; 0x01 is the RS-LiDAR-16, snark's robosense models)
  out[38] = 0x80;  // 25 degC: 400 x 0.0625, low 5 bits in byte 38's bits 3..7, the rest in byte 39
  out[39] = 0x0C;
  for (std::size_t b = 0; b < kBlocks; ++b) {
    const std::size_t base = kHeaderSize + 100 * b;
    out[base] = 0xFF;
    out[base + 1] = 0xEE;
    put16(out, base + 2, blocks[b].azimuth_cdeg);
    for (std::size_t c = 0; c < kSlots; ++c) {
      put16(out, base + 4 + 3 * c, blocks[b].returns[c].distance);
      out[base + 6 + 3 * c] = blocks[b].returns[c].intensity;
    }
  }
  out[1246] = 0x00;
  out[1247] = 0xFF;
  return out;
}

PacketBytes encode_difop(std::uint16_t rpm, bool dual, std::int64_t unix_ns) {
  PacketBytes out(kPacketSize);
  std::copy(kDifopMagic.begin(), kDifopMagic.end(), out.begin());
  put16(out, 8, rpm);
  put16(out, 34, 36000);  // field of view: from 0 (bytes 32..33) to 360 degrees
  std::copy(kTopFirmware.begin(), kTopFirmware.end(), out.begin() + 40);
  std::copy(kBottomFirmware.begin(), kBottomFirmware.end(), out.begin() + 45);
  std::copy(kSerial.begin(), kSerial.end(), out.begin() + 292);
  out[300] = dual ? 0x00 : 0x01;
  put_time(out, 303, unix_ns);
  put_angles(out, kVerticalTable, kVerticalDeg);
  put_angles(out, kHorizontalTable, kHorizontalDeg);
  out[1246] = 0x0F;
  out[1247] = 0xF0;
  return out;
}

}  // namespace fieldguard::sim::rs32
