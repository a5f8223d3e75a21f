// libFuzzer target for the RoboSense RS-32 path: MSOP header, DIFOP parsing, the decoder in every distance unit
// and return mode (configured and DIFOP-calibrated), and the stream with rotation assembly. Traps on any broken
// output invariant.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fieldguard/drivers/robosense.hpp"
#include "fieldguard/drivers/robosense_stream.hpp"

namespace {

using namespace fieldguard;
using namespace fieldguard::robosense;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

constexpr std::array<std::uint8_t, 8> kMsopMagic = {0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0};
constexpr std::array<std::uint8_t, 8> kDifopMagic = {0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};

Calibration odd_calibration() {
  Calibration c;
  for (std::size_t i = 0; i < kChannels; ++i) {
    c.vert_deg[i] = -89.9 + 5.6 * static_cast<double>(i);
    c.horiz_deg[i] = (i % 2 == 0 ? 1.0 : -1.0) * 89.0 * static_cast<double>(i % 3) / 2.0;
  }
  return c;
}

struct Decoders {
  std::vector<Decoder> all;
  Decoders() {
    for (auto unit : {DistanceUnitOption::HalfCm, DistanceUnitOption::OneCmGrouped}) {
      for (auto mode :
           {std::optional<ReturnMode>{}, std::optional{ReturnMode::Dual}, std::optional{ReturnMode::Last}}) {
        DecoderOptions o;
        o.calibration = odd_calibration();
        o.distance_unit = unit;
        o.return_mode = mode;
        all.emplace_back(o);
      }
    }
  }
};

void check_points(const std::vector<LidarPoint>& pts, const DecoderOptions& o) {
  constexpr float kMaxTimeS = static_cast<float>((12 * kBlockDurationUs + 47.0) * 1e-6);
  for (const LidarPoint& p : pts) {
    check(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.time_s));
    check(p.azimuth_cdeg < 36000);
    check(p.ring < kChannels);
    check(p.range_m >= static_cast<float>(o.min_range_m) - 1e-3F &&
          p.range_m <= static_cast<float>(o.max_range_m) + 1e-3F);
    check(p.time_s >= 0.F && p.time_s <= kMaxTimeS);
    check(p.intensity >= 0.F && p.intensity <= 255.F);
    const float norm = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    check(std::abs(norm - p.range_m) <= 0.05F + 1e-4F * p.range_m);  // the optical-centre offset is 4 cm
    const auto t = static_cast<std::uint8_t>(p.return_type);
    check(t >= 1 && t <= 4);
  }
}

// The input cut or padded to 1248 bytes and given the MSOP magic, block flags, in-range azimuths and a valid
// timestamp, so that the decoders run on arbitrary channel contents.
std::vector<std::uint8_t> repaired_msop(ByteSpan in) {
  std::vector<std::uint8_t> p(in.begin(), in.end());
  p.resize(kPacketSize, 0);
  std::copy(kMsopMagic.begin(), kMsopMagic.end(), p.begin());
  p[20] = static_cast<std::uint8_t>(p[20] % 100);
  p[21] = static_cast<std::uint8_t>(1 + p[21] % 12);
  p[22] = static_cast<std::uint8_t>(1 + p[22] % 28);
  p[23] = static_cast<std::uint8_t>(p[23] % 24);
  p[24] = static_cast<std::uint8_t>(p[24] % 60);
  p[25] = static_cast<std::uint8_t>(p[25] % 60);
  p[26] = static_cast<std::uint8_t>(p[26] % 3);  // ms < 1000 (767 at most)
  p[28] = static_cast<std::uint8_t>(p[28] % 3);  // us < 1000 (768 at most)
  for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
    const std::size_t o = kHeaderSize + b * kBlockSize;
    p[o] = 0xFF;
    p[o + 1] = 0xEE;
    const auto az = static_cast<std::uint16_t>(load_be16(p, o + 2) % 36000);
    p[o + 2] = static_cast<std::uint8_t>(az >> 8);
    p[o + 3] = static_cast<std::uint8_t>(az & 0xFF);
  }
  return p;
}

std::vector<std::uint8_t> repaired_difop(ByteSpan in) {
  std::vector<std::uint8_t> p(in.begin(), in.end());
  p.resize(kPacketSize, 0);
  std::copy(kDifopMagic.begin(), kDifopMagic.end(), p.begin());
  for (std::size_t i = 468; i < 660; i += 3) p[i] = static_cast<std::uint8_t>(p[i] & 0x01);  // decodable signs
  return p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Decoders decoders;
  static std::vector<LidarPoint> pts;
  const ByteSpan input(data, size);
  const std::vector<std::uint8_t> msop = repaired_msop(input);
  const std::vector<std::uint8_t> difop = repaired_difop(input);

  for (const ByteSpan variant : {input, ByteSpan(msop), ByteSpan(difop)}) {
    const auto h = read_msop_header(variant);
    if (h) check(h->sensor_time.ns > 0);
    const auto d = parse_difop(variant);
    if (d && d->calibration) {
      for (std::size_t c = 0; c < kChannels; ++c) {
        check(std::abs(d->calibration->vert_deg[c]) < 90.0 && std::abs(d->calibration->horiz_deg[c]) < 90.0);
      }
    }
    for (const Decoder& dec : decoders.all) {
      pts.clear();
      const auto r = dec.decode(variant, pts);
      check(r.has_value() == h.has_value());
      if (!r) check(pts.empty());
      check(pts.size() <= kBlocksPerPacket * kChannels);
      check_points(pts, DecoderOptions{});
    }
  }

  // DIFOP-calibrated decoding of the repaired packet, and a stream: the repaired DIFOP, then the input cut into
  // packets (each repaired) with advancing time, through the assembler.
  const auto d = parse_difop(difop);
  if (d) {
    Decoder dec;
    dec.apply(*d);
    check(dec.ready() == d->calibration.has_value());
    pts.clear();
    const auto r = dec.decode(msop, pts);
    if (!dec.ready()) check(!r.has_value() && r.error() == DecodeError::NoCalibration);
    check_points(pts, DecoderOptions{});
  }
  StreamOptions so;
  so.rotation_cut_deg = size > 0 ? static_cast<double>(data[0]) * 1.5 : 0.0;
  Stream stream(so);
  std::vector<LidarFrame> frames;
  stream.push_difop(difop);
  for (std::size_t off = 0, k = 0; off < size || k < 3; off += kPacketSize, ++k) {
    std::vector<std::uint8_t> p = repaired_msop(off < size ? input.subspan(off) : input);
    p[42 + 2] = static_cast<std::uint8_t>((p[42 + 2] + 3 * k) % 140);  // move the azimuths along
    stream.push_msop(p, Stamp{static_cast<std::int64_t>(k) * 666'240}, frames);
  }
  stream.push_msop(input, Stamp{1}, frames);
  stream.finish(frames);
  const auto& c = stream.counters();
  check(c.msop_decoded + c.msop_rejected() == c.msop_packets);
  check(c.difop_accepted + c.difop_rejected() == c.difop_packets);
  check(c.full_rotations + c.partial_rotations == frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    check(frames[i].index == i);
    check(!frames[i].points.empty());
    for (const auto& q : frames[i].points) check(std::isfinite(q.time_s) && std::isfinite(q.x));
  }
  return 0;
}
