#pragma once
// The data blocks every simulated sensor sends (12 blocks of an azimuth and 32 three-byte returns), and the Velodyne
// data packet that carries them (protocols.md §1.2-§1.4, §1.10): 12 blocks of FF EE, azimuth in 0.01 degree,
// 32 x (distance in 2 mm units, intensity); then the timestamp (us past the hour) and the factory bytes (return
// mode, product). All fields little-endian. The RS-LiDAR-32's packets are in rs32_encoder.hpp.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fieldguard::sim {

inline constexpr std::size_t kSlots = 32;   // returns per data block
inline constexpr std::size_t kBlocks = 12;  // data blocks per packet

struct EncodedReturn {
  std::uint16_t distance = 0;  // in the sensor's distance unit; 0 = no return
  std::uint8_t intensity = 0;
  friend bool operator==(const EncodedReturn&, const EncodedReturn&) = default;
};

struct EncodedBlock {
  std::uint16_t azimuth_cdeg = 0;  // of the block's first firing, 0..35999
  std::array<EncodedReturn, kSlots> returns{};
};

using PacketBlocks = std::array<EncodedBlock, kBlocks>;
using PacketBytes = std::vector<std::uint8_t>;

[[nodiscard]] PacketBytes encode_velodyne(const PacketBlocks& blocks, std::uint32_t timestamp_us,
                                          std::uint8_t return_byte, std::uint8_t product_byte);

// Range (m) -> distance units, rounded; 0 (no return) for ranges that do not fit the 16-bit field.
[[nodiscard]] std::uint16_t encode_distance(double range_m, double unit_m);

}  // namespace fieldguard::sim
