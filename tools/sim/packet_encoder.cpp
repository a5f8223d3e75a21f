#include "sim/packet_encoder.hpp"

#include <cmath>

namespace fieldguard::sim {

namespace {
void put16(PacketBytes& b, std::size_t off, std::uint16_t v) {
  b[off] = static_cast<std::uint8_t>(v & 0xFFU);
  b[off + 1] = static_cast<std::uint8_t>(v >> 8U);
}
}  // namespace

PacketBytes encode_packet(const std::array<EncodedBlock, hdl32e::kBlocksPerPacket>& blocks,
                          std::uint32_t timestamp_us) {
  PacketBytes out{};
  for (std::size_t b = 0; b < hdl32e::kBlocksPerPacket; ++b) {
    const std::size_t base = 100 * b;
    out[base] = 0xFF;
    out[base + 1] = 0xEE;
    put16(out, base + 2, blocks[b].azimuth_cdeg);
    for (std::size_t j = 0; j < hdl32e::kLasers; ++j) {
      put16(out, base + 4 + 3 * j, blocks[b].returns[j].distance);
      out[base + 6 + 3 * j] = blocks[b].returns[j].intensity;
    }
  }
  for (std::size_t i = 0; i < 4; ++i) out[1200 + i] = static_cast<std::uint8_t>(timestamp_us >> (8U * i));
  out[1204] = hdl32e::kReturnStrongest;
  out[1205] = hdl32e::kProductHdl32e;
  return out;
}

std::uint16_t encode_distance(double range_m) {
  if (!(range_m > 0.0)) return 0;
  const double units = std::round(range_m / hdl32e::kDistanceUnitM);
  if (units < 1.0 || units > 65535.0) return 0;
  return static_cast<std::uint16_t>(units);
}

}  // namespace fieldguard::sim
