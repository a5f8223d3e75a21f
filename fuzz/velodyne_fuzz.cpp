// libFuzzer target for the Velodyne data packet path: header check, decoders (HDL-32E / VLP-16, both timestamp
// references), model detection, sensor time and rotation assembly, and velodyne::Stream (detection, decoding in
// place into the frame under construction, frame recycling). Traps on any broken output invariant.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "fieldguard/drivers/rotation_assembler.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"

namespace {

using namespace fieldguard;
using namespace fieldguard::velodyne;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

Decoder make(Model m, TimestampReference ref, bool odd_calibration) {
  Calibration cal = default_calibration(m);
  if (odd_calibration) {
    // Corrections that push azimuths across 0 and 360 degrees and ranges below zero.
    for (std::size_t i = 0; i < cal.lasers.size(); ++i) {
      cal.lasers[i].rot_deg = (i % 2 == 0 ? -1.0 : 1.0) * 725.3 * static_cast<double>(i % 3);
      cal.lasers[i].dist_m = i % 4 == 0 ? -2.0 : 0.3;
      cal.lasers[i].vert_offset_m = 0.1;
      cal.lasers[i].horiz_offset_m = -0.05;
    }
  }
  DecoderOptions o;
  o.model = m;
  o.timestamp_reference = ref;
  return Decoder(cal, o);
}

struct Decoders {
  std::vector<Decoder> all;
  Decoders() {
    for (Model m : {Model::HDL32E, Model::VLP16}) {
      for (auto ref : {TimestampReference::FirstFiring, TimestampReference::LastFiring}) {
        all.push_back(make(m, ref, false));
      }
      all.push_back(make(m, TimestampReference::LastFiring, true));
    }
  }
};

void check_points(const std::vector<LidarPoint>& pts, Model m) {
  const std::uint16_t rings = m == Model::VLP16 ? 16 : 32;
  for (const LidarPoint& p : pts) {
    check(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.time_s));
    check(p.azimuth_cdeg < 36000);
    check(p.ring < rings);
    check(p.range_m >= 0.5F && p.range_m <= 130.F);
    check(p.time_s > -2e-3F && p.time_s < 2e-3F);
    check(p.intensity >= 0.F && p.intensity <= 255.F);
    const auto t = static_cast<std::uint8_t>(p.return_type);
    check(t >= 1 && t <= 3);
  }
}

