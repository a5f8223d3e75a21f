#pragma once
// Test scaffolding for the Velodyne driver tests: a data packet builder and a minimal classic-pcap reader.
// The drivers module must not depend on io, so the tests read their captures with this instead of io's reader.

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/drivers/velodyne_types.hpp"

namespace fieldguard::velodyne::test {

// A 1206-byte data packet: every block flagged FF EE, all azimuths and slots zero until set.
class PacketBuilder {
 public:
  PacketBuilder() : bytes_(kDataPacketSize, 0) {
    for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
      bytes_[b * kBlockSize] = 0xFF;
      bytes_[b * kBlockSize + 1] = 0xEE;
    }
    factory(0x37, 0x21);
  }
  PacketBuilder& azimuth(std::size_t block, std::uint16_t cdeg) {
    put16(block * kBlockSize + 2, cdeg);
    return *this;
  }
  // Azimuth of every block: first + step * block (mod 36000); with pairs=true blocks 2k and 2k+1 share one.
  PacketBuilder& azimuths(int first, int step, bool pairs = false) {
    for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
      const int k = pairs ? static_cast<int>(b / 2) : static_cast<int>(b);
      azimuth(b, static_cast<std::uint16_t>(((first + step * k) % 36000 + 36000) % 36000));
    }
    return *this;
  }
  PacketBuilder& slot(std::size_t block, std::size_t slot, std::uint16_t raw, std::uint8_t intensity) {
    const std::size_t off = block * kBlockSize + 4 + 3 * slot;
    put16(off, raw);
    bytes_[off + 2] = intensity;
    return *this;
  }
  PacketBuilder& timestamp(std::uint32_t us) {
    for (std::size_t i = 0; i < 4; ++i) bytes_[1200 + i] = static_cast<std::uint8_t>(us >> (8 * i));
    return *this;
  }
  PacketBuilder& factory(std::uint8_t return_byte, std::uint8_t product_byte) {
    bytes_[1204] = return_byte;
    bytes_[1205] = product_byte;
    return *this;
  }
  [[nodiscard]] std::vector<std::uint8_t>& bytes() { return bytes_; }
  [[nodiscard]] ByteSpan span() const { return bytes_; }

 private:
  void put16(std::size_t off, std::uint16_t v) {
    bytes_[off] = static_cast<std::uint8_t>(v & 0xFF);
    bytes_[off + 1] = static_cast<std::uint8_t>(v >> 8);
  }
  std::vector<std::uint8_t> bytes_;
};

struct UdpRecord {
  Stamp host;  // pcap record time
  std::uint16_t dst_port = 0;
  std::vector<std::uint8_t> payload;  // UDP payload (Ethernet + IPv4 without options + UDP = 42 bytes before it)
};

// Classic pcap (either byte order, µs or ns), linktype Ethernet, IPv4 without options. Returns the UDP records;
// an empty vector if the file is missing or not such a capture.
inline std::vector<UdpRecord> read_udp_records(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<UdpRecord> out;
  if (file.size() < 24) return out;
  const ByteSpan all(file);
  const std::uint32_t magic = load_le32(all, 0);
  const bool swapped = magic == 0xD4C3B2A1U || magic == 0x4D3CB2A1U;
  const bool nanos = magic == 0xA1B23C4DU || magic == 0x4D3CB2A1U;
  if (!swapped && magic != 0xA1B2C3D4U && magic != 0xA1B23C4DU) return out;
  auto u32 = [&](std::size_t off) { return swapped ? load_be32(all, off) : load_le32(all, off); };
  if (u32(20) != 1) return out;  // LINKTYPE_ETHERNET
  std::size_t off = 24;
  while (off + 16 <= file.size()) {
    const std::uint32_t sec = u32(off);
    const std::uint32_t frac = u32(off + 4);
    const std::uint32_t incl = u32(off + 8);
    off += 16;
    if (incl > file.size() - off) break;
    const ByteSpan frame = all.subspan(off, incl);
    off += incl;
    constexpr std::size_t kUdpPayload = 42;
    if (frame.size() < kUdpPayload || load_be16(frame, 12) != 0x0800 || frame[14] != 0x45 || frame[23] != 17) continue;
    UdpRecord r;
    r.host =
        Stamp{static_cast<std::int64_t>(sec) * 1'000'000'000 + static_cast<std::int64_t>(frac) * (nanos ? 1 : 1000)};
    r.dst_port = load_be16(frame, 36);
    const ByteSpan udp = frame.subspan(kUdpPayload);
    r.payload.assign(udp.begin(), udp.end());
    out.push_back(std::move(r));
  }
  return out;
}

// The data packets (1206-byte payloads) of a capture.
inline std::vector<UdpRecord> read_data_packets(const std::string& path) {
  std::vector<UdpRecord> out;
  for (auto& r : read_udp_records(path)) {
    if (r.payload.size() == kDataPacketSize) out.push_back(std::move(r));
  }
  return out;
}

inline std::string test_data(const std::string& name) { return std::string(FIELDGUARD_TEST_DATA) + "/" + name; }

}  // namespace fieldguard::velodyne::test
