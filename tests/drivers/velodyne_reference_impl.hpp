#pragma once
// The Velodyne decoder's and rotation assembler's algorithms as they were before they were made fast (commit
// ff177ca), kept here as the reference the fast ones are held to: a straightforward per-return loop with libm
// cos/sin/fmod/lround, and a per-point assembler that copies every point into its frame. Test code only.

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <utility>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/drivers/velodyne_calibration.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"

namespace fieldguard::velodyne::reference {

// Decoder::decode() before the azimuth table: same options, same calibration, libm per point.
class Decoder {
 public:
  Decoder(Calibration calibration, const DecoderOptions& options) : options_(options), cal_(std::move(calibration)) {
    if (cal_.ring_of_laser.size() != cal_.lasers.size()) assign_rings(cal_);
    constexpr double kRadPerDeg = std::numbers::pi / 180.0;
    for (std::size_t i = 0; i < cal_.lasers.size(); ++i) {
      const LaserCorrection& c = cal_.lasers[i];
      const int ring = cal_.ring_of_laser[i];
      table_.push_back(LaserTable{
          static_cast<float>(std::cos(c.vert_deg * kRadPerDeg)), static_cast<float>(std::sin(c.vert_deg * kRadPerDeg)),
          static_cast<float>(c.rot_deg * 100.0), static_cast<float>(c.dist_m), static_cast<float>(c.vert_offset_m),
          static_cast<float>(c.horiz_offset_m), static_cast<std::uint16_t>(ring < 0 ? 0 : ring)});
    }
  }

  // Model, return mode and errors are the fast decoder's business (read_packet_header() is shared): this only
  // decodes packets the fast decoder accepted.
  void decode(ByteSpan payload, const PacketHeader& header, std::vector<LidarPoint>& out) const {
    struct Layout {
      std::size_t lasers;
      std::size_t sequences;
      float block_us;
      float sequence_us;
      float firing_us;
    };
    const Layout lay = options_.model == Model::VLP16 ? Layout{16, 2, 110.592F, 55.296F, 2.304F}
                                                      : Layout{32, 1, 46.08F, 46.08F, 1.152F};
    const bool dual = header.return_mode == ReturnMode::Dual || header.dual_layout;
    const std::size_t step = dual ? 2 : 1;
    const std::size_t groups = kBlocksPerPacket / step;
    const float last_firing_us =
        static_cast<float>(groups - 1) * lay.block_us +
        (static_cast<float>(lay.sequences - 1) * lay.sequence_us + static_cast<float>(lay.lasers - 1) * lay.firing_us);
    const float ref_us = options_.timestamp_reference == TimestampReference::LastFiring ? last_firing_us : 0.F;
    std::array<float, kBlocksPerPacket> az{};
    std::array<float, kBlocksPerPacket> delta{};
    int fallback = 0;
    for (std::size_t g = 0; g < groups; ++g) {
      const int a = load_le16(payload, g * step * kBlockSize + 2);
      az[g] = static_cast<float>(a);
      int d = fallback;
      if (g + 1 < groups) {
        const int next = load_le16(payload, (g + 1) * step * kBlockSize + 2);
        const int raw_step = (next - a + 36000) % 36000;
        if (raw_step <= 500) d = raw_step;
      }
      fallback = d;
      delta[g] = static_cast<float>(d);
    }
    const ReturnType single_type = header.return_mode == ReturnMode::Last ? ReturnType::Last : ReturnType::Strongest;
    const auto res = static_cast<float>(cal_.distance_resolution_m);
    const auto min_r = static_cast<float>(options_.min_range_m);
    const auto max_r = static_cast<float>(options_.max_range_m);
    constexpr float kRadPerCdeg = std::numbers::pi_v<float> / 18000.F;
    for (std::size_t g = 0; g < groups; ++g) {
      const std::size_t block0 = g * step;
      const float group_us = static_cast<float>(g) * lay.block_us;
      for (std::size_t s = 0; s < lay.sequences; ++s) {
        for (std::size_t j = 0; j < lay.lasers; ++j) {
          const std::size_t slot = s * lay.lasers + j;
          const LaserTable& laser = table_[j];
          const float in_block_us = static_cast<float>(s) * lay.sequence_us + static_cast<float>(j) * lay.firing_us;
          const float azimuth = wrap_cdeg(az[g] + delta[g] * (in_block_us / lay.block_us) - laser.rot_cdeg);
          const float time_s = ((group_us + in_block_us) - ref_us) * 1e-6F;
          const float angle = azimuth * kRadPerCdeg;
          const float cos_a = std::cos(angle);
          const float sin_a = std::sin(angle);
          auto read = [&](std::size_t b, std::uint16_t& raw, std::uint8_t& intensity) {
            const std::size_t off = b * kBlockSize + 4 + 3 * slot;
            raw = load_le16(payload, off);
            intensity = payload[off + 2];
            if (raw == 0) return false;
            const float d = static_cast<float>(raw) * res + laser.dist_m;
            return d >= min_r && d <= max_r;
          };
          auto emit = [&](std::uint16_t raw, std::uint8_t intensity, ReturnType type) {
            const float d = static_cast<float>(raw) * res + laser.dist_m;
            const float xy = d * laser.cos_vert - laser.vert_offset_m * laser.sin_vert;
            LidarPoint p;
            p.x = xy * cos_a + laser.horiz_offset_m * sin_a;
            p.y = -xy * sin_a + laser.horiz_offset_m * cos_a;
            p.z = d * laser.sin_vert + laser.vert_offset_m * laser.cos_vert;
            p.intensity = static_cast<float>(intensity);
            p.time_s = time_s;
            p.range_m = d;
            const long r = std::lround(azimuth);
            p.azimuth_cdeg = static_cast<std::uint16_t>(r >= 36000 ? r - 36000 : r);
            p.ring = laser.ring;
            p.return_type = type;
            out.push_back(p);
          };
          std::uint16_t raw0 = 0;
          std::uint8_t int0 = 0;
          const bool ok0 = read(block0, raw0, int0);
          if (!dual) {
            if (ok0) emit(raw0, int0, single_type);
            continue;
          }
          std::uint16_t raw1 = 0;
          std::uint8_t int1 = 0;
          const bool ok1 = read(block0 + 1, raw1, int1);
          if (raw0 == raw1 && int0 == int1) {
            if (ok0) emit(raw0, int0, ReturnType::StrongestAndLast);
            continue;
          }
          if (ok0) emit(raw0, int0, ReturnType::Last);
          if (ok1) emit(raw1, int1, ReturnType::Strongest);
        }
      }
    }
  }

