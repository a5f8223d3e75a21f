// libFuzzer target for the 3D LiDAR stream as replay and the daemon drive it: a sequence of datagrams to the
// Velodyne data, RS-32 MSOP and DIFOP channels, in auto mode and with each model configured, through the model
// decision, the refusal of other RoboSense models, both families' decoders and rotation assembly.
//
// Input: records of [selector][payload...]. The selector's low two bits pick the channel (3 = MSOP again); bit 2
// writes the channel's own header over the payload (Velodyne block flags, the MSOP header and model byte 0x02, the
// DIFOP magic) so that most records get past the header checks; bit 3 makes the record short (its length from the
// next byte). A record takes the channel's packet length (1206 or 1248 bytes) from the input, zero-padded.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fieldguard/drivers/lidar3d_stream.hpp"

namespace {

using namespace fieldguard;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

constexpr std::array<std::uint8_t, 8> kMsopMagic = {0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0};
constexpr std::array<std::uint8_t, 8> kDifopMagic = {0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};

void check_frames(const std::vector<LidarFrame>& frames) {
  for (const LidarFrame& f : frames) {
    for (const LidarPoint& p : f.points) {
      check(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.time_s));
      check(p.azimuth_cdeg < 36000);
      check(p.ring < 32);
    }
  }
}

void run(lidar3d::Model model, const std::uint8_t* data, std::size_t size) {
  lidar3d::StreamOptions o;
  o.model = model;
  o.robosense.decoder.nominal_until_difop = true;
  lidar3d::Stream s(o);
  std::vector<LidarFrame> frames;
  std::vector<std::uint8_t> payload;
  std::size_t i = 0;
  std::uint64_t pushed = 0;
  while (i < size) {
    const std::uint8_t sel = data[i++];
    const auto channel = static_cast<lidar3d::Channel>((sel & 3U) == 3U ? 1U : (sel & 3U));
    std::size_t len = channel == lidar3d::Channel::VelodyneData ? 1206 : 1248;
    if ((sel & 8U) != 0 && i < size) len = data[i++];
    payload.assign(len, 0);
    const std::size_t take = std::min(len, size - i);
    std::copy(data + i, data + i + take, payload.begin());
    i += take;
    if ((sel & 4U) != 0) {
      if (channel == lidar3d::Channel::VelodyneData && len == 1206) {
        for (std::size_t b = 0; b < 12; ++b) {
          payload[100 * b] = 0xFF;
          payload[100 * b + 1] = 0xEE;
        }
      } else if (len == 1248) {
        const auto& magic = channel == lidar3d::Channel::Msop ? kMsopMagic : kDifopMagic;
        std::copy(magic.begin(), magic.end(), payload.begin());
        if (channel == lidar3d::Channel::Msop) payload[30] = 0x02;
      }
    }
    frames.clear();
    (void)s.push(channel, payload, Stamp{static_cast<std::int64_t>(pushed) * 500'000}, frames);
    ++pushed;
    check_frames(frames);
    for (LidarFrame& f : frames) s.recycle(std::move(f));
  }
  frames.clear();
  s.finish(frames);
  check_frames(frames);
  const lidar3d::Counters c = s.counters();
  check(c.decoded <= c.data_packets);
  check(c.data_packets + c.info_packets + c.other_family + c.refused + c.bad_length <= pushed);
  if (s.model()) check(s.family() != lidar3d::Family::Undecided);
  (void)s.ring_elevations_deg();
  (void)s.reason();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  for (const auto m : {lidar3d::Model::Auto, lidar3d::Model::RS32, lidar3d::Model::HDL32E}) run(m, data, size);
  return 0;
}