// The input as it is, cut or padded to 1206 bytes, and "repaired" (flags FF EE, azimuths < 36000) so that the
// decoders get past the header check and run on arbitrary slot contents.
std::vector<std::uint8_t> repaired(ByteSpan in) {
  std::vector<std::uint8_t> p(in.begin(), in.end());
  p.resize(kDataPacketSize, 0);
  for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
    const std::size_t o = b * kBlockSize;
    p[o] = 0xFF;
    p[o + 1] = 0xEE;
    const auto az = static_cast<std::uint16_t>(load_le16(p, o + 2) % 36000);
    p[o + 2] = static_cast<std::uint8_t>(az & 0xFF);
    p[o + 3] = static_cast<std::uint8_t>(az >> 8);
  }
  return p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Decoders decoders;
  static std::vector<LidarPoint> pts;
  const ByteSpan input(data, size);

  std::vector<std::uint8_t> padded(input.begin(), input.end());
  padded.resize(kDataPacketSize, 0);
  const std::vector<std::uint8_t> fixed = repaired(input);
  for (const ByteSpan variant : {input, ByteSpan(padded), ByteSpan(fixed)}) {
    const auto h = read_packet_header(variant);
    for (const Decoder& d : decoders.all) {
      pts.clear();
      const auto r = d.decode(variant, pts);
      if (r.has_value()) check(h.has_value());
      if (!r.has_value()) check(pts.empty());
      check_points(pts, d.model());
    }
  }

  // A stream: the input cut into packets (each repaired), then the repaired input repeated with timestamps
  // advancing by a spacing taken from the input, through the detector, sensor time and the assembler.
  const std::uint32_t spacing = size >= 2 ? static_cast<std::uint32_t>(data[0] | (data[1] << 8)) : 553U;
  const double cut_deg = size >= 3 ? static_cast<double>(data[2]) * 1.5 - 20.0 : 0.0;
  const std::int64_t host0 = size >= 8 ? static_cast<std::int64_t>(load_le32(input, 4)) * 1'000'000'000LL : 0;
  std::vector<std::vector<std::uint8_t>> stream;
  for (std::size_t off = 0; off < size; off += kDataPacketSize) stream.push_back(repaired(input.subspan(off)));
  for (std::uint32_t k = 1; k <= 12; ++k) {
    std::vector<std::uint8_t> p = fixed;
    const std::uint32_t t = load_le32(p, 1200) + k * spacing;
    for (std::size_t i = 0; i < 4; ++i) p[1200 + i] = static_cast<std::uint8_t>(t >> (8 * i));
    stream.push_back(std::move(p));
  }

  ModelDetector detector;
  RotationAssembler assembler(cut_deg);
  std::vector<LidarFrame> frames;
  const Decoder& hdl = decoders.all[1];
  std::int64_t host = host0;
  for (const auto& p : stream) {
    const auto h = read_packet_header(p);
    if (!h) continue;
    detector.observe(*h);
    host += 552'960;
    const Stamp sensor = sensor_time_from_hour_offset(h->timestamp_us, Stamp{host});
    check(std::llabs(sensor.ns - host) <= 1'800'000'000'000LL);
    pts.clear();
    if (hdl.decode(p, pts).has_value()) assembler.push(pts, sensor, Stamp{host}, frames);
  }
  if (detector.decided()) check(!detector.reason().empty());
  assembler.finish(frames);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    check(frames[i].index == i);
    check(!frames[i].points.empty());
    check(frames[i].packets >= 1);
    for (const auto& q : frames[i].points) check(std::isfinite(q.time_s));
  }
  check(assembler.frames_emitted() == frames.size());

  // The same packets through two velodyne::Streams (model detected from the stream, decoding in place): one
  // recycles every frame as soon as it has it, the other never does. Reused buffers must not change a single
  // point, and the counters must add up.
  velodyne::StreamOptions options;
  options.rotation_cut_deg = cut_deg;
  options.max_undecided_packets = 4;
  velodyne::Stream recycling(options);
  velodyne::Stream keeping(options);
  std::vector<LidarFrame> kept;
  std::vector<LidarFrame> out;
  std::vector<LidarFrame> seen;  // copies of what the recycling stream emitted
  host = host0;
  const auto take = [&](std::vector<LidarFrame>& got) {
    for (LidarFrame& f : got) {
      seen.push_back(f);
      recycling.recycle(std::move(f));
    }
    got.clear();
  };
  for (const auto& p : stream) {
    host += 552'960;
    recycling.push(p, Stamp{host}, out);
    take(out);
    keeping.push(p, Stamp{host}, kept);
  }
  recycling.finish(out);
  take(out);
  keeping.finish(kept);
  check(seen.size() == kept.size());
  std::uint64_t points = 0;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    check(seen[i].index == i && kept[i].index == i);
    check(seen[i].points.size() == kept[i].points.size());
    for (std::size_t j = 0; j < kept[i].points.size(); ++j) {
      const LidarPoint& a = seen[i].points[j];
      const LidarPoint& b = kept[i].points[j];
      check(a.x == b.x && a.y == b.y && a.z == b.z && a.time_s == b.time_s && a.ring == b.ring &&
            a.azimuth_cdeg == b.azimuth_cdeg && a.intensity == b.intensity);
    }
    const std::uint16_t rings = keeping.model() == Model::VLP16 ? 16 : 32;
    for (const LidarPoint& q : kept[i].points) {
      check(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.time_s));
      check(q.ring < rings && q.range_m >= 0.5F && q.range_m <= 130.F);
    }
    points += kept[i].points.size();
  }
  const velodyne::StreamCounters& c = recycling.counters();
  check(c.packets == stream.size());
  check(c.decoded + c.rejected() == c.packets);
  check(c.points == points);
  check(c.full_rotations + c.partial_rotations == kept.size());
  return 0;
}
