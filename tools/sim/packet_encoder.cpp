#include "sim/packet_encoder.hpp"

#include <cmath>

#include "sim/hdl32e.hpp"

namespace fieldguard::sim {

namespace {
void put16(PacketBytes& b, std::size_t off, std::uint16_t v) {
  b[off] = static_cast<std::uint8_t>(v & 0xFFU);
  b[off + 1] = static_cast<std::uint8_t>(v >> 8U);
}
}  // namespace

PacketBytes encode_velodyne(const PacketBlocks& blocks, std::uint32_t timestamp_us, std::uint8_t return_byte,
                            std::uint8_t product_byte) {
  PacketBytes out(hdl32e::kPacketSize);
  for (std::size_t b = 0; b < kBlocks; ++b) {
    const std::size_t base = 100 * b;
    out[base] = 0xFF;
    out[base + 1] = 0xEE;
    put16(out, base + 2, blocks[b].azimuth_cdeg);
    for (std::size_t j = 0; j < kSlots; ++j) {
      put16(out, base + 4 + 3 * j, blocks[b].returns[j].distance);
      out[base + 6 + 3 * j] = blocks[b].returns[j].intensity;
    }
  }
  for (std::size_t i = 0; i < 4; ++i) out[1200 + i] = static_cast<std::uint8_t>(timestamp_us >> (8U * i));
  out[1204] = return_byte;
  out[1205] = product_byte;
  return out;
}

std::uint16_t encode_distance(double range_m, double unit_m) {
  if (!(range_m > 0.0)) return 0;
  const double units = std::round(range_m / unit_m);
  if (units < 1.0 || units > 65535.0) return 0;
  return static_cast<std::uint16_t>(units);
}

}  // namespace fieldguard::sim
