// RoboSense RS-32 stream: decoding, DIFOP handling and rotation assembly, with counters.
#include "fieldguard/drivers/robosense_stream.hpp"

#include <numeric>
#include <utility>

namespace fieldguard::robosense {

std::uint64_t StreamCounters::msop_rejected() const {
  return std::accumulate(msop_errors.begin(), msop_errors.end(), std::uint64_t{0});
}
std::uint64_t StreamCounters::difop_rejected() const {
  return std::accumulate(difop_errors.begin(), difop_errors.end(), std::uint64_t{0});
}

Stream::Stream(StreamOptions options) : decoder_(std::move(options.decoder)), assembler_(options.rotation_cut_deg) {}

void Stream::count_frames(const std::vector<LidarFrame>& frames, std::size_t from) {
  for (std::size_t i = from; i < frames.size(); ++i) {
    ++(frames[i].partial ? counters_.partial_rotations : counters_.full_rotations);
  }
}

void Stream::push_difop(ByteSpan payload) {
  ++counters_.difop_packets;
  auto d = parse_difop(payload);
  if (!d) {
    ++counters_.difop_errors[static_cast<std::size_t>(d.error())];
    return;
  }
  ++counters_.difop_accepted;
  if (!d->calibration) ++counters_.difop_without_angles;
  if (decoder_.apply(*d)) ++counters_.difop_angle_changes;
  last_difop_ = std::move(*d);
}

void Stream::push_msop(ByteSpan payload, Stamp host_time, std::vector<LidarFrame>& frames) {
  ++counters_.msop_packets;
  // Straight into the rotation under construction (no copy through a scratch buffer).
  std::size_t written = 0;
  AzimuthRange azimuths;
  const auto header = decoder_.decode(payload, assembler_.append_room(kMaxPointsPerPacket), written, &azimuths);
  if (!header) {
    ++counters_.msop_errors[static_cast<std::size_t>(header.error())];
    return;
  }
  ++counters_.msop_decoded;
  counters_.points += written;
  const std::size_t before = frames.size();
  assembler_.commit(written, header->sensor_time, host_time, frames, azimuths);
  count_frames(frames, before);
}

void Stream::finish(std::vector<LidarFrame>& frames) {
  const std::size_t before = frames.size();
  assembler_.finish(frames);
  count_frames(frames, before);
}

}  // namespace fieldguard::robosense
