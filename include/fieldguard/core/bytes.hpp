#pragma once
// Explicit-endian loads from byte buffers. Callers check the buffer length once, before any load;
// these functions do no bounds checking of their own beyond a debug assert.

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <span>

namespace fieldguard {

using ByteSpan = std::span<const std::uint8_t>;

[[nodiscard]] inline std::uint16_t load_le16(ByteSpan b, std::size_t off) {
  assert(off + 2 <= b.size());
  return static_cast<std::uint16_t>(b[off] | (b[off + 1] << 8));
}
[[nodiscard]] inline std::uint32_t load_le32(ByteSpan b, std::size_t off) {
  assert(off + 4 <= b.size());
  return static_cast<std::uint32_t>(b[off]) | (static_cast<std::uint32_t>(b[off + 1]) << 8) |
         (static_cast<std::uint32_t>(b[off + 2]) << 16) | (static_cast<std::uint32_t>(b[off + 3]) << 24);
}
[[nodiscard]] inline std::uint16_t load_be16(ByteSpan b, std::size_t off) {
  assert(off + 2 <= b.size());
  return static_cast<std::uint16_t>((b[off] << 8) | b[off + 1]);
}
[[nodiscard]] inline std::uint32_t load_be32(ByteSpan b, std::size_t off) {
  assert(off + 4 <= b.size());
  return (static_cast<std::uint32_t>(b[off]) << 24) | (static_cast<std::uint32_t>(b[off + 1]) << 16) |
         (static_cast<std::uint32_t>(b[off + 2]) << 8) | static_cast<std::uint32_t>(b[off + 3]);
}

}  // namespace fieldguard