 private:
  struct LaserTable {
    float cos_vert;
    float sin_vert;
    float rot_cdeg;
    float dist_m;
    float vert_offset_m;
    float horiz_offset_m;
    std::uint16_t ring;
  };
  static float wrap_cdeg(float a) {
    a = std::fmod(a, 36000.F);
    if (a < 0.F) a += 36000.F;
    return a;
  }
  DecoderOptions options_;
  Calibration cal_;
  std::vector<LaserTable> table_;
};

// RotationAssembler::push() before the in-place assembly: every point copied into the frame with push_back.
class RotationAssembler {
 public:
  explicit RotationAssembler(double cut_deg) {
    double c = std::fmod(cut_deg, 360.0);
    if (c < 0.0) c += 360.0;
    const long cdeg = std::lround(c * 100.0);
    cut_cdeg_ = static_cast<std::uint16_t>(cdeg >= 36000 || cdeg < 0 ? 0 : cdeg);
  }

  void push(std::span<const LidarPoint> points, Stamp packet_sensor_time, Stamp packet_host_time,
            std::vector<LidarFrame>& done) {
    bool counted = false;
    for (const LidarPoint& p : points) {
      const int rel = (static_cast<int>(p.azimuth_cdeg) - static_cast<int>(cut_cdeg_) + 36000) % 36000;
      if (prev_rel_cdeg_ >= 0) {
        if (rel + 18000 < prev_rel_cdeg_) {
          if (have_current_) emit(done, !current_started_at_cut_);
          current_started_at_cut_ = true;
          counted = false;
          prev_rel_cdeg_ = rel;
        } else if (rel > prev_rel_cdeg_ + 18000 && prev_rel_cdeg_ + 36000 - rel <= 1000) {
        } else {
          prev_rel_cdeg_ = rel;
        }
      } else {
        prev_rel_cdeg_ = rel;
      }
      if (!have_current_) {
        have_current_ = true;
        const auto offset_ns = static_cast<std::int64_t>(std::llround(static_cast<double>(p.time_s) * 1e9));
        current_.sensor_stamp = Stamp{packet_sensor_time.ns + offset_ns};
        current_.host_stamp = packet_host_time;
        current_.packets = 0;
      }
      if (!counted) {
        ++current_.packets;
        counted = true;
      }
      LidarPoint q = p;
      const double packet_to_frame_s = static_cast<double>(packet_sensor_time.ns - current_.sensor_stamp.ns) * 1e-9;
      q.time_s = static_cast<float>(packet_to_frame_s + static_cast<double>(p.time_s));
      current_.points.push_back(q);
    }
  }

  void finish(std::vector<LidarFrame>& done) {
    if (have_current_ && !current_.points.empty()) emit(done, true);
    current_ = LidarFrame{};
    have_current_ = false;
    current_started_at_cut_ = false;
    prev_rel_cdeg_ = -1;
  }

 private:
  void emit(std::vector<LidarFrame>& done, bool partial) {
    current_.index = next_index_++;
    current_.partial = partial;
    done.push_back(std::move(current_));
    current_ = LidarFrame{};
    have_current_ = false;
  }

  std::uint16_t cut_cdeg_ = 0;
  LidarFrame current_;
  bool have_current_ = false;
  bool current_started_at_cut_ = false;
  int prev_rel_cdeg_ = -1;
  std::uint64_t next_index_ = 0;
};

}  // namespace fieldguard::velodyne::reference
