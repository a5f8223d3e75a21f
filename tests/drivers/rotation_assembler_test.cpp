#include "fieldguard/drivers/rotation_assembler.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "drivers/velodyne_test_support.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"

namespace fieldguard {
namespace {

constexpr std::int64_t kPointNs = 10'000;  // 10 us between points
constexpr std::int64_t kHostDelayNs = 700'000;

// A synthetic sensor: point i at azimuth start + i * step (0.01 deg), sensor time t0 + i * 10 us, packets of
// `per_packet` points stamped with their first point's time.
struct Synthetic {
  int start_cdeg = 0;
  int step_cdeg = 17;
  std::size_t per_packet = 24;
  std::int64_t t0_ns = 1'000'000'000'000;

  [[nodiscard]] std::uint16_t azimuth(std::size_t i) const {
    return static_cast<std::uint16_t>((start_cdeg + step_cdeg * static_cast<int>(i)) % 36000);
  }
  [[nodiscard]] Stamp sensor(std::size_t i) const { return Stamp{t0_ns + static_cast<std::int64_t>(i) * kPointNs}; }

  // Pushes points [0, n) and returns the frames, finish() included.
  std::vector<LidarFrame> run(RotationAssembler& a, std::size_t n) const {
    std::vector<LidarFrame> done;
    for (std::size_t first = 0; first < n; first += per_packet) {
      std::vector<LidarPoint> pts;
      for (std::size_t i = first; i < std::min(n, first + per_packet); ++i) {
        LidarPoint p;
        p.azimuth_cdeg = azimuth(i);
        p.time_s = static_cast<float>(static_cast<double>(static_cast<std::int64_t>(i - first) * kPointNs) * 1e-9);
        p.intensity = static_cast<float>(i % 256);
        pts.push_back(p);
      }
      const Stamp s = sensor(first);
      a.push(pts, s, Stamp{s.ns + kHostDelayNs}, done);
    }
    a.finish(done);
    return done;
  }
};

// Index of the point that starts each frame, from the synthetic azimuths.
std::vector<std::size_t> frame_starts(const std::vector<LidarFrame>& frames) {
  std::vector<std::size_t> out;
  std::size_t i = 0;
  for (const auto& f : frames) {
    out.push_back(i);
    i += f.points.size();
  }
  return out;
}

TEST(RotationAssembler, ThreeAndAHalfRotations) {
  // Cut at 90 deg; start a quarter turn past it; 3.5 turns at 0.17 deg per point.
  Synthetic s{.start_cdeg = 18000, .step_cdeg = 17, .per_packet = 24};
  const std::size_t n = 3 * 36000 / 17 + 36000 / 34;  // 3.5 turns
  RotationAssembler a(90.0);
  const auto frames = s.run(a, n);
  ASSERT_EQ(frames.size(), 4U);
  EXPECT_EQ(a.frames_emitted(), 4U);
  const bool partial[] = {true, false, false, true};
  std::size_t total = 0;
  std::size_t packets = 0;
  const auto starts = frame_starts(frames);
  for (std::size_t k = 0; k < 4; ++k) {
    const LidarFrame& f = frames[k];
    SCOPED_TRACE(k);
    EXPECT_EQ(f.index, k);
    EXPECT_EQ(f.partial, partial[k]);
    const std::size_t i0 = starts[k];
    EXPECT_EQ(f.sensor_stamp.ns, s.sensor(i0).ns);
    // host stamp: the packet that holds the first point
    EXPECT_EQ(f.host_stamp.ns, s.sensor(i0 / s.per_packet * s.per_packet).ns + kHostDelayNs);
    EXPECT_NEAR(f.points.front().time_s, 0.0, 1e-9);
    for (std::size_t j = 0; j < f.points.size(); ++j) {
      ASSERT_NEAR(f.points[j].time_s, static_cast<double>(j) * 1e-5, 1e-7);
      ASSERT_EQ(f.points[j].intensity, static_cast<float>((i0 + j) % 256));
    }
    const std::size_t last = i0 + f.points.size() - 1;
    EXPECT_EQ(f.packets, last / s.per_packet - i0 / s.per_packet + 1);
    total += f.points.size();
    packets += f.packets;
    if (k > 0) {
      // A full frame starts at the first point at or past 90 deg, and the point before it is below 90 deg.
      EXPECT_GE(s.azimuth(i0), 9000);
      EXPECT_LT(s.azimuth(i0), 9000 + 17);
      EXPECT_LT(s.azimuth(i0 - 1), 9000);
    }
  }
  EXPECT_EQ(total, n);
  // 0.17 deg per point and 24 points per packet: every cut falls inside a packet, which counts in both frames.
  std::size_t splits = 0;
  for (std::size_t k = 1; k < 4; ++k) splits += starts[k] % s.per_packet != 0 ? 1U : 0U;
  EXPECT_EQ(splits, 3U);
  EXPECT_EQ(packets, (n + s.per_packet - 1) / s.per_packet + splits);
  // A full frame is one turn of points.
  EXPECT_NEAR(static_cast<double>(frames[1].points.size()), 36000.0 / 17.0, 1.0);
}

TEST(RotationAssembler, CutAtZeroAndNegativeCutAngle) {
  Synthetic s{.start_cdeg = 35000, .step_cdeg = 50, .per_packet = 10};
  RotationAssembler at_zero(0.0);
  const auto f0 = s.run(at_zero, 600);  // 600 * 0.5 deg: 350 -> 0 -> 290 deg
  ASSERT_EQ(f0.size(), 2U);
  EXPECT_EQ(f0[1].points.front().azimuth_cdeg, 0);
  RotationAssembler minus(-90.0);     // = 270 deg
  const auto f1 = s.run(minus, 600);  // 350 -> 0 -> 270 -> 290 deg: cut once at 270
  ASSERT_EQ(f1.size(), 2U);
  EXPECT_EQ(f1[1].points.front().azimuth_cdeg, 27000);
  EXPECT_TRUE(f1[0].partial);
  EXPECT_TRUE(f1[1].partial);
}

// One firing's last and strongest returns share an azimuth; per-laser corrections move azimuths back a little.
TEST(RotationAssembler, DualReturnsAndSmallStepsBackDoNotCut) {
  RotationAssembler a(0.0);
  std::vector<LidarFrame> done;
  std::vector<LidarPoint> pts;
  int az = 35000;
  for (int i = 0; i < 200; ++i) {
    for (int k = 0; k < 2; ++k) {  // last then strongest, same azimuth
      LidarPoint p;
      p.azimuth_cdeg = static_cast<std::uint16_t>(az % 36000);
      p.return_type = k == 0 ? ReturnType::Last : ReturnType::Strongest;
      pts.push_back(p);
    }
    LidarPoint back;  // a laser with a -0.3 deg correction
    back.azimuth_cdeg = static_cast<std::uint16_t>((az + 36000 - 30) % 36000);
    pts.push_back(back);
    az += 20;
    if (pts.size() >= 30) {
      a.push(pts, Stamp{1}, Stamp{2}, done);
      pts.clear();
    }
  }
  a.push(pts, Stamp{1}, Stamp{2}, done);
  EXPECT_EQ(done.size(), 1U);  // exactly one cut, at 0 deg
  a.finish(done);
  ASSERT_EQ(done.size(), 2U);
  EXPECT_LT(done[1].points.front().azimuth_cdeg, 20);
  // No point of the second frame is from before the cut, except the corrected ones right after it.
  for (const auto& p : done[1].points) ASSERT_TRUE(p.azimuth_cdeg < 30000 || p.azimuth_cdeg >= 35970);
}

TEST(RotationAssembler, GapsCutOnlyWhenTheyCrossTheCut) {
  RotationAssembler a(0.0);
  std::vector<LidarFrame> done;
  auto one = [&](int cdeg) {
    LidarPoint p;
    p.azimuth_cdeg = static_cast<std::uint16_t>(cdeg);
    a.push(std::span<const LidarPoint>(&p, 1), Stamp{1}, Stamp{1}, done);
  };
  one(1000);
  one(25000);  // lost packets, forward 240 deg without crossing 0
  one(26000);
  EXPECT_TRUE(done.empty());
  one(500);  // lost packets across 0
  EXPECT_EQ(done.size(), 1U);
  a.finish(done);
  ASSERT_EQ(done.size(), 2U);
  EXPECT_EQ(done[0].points.size(), 3U);
  EXPECT_EQ(done[1].points.size(), 1U);
  a.finish(done);  // nothing pending: no frame
  EXPECT_EQ(done.size(), 2U);
}

// The HDL-32E capture (velodyne_vlp32.pcap): 0.05 s, 221.7 deg -> 76.6 deg, less than a turn.
TEST(RotationAssembler, RealHdl32eCapture) {
  using namespace velodyne;
  const auto packets = test::read_data_packets(test::test_data("velodyne_vlp32.pcap"));
  ASSERT_EQ(packets.size(), 91U);
  DecoderOptions o;
  o.model = Model::HDL32E;
  const Decoder d(default_calibration(Model::HDL32E), o);
  auto assemble = [&](double cut_deg) {
    RotationAssembler a(cut_deg);
    std::vector<LidarFrame> done;
    std::vector<LidarPoint> pts;
    std::size_t total = 0;
    for (const auto& r : packets) {
      pts.clear();
      const auto h = d.decode(r.payload, pts);
      EXPECT_TRUE(h.has_value());
      if (!h) continue;
      total += pts.size();
      a.push(pts, sensor_time_from_hour_offset(h->timestamp_us, r.host), r.host, done);
    }
    a.finish(done);
    std::size_t assembled = 0;
    for (const auto& f : done) assembled += f.points.size();
    EXPECT_EQ(assembled, total);
    return done;
  };
  const auto behind = assemble(150.0);  // the cut is never passed
  ASSERT_EQ(behind.size(), 1U);
  EXPECT_TRUE(behind[0].partial);
  EXPECT_EQ(behind[0].index, 0U);
  EXPECT_EQ(behind[0].packets, 91U);
  EXPECT_EQ(behind[0].host_stamp, packets.front().host);
  EXPECT_NEAR(behind[0].points.back().time_s, 0.05, 0.002);

  const auto ahead = assemble(0.0);  // passed once, near the middle of the capture
  ASSERT_EQ(ahead.size(), 2U);
  EXPECT_TRUE(ahead[0].partial);
  EXPECT_TRUE(ahead[1].partial);
  EXPECT_LT(ahead[1].points.front().azimuth_cdeg, 100);
  EXPECT_GT(ahead[0].points.back().azimuth_cdeg, 35800);
  EXPECT_EQ(ahead[0].packets + ahead[1].packets, 92U);  // the packet with the cut counts in both
}

// A stream whose packets meet the cut on a packet boundary (an emulator's, or a sensor phase-locked to the cut): the
// rotation comes out with the packet carrying its last firing, not a packet later, with the points it has when it
// waits for the next rotation; and a stream that ends on a whole turn ends on a full rotation.
TEST(RotationAssembler, ARotationEndingBetweenPacketsIsEmittedWithItsLastPacket) {
  // 25 cdeg a firing, 24 firings a packet: 600 cdeg a packet, 60 packets a turn, the first at the cut.
  const Synthetic s{.start_cdeg = 0, .step_cdeg = 25, .per_packet = 24};
  const std::size_t turns = 4;
  const std::size_t n = turns * 36000 / 25;
  auto assemble = [&](RotationClose close, std::vector<std::size_t>& emitted_after) {
    RotationAssembler a(0.0, close);
    std::vector<LidarFrame> done;
    for (std::size_t first = 0; first < n; first += s.per_packet) {
      std::vector<LidarPoint> pts;
      for (std::size_t i = first; i < first + s.per_packet; ++i) {
        LidarPoint p;
        p.azimuth_cdeg = s.azimuth(i);
        p.time_s = static_cast<float>(static_cast<double>(static_cast<std::int64_t>(i - first) * kPointNs) * 1e-9);
        p.intensity = static_cast<float>(i % 256);
        pts.push_back(p);
      }
      const std::size_t before = done.size();
      a.push(pts, s.sensor(first), Stamp{static_cast<std::int64_t>(first / s.per_packet)}, done);
      for (std::size_t k = before; k < done.size(); ++k) emitted_after.push_back(first / s.per_packet);
    }
    a.finish(done);
    return done;
  };
  std::vector<std::size_t> early_at;
  std::vector<std::size_t> late_at;
  const auto early = assemble(RotationClose::LastFiring, early_at);
  const auto late = assemble(RotationClose::NextRotation, late_at);
  ASSERT_EQ(early.size(), turns);
  ASSERT_EQ(late.size(), turns);
  ASSERT_EQ(early_at.size(), turns);  // all of them while the stream runs, none left for finish()
  ASSERT_EQ(late_at.size(), turns - 1);
  const std::size_t packets_per_turn = 36000 / (25 * 24);
  for (std::size_t k = 0; k < turns; ++k) {
    SCOPED_TRACE(k);
    // Packets 0..59 make turn 0, and its last one emits it; waiting, it came with packet 60.
    EXPECT_EQ(early_at[k], (k + 1) * packets_per_turn - 1);
    if (k + 1 < turns) {
      EXPECT_EQ(late_at[k], (k + 1) * packets_per_turn);
    }
    EXPECT_EQ(early[k].last_host_stamp.ns, static_cast<std::int64_t>((k + 1) * packets_per_turn - 1));
    EXPECT_EQ(early[k].host_stamp, late[k].host_stamp);
    EXPECT_EQ(early[k].sensor_stamp, late[k].sensor_stamp);
    EXPECT_EQ(early[k].packets, packets_per_turn);
    // The first is partial as the stream's first (it did not start by passing the cut); the others are whole turns.
    EXPECT_EQ(early[k].partial, k == 0);
    ASSERT_EQ(early[k].points.size(), late[k].points.size());
    for (std::size_t j = 0; j < early[k].points.size(); ++j) {
      ASSERT_EQ(early[k].points[j].azimuth_cdeg, late[k].points[j].azimuth_cdeg);
      ASSERT_EQ(early[k].points[j].time_s, late[k].points[j].time_s);
    }
  }
  EXPECT_TRUE(late.back().partial) << "waiting for a next rotation that never comes, finish() emits it partial";
}

// A packet of 24 firings 0.25 degree apart, the first at `first_cdeg`.
void push_steady_packet(RotationAssembler& a, int first_cdeg, std::vector<LidarFrame>& done) {
  std::vector<LidarPoint> pts(24);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    pts[i].azimuth_cdeg = static_cast<std::uint16_t>((first_cdeg + 25 * static_cast<int>(i)) % 36000);
  }
  a.push(pts, Stamp{1}, Stamp{1}, done);
}

// The step is predicted; where the next packet after all starts a little before the cut (the sensor's spin wavered),
// its firings join the next rotation, like per-laser corrections right after a cut: no frame of a few points.
TEST(RotationAssembler, AMissedPredictionMovesAFewFiringsToTheNextRotation) {
  RotationAssembler a(0.0);
  std::vector<LidarFrame> done;
  auto packet = [&](int first_cdeg) { push_steady_packet(a, first_cdeg, done); };
  for (int first = 0; first < 36000; first += 600) packet(first);  // a whole turn, the last packet at 354 deg
  ASSERT_EQ(done.size(), 1U) << "emitted with its last packet";
  packet(35990);  // 0.1 deg short of the predicted start
  packet(590);
  packet(1190);
  EXPECT_EQ(done.size(), 1U) << "no cut for the firings just before the cut";
  a.finish(done);
  ASSERT_EQ(done.size(), 2U);
  EXPECT_EQ(done[1].points.size(), 72U);
  EXPECT_EQ(done[1].points.front().azimuth_cdeg, 35990);
}

// A lost packet, or a step that changes, gives no prediction: the rotation waits for the next one's first packet.
TEST(RotationAssembler, AnUnsteadyStepWaitsForTheNextRotation) {
  RotationAssembler a(0.0);
  std::vector<LidarFrame> done;
  auto packet = [&](int first_cdeg) { push_steady_packet(a, first_cdeg, done); };
  for (int first = 0; first < 34800; first += 600) packet(first);
  packet(35400);  // the one at 348 deg lost: a step of 1200 after steps of 600
  EXPECT_TRUE(done.empty());
  packet(0);
  EXPECT_EQ(done.size(), 1U);
}

// Real captures, whose cut falls where the packets put it: the same frames either way.
TEST(RotationAssembler, RealCapturesGiveTheSameRotationsEitherWay) {
  using namespace velodyne;
  for (const auto& [file, model] :
       {std::pair{"hdl32e_monterey_600.pcap", Model::HDL32E}, std::pair{"vlp16_veloview_300.pcap", Model::VLP16}}) {
    SCOPED_TRACE(file);
    const auto packets = test::read_data_packets(test::test_data(file));
    DecoderOptions o;
    o.model = model;
    const Decoder d(default_calibration(model), o);
    auto assemble = [&](RotationClose close) {
      RotationAssembler a(0.0, close);
      std::vector<LidarFrame> done;
      std::vector<LidarPoint> pts;
      for (const auto& r : packets) {
        pts.clear();
        const auto h = d.decode(r.payload, pts);
        if (h) a.push(pts, sensor_time_from_hour_offset(h->timestamp_us, r.host), r.host, done);
      }
      a.finish(done);
      return done;
    };
    const auto early = assemble(RotationClose::LastFiring);
    const auto late = assemble(RotationClose::NextRotation);
    ASSERT_GE(early.size(), 2U);
    ASSERT_EQ(early.size(), late.size());
    for (std::size_t k = 0; k < early.size(); ++k) {
      EXPECT_EQ(early[k].points.size(), late[k].points.size());
      EXPECT_EQ(early[k].partial, late[k].partial);
      EXPECT_EQ(early[k].last_host_stamp, late[k].last_host_stamp);
    }
  }
}

}  // namespace
}  // namespace fieldguard
