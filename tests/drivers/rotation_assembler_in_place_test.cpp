// In-place rotation assembly (RotationAssembler::append_room() / commit(), used by velodyne::Stream) and frame
// recycling against the assembler it replaced (velodyne_reference_impl.hpp): the same frames, bit for bit.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "drivers/velodyne_reference_impl.hpp"
#include "drivers/velodyne_test_support.hpp"
#include "fieldguard/drivers/rotation_assembler.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"

namespace fieldguard {
namespace {

using namespace velodyne;

void expect_same_frames(const std::vector<LidarFrame>& a, const std::vector<LidarFrame>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t k = 0; k < a.size(); ++k) {
    SCOPED_TRACE(what + ", frame " + std::to_string(k));
    EXPECT_EQ(a[k].index, b[k].index);
    EXPECT_EQ(a[k].partial, b[k].partial);
    EXPECT_EQ(a[k].packets, b[k].packets);
    EXPECT_EQ(a[k].sensor_stamp, b[k].sensor_stamp);
    EXPECT_EQ(a[k].host_stamp, b[k].host_stamp);
    ASSERT_EQ(a[k].points.size(), b[k].points.size());
    ASSERT_EQ(std::memcmp(static_cast<const void*>(a[k].points.data()), static_cast<const void*>(b[k].points.data()),
                          a[k].points.size() * sizeof(LidarPoint)),
              0);
  }
}

struct Decoded {
  std::vector<std::vector<LidarPoint>> points;  // per packet, time_s packet-relative
  std::vector<Stamp> sensor;
  std::vector<Stamp> host;
};

// The tight azimuth bounds of a packet's points, as a decoder reports them (non-empty `pts`).
AzimuthRange azimuth_bounds_of(const std::vector<LidarPoint>& pts) {
  int lo = 65535;
  int hi = 0;
  for (const auto& p : pts) {
    lo = std::min<int>(lo, p.azimuth_cdeg);
    hi = std::max<int>(hi, p.azimuth_cdeg);
  }
  return AzimuthRange{static_cast<std::uint16_t>(lo), static_cast<std::uint16_t>(hi)};
}

Decoded decode_capture(const char* file, Model model, const Calibration& cal) {
  DecoderOptions o;
  o.model = model;
  const Decoder d(cal, o);
  Decoded out;
  for (const auto& r : test::read_data_packets(test::test_data(file))) {
    std::vector<LidarPoint> pts;
    const auto h = d.decode(r.payload, pts);
    if (!h) continue;
    out.points.push_back(std::move(pts));
    out.sensor.push_back(sensor_time_from_hour_offset(h->timestamp_us, r.host));
    out.host.push_back(r.host);
  }
  return out;
}

// Real captures at several cut angles, with and without per-laser azimuth corrections (points a little before
// the cut after it), through push(), through append_room() / commit(), and with recycling.
TEST(RotationAssemblerInPlace, RealCapturesGiveTheReferenceFrames) {
  struct Case {
    const char* file;
    Model model;
  };
  for (const Case& c : {Case{"hdl32e_monterey_600.pcap", Model::HDL32E}, Case{"vlp16_veloview_300.pcap", Model::VLP16},
                        Case{"velodyne_vlp32.pcap", Model::HDL32E}}) {
    for (int corrections = 0; corrections < 2; ++corrections) {
      Calibration cal = default_calibration(c.model);
      if (corrections) {
        for (std::size_t i = 0; i < cal.lasers.size(); ++i) cal.lasers[i].rot_deg = i % 3 == 0 ? 2.5 : -1.0;
      }
      const Decoded dec = decode_capture(c.file, c.model, cal);
      ASSERT_FALSE(dec.points.empty()) << c.file;
      for (double cut : {0.0, 90.0, 150.0, 359.99, -45.0}) {
        const std::string what =
            std::string(c.file) + " cut " + std::to_string(cut) + (corrections ? " with corrections" : "");
        reference::RotationAssembler ref(cut);
        RotationAssembler pushed(cut, RotationClose::NextRotation);
        RotationAssembler in_place(cut, RotationClose::NextRotation);
        RotationAssembler recycling(cut, RotationClose::NextRotation);
        std::vector<LidarFrame> want;
        std::vector<LidarFrame> got_push;
        std::vector<LidarFrame> got_in_place;
        std::vector<LidarFrame> got_recycling;
        std::vector<LidarFrame> recycled_copies;
        for (std::size_t k = 0; k < dec.points.size(); ++k) {
          ref.push(dec.points[k], dec.sensor[k], dec.host[k], want);
          pushed.push(dec.points[k], dec.sensor[k], dec.host[k], got_push);
          // Room larger than needed, holding garbage: only `count` points are committed.
          const std::size_t n = dec.points[k].size();
          const std::span<LidarPoint> room = in_place.append_room(n + 100);
          ASSERT_EQ(room.size(), n + 100);
          std::memset(static_cast<void*>(room.data()), 0x5A, room.size() * sizeof(LidarPoint));
          std::copy(dec.points[k].begin(), dec.points[k].end(), room.begin());
          in_place.commit(n, dec.sensor[k], dec.host[k], got_in_place);
          // The consumer copies each frame and hands it back at once.
          std::vector<LidarFrame> done;
          recycling.push(dec.points[k], dec.sensor[k], dec.host[k], done);
          for (auto& f : done) {
            recycled_copies.push_back(f);
            recycling.recycle(std::move(f));
          }
        }
        ref.finish(want);
        pushed.finish(got_push);
        in_place.finish(got_in_place);
        std::vector<LidarFrame> done;
        recycling.finish(done);
        for (auto& f : done) recycled_copies.push_back(std::move(f));
        expect_same_frames(got_push, want, what + ", push()");
        expect_same_frames(got_in_place, want, what + ", append_room()/commit()");
        expect_same_frames(recycled_copies, want, what + ", recycled");
        if (HasFatalFailure()) return;
      }
    }
  }
}

// Random azimuth walks: forward steps, steps back of every size, jumps, azimuths >= 36000 (push() takes any u16),
// packets of 0..40 points, pushed by the two APIs in turn.
TEST(RotationAssemblerInPlace, RandomStreamsGiveTheReferenceFrames) {
  std::mt19937 rng(7);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  for (int run = 0; run < 40; ++run) {
    const double cut = run % 4 == 0 ? 0.0 : uniform(0, 35999) / 100.0;
    reference::RotationAssembler ref(cut);
    RotationAssembler fast(cut, RotationClose::NextRotation);
    std::vector<LidarFrame> want;
    std::vector<LidarFrame> got;
    int az = uniform(0, 35999);
    std::int64_t t = 1'000'000'000'000;
    for (int packet = 0; packet < 400; ++packet) {
      std::vector<LidarPoint> pts(static_cast<std::size_t>(uniform(0, 40)));
      for (std::size_t i = 0; i < pts.size(); ++i) {
        const int kind = uniform(0, 99);
        az += kind < 80 ? uniform(0, 60) : kind < 90 ? -uniform(0, 1200) : kind < 97 ? uniform(0, 36000) : 0;
        az = ((az % 36000) + 36000) % 36000;
        pts[i].azimuth_cdeg = static_cast<std::uint16_t>(kind == 99 ? uniform(36000, 65535) : az);
        pts[i].time_s = static_cast<float>(i) * 1.152e-6F - 5e-4F;
        pts[i].intensity = static_cast<float>(uniform(0, 255));
        pts[i].x = static_cast<float>(packet);
      }
      t += uniform(0, 2'000'000);
      ref.push(pts, Stamp{t}, Stamp{t + 700}, want);
      if (packet % 2 == 0) {
        fast.push(pts, Stamp{t}, Stamp{t + 700}, got);
      } else {
        const std::span<LidarPoint> room = fast.append_room(pts.size());
        std::copy(pts.begin(), pts.end(), room.begin());
        fast.commit(pts.size(), Stamp{t}, Stamp{t + 700}, got);
      }
      if (packet == 200) {  // end of a stream and start of another in the same assembler
        ref.finish(want);
        fast.finish(got);
      }
    }
    ref.finish(want);
    fast.finish(got);
    expect_same_frames(got, want, "run " + std::to_string(run));
    if (HasFatalFailure()) return;
  }
}

// commit() with azimuth bounds: random walks as above, each packet committed with bounds that hold its azimuths
// (tight, loose, or none at all), against the reference. Packets with an azimuth >= 36000 get bounds that say so.
TEST(RotationAssemblerInPlace, AzimuthBoundsGiveTheReferenceFrames) {
  std::mt19937 rng(11);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  std::size_t fast_packets = 0;
  for (int run = 0; run < 40; ++run) {
    const double cut = run % 4 == 0 ? 0.0 : uniform(0, 35999) / 100.0;
    reference::RotationAssembler ref(cut);
    RotationAssembler fast(cut, RotationClose::NextRotation);
    std::vector<LidarFrame> want;
    std::vector<LidarFrame> got;
    int az = uniform(0, 35999);
    std::int64_t t = 1'000'000'000'000;
    for (int packet = 0; packet < 400; ++packet) {
      // Mostly packets as a sensor gives them (a small forward sweep), some of random walks with jumps.
      const bool sweep = uniform(0, 9) != 0;
      std::vector<LidarPoint> pts(static_cast<std::size_t>(uniform(0, 40)));
      for (std::size_t i = 0; i < pts.size(); ++i) {
        const int kind = sweep ? uniform(0, 79) : uniform(0, 99);
        az += kind < 80 ? uniform(0, 60) : kind < 90 ? -uniform(0, 1200) : kind < 97 ? uniform(0, 36000) : 0;
        az = ((az % 36000) + 36000) % 36000;
        pts[i].azimuth_cdeg = static_cast<std::uint16_t>(kind == 99 ? uniform(36000, 65535) : az);
        pts[i].time_s = static_cast<float>(i) * 1.152e-6F - 5e-4F;
        pts[i].x = static_cast<float>(packet);
      }
      AzimuthRange bounds;
      if (!pts.empty() && uniform(0, 9) != 0) {
        bounds = azimuth_bounds_of(pts);
        if (uniform(0, 1) == 0) {  // loose
          bounds.min_cdeg = static_cast<std::uint16_t>(std::max(0, bounds.min_cdeg - uniform(0, 3000)));
          bounds.max_cdeg = static_cast<std::uint16_t>(std::min(65535, bounds.max_cdeg + uniform(0, 3000)));
        }
      }
      t += uniform(0, 2'000'000);
      ref.push(pts, Stamp{t}, Stamp{t + 700}, want);
      const std::span<LidarPoint> room = fast.append_room(pts.size());
      std::copy(pts.begin(), pts.end(), room.begin());
      fast.commit(pts.size(), Stamp{t}, Stamp{t + 700}, got, bounds);
      if (packet == 200) {  // end of a stream and start of another in the same assembler
        ref.finish(want);
        fast.finish(got);
      }
      if (bounds.max_cdeg < 36000 && !pts.empty()) ++fast_packets;
    }
    ref.finish(want);
    fast.finish(got);
    expect_same_frames(got, want, "run " + std::to_string(run));
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(fast_packets, 40U * 400U / 2);
}

// A decoder that makes the times frame-relative itself (velodyne::Stream): where in_frame_offset_s() gives an
// offset, the points are written with float(offset + double(time)) and commit_in_frame()ted; elsewhere as before.
// The same frames as the reference, bit for bit; and the offset is refused before any frame, and where the bounds
// hold the cut or are no information.
TEST(RotationAssemblerInPlace, FrameRelativeTimesFromTheDecoderGiveTheReferenceFrames) {
  std::mt19937 rng(23);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  std::size_t in_frame = 0;
  std::size_t empty_in_frame = 0;
  for (int run = 0; run < 40; ++run) {
    const double cut = run % 4 == 0 ? 0.0 : uniform(0, 35999) / 100.0;
    reference::RotationAssembler ref(cut);
    RotationAssembler fast(cut, RotationClose::NextRotation);
    std::vector<LidarFrame> want;
    std::vector<LidarFrame> got;
    EXPECT_FALSE(fast.in_frame_offset_s(AzimuthRange{100, 200}, Stamp{0}).has_value()) << "no frame under way";
    int az = uniform(0, 35999);
    std::int64_t t = 1'000'000'000'000;
    for (int packet = 0; packet < 400; ++packet) {
      std::vector<LidarPoint> pts(static_cast<std::size_t>(uniform(0, 40)));
      for (std::size_t i = 0; i < pts.size(); ++i) {
        const int kind = uniform(0, 99);
        az += kind < 90 ? uniform(0, 60) : kind < 95 ? -uniform(0, 1200) : uniform(0, 36000);
        az = ((az % 36000) + 36000) % 36000;
        pts[i].azimuth_cdeg = static_cast<std::uint16_t>(az);
        pts[i].time_s = static_cast<float>(i) * 1.152e-6F - 5e-4F;
        pts[i].y = static_cast<float>(packet);
      }
      AzimuthRange bounds;
      if (!pts.empty() && uniform(0, 9) != 0) bounds = azimuth_bounds_of(pts);
      t += uniform(0, 2'000'000);
      ref.push(pts, Stamp{t}, Stamp{t + 700}, want);
      const std::optional<double> offset = fast.in_frame_offset_s(bounds, Stamp{t});
      if (bounds.max_cdeg >= 36000) {
        EXPECT_FALSE(offset.has_value());
      }
      const std::span<LidarPoint> room = fast.append_room(pts.size());
      std::copy(pts.begin(), pts.end(), room.begin());
      if (offset) {
        for (std::size_t i = 0; i < pts.size(); ++i) {
          room[i].time_s = static_cast<float>(*offset + static_cast<double>(pts[i].time_s));
        }
        fast.commit_in_frame(pts.size(), Stamp{t + 700}, got);
        ++(pts.empty() ? empty_in_frame : in_frame);
      } else {
        fast.commit(pts.size(), Stamp{t}, Stamp{t + 700}, got, bounds);
      }
      if (packet == 200) {
        ref.finish(want);
        fast.finish(got);
      }
    }
    ref.finish(want);
    fast.finish(got);
    expect_same_frames(got, want, "run " + std::to_string(run));
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(in_frame, 40U * 400U / 2);
}

// Bounds that are no information (the default, or min > max) are safe: the per-point path.
TEST(RotationAssemblerInPlace, UninformativeAzimuthBoundsAreSafe) {
  for (const AzimuthRange bounds : {AzimuthRange{}, AzimuthRange{500, 100}, AzimuthRange{0, 36000}}) {
    reference::RotationAssembler ref(0.0);
    RotationAssembler fast(0.0, RotationClose::NextRotation);
    std::vector<LidarFrame> want;
    std::vector<LidarFrame> got;
    for (int k = 0; k < 250; ++k) {
      std::vector<LidarPoint> pts(32);
      for (std::size_t i = 0; i < pts.size(); ++i) {
        pts[i].azimuth_cdeg = static_cast<std::uint16_t>((k * 360 + static_cast<int>(i) * 11) % 36000);
        pts[i].time_s = static_cast<float>(i) * 1e-6F;
      }
      ref.push(pts, Stamp{k * 1000}, Stamp{k * 1000}, want);
      const std::span<LidarPoint> room = fast.append_room(pts.size());
      std::copy(pts.begin(), pts.end(), room.begin());
      fast.commit(pts.size(), Stamp{k * 1000}, Stamp{k * 1000}, got, bounds);
    }
    ref.finish(want);
    fast.finish(got);
    ASSERT_GE(want.size(), 2U);
    expect_same_frames(got, want, "bounds " + std::to_string(bounds.min_cdeg) + ".." + std::to_string(bounds.max_cdeg));
  }
}

TEST(RotationAssemblerInPlace, RecycledBuffersAreReused) {
  RotationAssembler a(0.0);
  std::vector<LidarFrame> done;
  auto turn = [&](int turns) {
    for (int k = 0; k < turns * 100; ++k) {
      std::vector<LidarPoint> pts(384);
      for (std::size_t i = 0; i < pts.size(); ++i) {
        pts[i].azimuth_cdeg = static_cast<std::uint16_t>((k % 100) * 360 + static_cast<int>(i) * 360 / 384);
      }
      a.push(pts, Stamp{k}, Stamp{k}, done);
    }
  };
  turn(3);
  ASSERT_GE(done.size(), 2U);
  const LidarPoint* const buffer = done.back().points.data();
  a.recycle(std::move(done.back()));
  done.pop_back();
  done.clear();
  turn(2);
  ASSERT_FALSE(done.empty());
  bool reused = false;
  for (const auto& f : done) reused = reused || f.points.data() == buffer;
  EXPECT_TRUE(reused) << "a recycled buffer should hold a later frame";
  for (const auto& f : done) EXPECT_EQ(f.points.size(), 38400U);
}

// Stream decodes straight into the frame: the same frames and counters as decoding into a vector and pushing.
TEST(RotationAssemblerInPlace, StreamGivesTheFramesOfDecodeThenPush) {
  for (const char* file : {"hdl32e_monterey_600.pcap", "vlp16_veloview_300.pcap"}) {
    const auto packets = test::read_data_packets(test::test_data(file));
    StreamOptions so;  // model detected from the stream
    Stream stream(so);
    std::vector<LidarFrame> got;
    for (const auto& r : packets) stream.push(r.payload, r.host, got);
    stream.finish(got);
    ASSERT_TRUE(stream.model().has_value()) << file;
    DecoderOptions o;
    o.model = *stream.model();
    const Decoder d(default_calibration(o.model), o);
    reference::RotationAssembler ref(0.0);
    std::vector<LidarFrame> want;
    std::uint64_t points = 0;
    for (const auto& r : packets) {
      std::vector<LidarPoint> pts;
      const auto h = d.decode(r.payload, pts);
      if (!h) continue;
      points += pts.size();
      ref.push(pts, sensor_time_from_hour_offset(h->timestamp_us, r.host), r.host, want);
    }
    ref.finish(want);
    expect_same_frames(got, want, file);
    EXPECT_EQ(stream.counters().points, points);
    EXPECT_EQ(stream.counters().full_rotations + stream.counters().partial_rotations, want.size());
  }
}

}  // namespace
}  // namespace fieldguard
