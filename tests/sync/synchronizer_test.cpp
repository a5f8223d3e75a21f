// Sync end to end on sensor-native times (Velodyne hour offset, SCIP milliseconds, NMEA UTC, Xsens
// SampleTimeFine), and the health status line.

#include "fieldguard/sync/synchronizer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "fieldguard/sync/health.hpp"

namespace fieldguard::sync {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kHourNs = 3'600'000'000'000LL;
// 2024-06-15 10:59:30 UTC: the Velodyne's hour offset wraps 30 s in.
constexpr std::int64_t kT0 = 1'718'449'170'000'000'000LL;

// Host receive time = true time + 0.3 ms + Exp(1 ms). Sensor clocks: the LiDAR and GNSS on GPS time (offset 0),
// the 2D scanner and the AHRS free-running with their own epoch and a 40/-30 ppm drift.
struct Rig {
  std::mt19937_64 rng{11};
  std::exponential_distribution<double> jitter{1.0 / 1e-3};
  Synchronizer sync;
  std::vector<SyncedFrame> frames;
  std::int64_t rx(std::int64_t t) { return t + 300'000 + static_cast<std::int64_t>(jitter(rng) * 1e9); }

  void lidar(std::uint64_t index, std::int64_t t, std::int64_t period) {
    LidarFrame f;
    f.index = index;
    f.sensor_stamp = Stamp{t};
    f.host_stamp = Stamp{rx(t + period)};  // the frame's first packet reaches the host once the rotation is done
    f.host_stamp.ns -= period;
    for (int i = 0; i < 50; ++i) {
      LidarPoint p;
      p.time_s = static_cast<float>(static_cast<double>(period) * 1e-9 * i / 50.0);
      f.points.push_back(p);
    }
    sync.push_lidar(std::move(f));
  }
  void scan(std::int64_t t) {
    scip::Scan s;
    const double local_ms =
        static_cast<double>(t - kT0) * 1e-6 * (1.0 + 40e-6) + 16'777'000.0;  // wraps at 16 777.216 s
    s.timestamp_ms = static_cast<std::uint32_t>(static_cast<std::uint64_t>(local_ms) % (1U << 24));
    sync.push_scan(std::move(s), Stamp{rx(t)});
  }
  void gnss(std::int64_t t) {
    nmea::Gga g;
    g.utc_seconds_of_day = static_cast<double>(t % (24 * kHourNs)) * 1e-9;
    const std::int64_t r = rx(t);
    sync.push_gnss(nmea::Sentence{g}, Stamp{r + 20 * kMs});
    sync.push_gnss(nmea::Sentence{nmea::Vtg{}}, Stamp{r + 25 * kMs});  // untimed: takes the fix's time
  }
  void ahrs(std::int64_t t) {
    xsens::MtData2 m;
    const double ticks =
        static_cast<double>(t - kT0) * 1e-5 * (1.0 - 30e-6) + 4'294'500'000.0;  // wraps at 2^32, 46.7 s in
    m.sample_time_fine = static_cast<std::uint32_t>(static_cast<std::uint64_t>(ticks) % (1ULL << 32));
    sync.push_ahrs(std::move(m), Stamp{rx(t)});
  }
};

TEST(Synchronizer, AcrossTheHourAndEveryCounterWrapFramesKeepComing) {
  Rig rig;
  const std::int64_t period = 100 * kMs;  // 10 Hz spin
  const std::int64_t end = kT0 + 90'000 * kMs;
  std::int64_t next_rot = kT0, next_scan = kT0 + 3 * kMs, next_gnss = kT0, next_ahrs = kT0;
  std::uint64_t index = 0;
  std::int64_t t = kT0;
  std::string status_mid;
  while (t < end) {
    t = std::min({next_rot + period, next_scan, next_gnss, next_ahrs});
    if (t == next_rot + period) {
      rig.lidar(index++, next_rot, period);
      next_rot += period;
    } else if (t == next_scan) {
      rig.scan(t);
      next_scan += 25 * kMs;
    } else if (t == next_gnss) {
      rig.gnss(t);
      next_gnss += 100 * kMs;
    } else {
      rig.ahrs(t);
      next_ahrs += 10 * kMs;
    }
    rig.sync.poll(Stamp{t}, rig.frames);
    if (status_mid.empty() && t >= kT0 + 45'000 * kMs) status_mid = rig.sync.status(Stamp{t});
  }
  // 900 rotations, 450 frames; the last few may still be waiting.
  ASSERT_GE(rig.frames.size(), 445U);
  std::size_t complete = 0;
  for (std::size_t k = 0; k < rig.frames.size(); ++k) {
    const SyncedFrame& f = rig.frames[k];
    EXPECT_EQ(f.seq, k);
    EXPECT_EQ(f.rotations, 2U);
    // Windows follow each other by 200 ms within the clock model's error (jitter 1 ms, samples at 10 Hz).
    if (k > 0) {
      EXPECT_NEAR(static_cast<double>(f.window_start.ns - rig.frames[k - 1].window_start.ns), 200e6, 1.5e6) << k;
    }
    // Mapped LiDAR time is the true time (offset 0) plus the least delay (0.3 ms).
    const std::int64_t truth = kT0 + static_cast<std::int64_t>(k) * 200 * kMs;
    if (k > 100) {
      EXPECT_NEAR(static_cast<double>(f.window_start.ns - truth), 0.3e6, 0.5e6) << k;
    }
    if (f.missing == 0) ++complete;
  }
  // The first frame has no GNSS/AHRS sample before it: everything after is complete.
  EXPECT_GE(complete, rig.frames.size() - 1);
  for (SensorKind k : kAllSensors) {
    EXPECT_EQ(rig.sync.clock(k).model().jumps(), 0U) << to_string(k);
  }
  EXPECT_EQ(rig.sync.clock(SensorKind::Lidar3d).unwrapper().wraps(), 1U);  // the top of the hour
  EXPECT_EQ(rig.sync.clock(SensorKind::Scan2d).unwrapper().wraps(), 1U);
  EXPECT_EQ(rig.sync.clock(SensorKind::Ahrs).unwrapper().wraps(), 1U);
  // The scanner's whole milliseconds hide its 40 ppm (a 1 ms step every 25 s), so its skew is not checked;
  // its mapped times are: true time + least delay (0.3 ms), within the 1 ms quantisation.
  for (std::size_t k = 100; k < rig.frames.size(); ++k) {
    ASSERT_TRUE(rig.frames[k].scan2d.has_value()) << k;
    const std::int64_t rel = rig.frames[k].scan2d->time.ns - kT0 - 3 * kMs;
    const std::int64_t n = (rel + 12 * kMs) / (25 * kMs);
    EXPECT_NEAR(static_cast<double>(rel - n * 25 * kMs), 0.3e6, 1.2e6) << k;
  }
  EXPECT_NEAR(rig.sync.clock(SensorKind::Ahrs).model().skew(), 30e-6, 5e-6);
  // GNSS frames carry the untimed VTG of each epoch too, with the fix's time.
  const SyncedFrame& f = rig.frames[200];
  ASSERT_GE(f.gnss.size(), 6U);
  EXPECT_EQ(f.gnss[0].time, f.gnss[1].time);
  EXPECT_TRUE(std::holds_alternative<nmea::Vtg>(f.gnss[1].sentence));
  EXPECT_EQ(rig.sync.health().get(SensorKind::Gnss).errors.untimed, 0U);
  std::printf("status at 45 s: %s\n", status_mid.c_str());
  double r_lidar = 0, r_scan = 0, r_gnss = 0, r_ahrs = 0;
  unsigned long long frames = 0, incomplete = 0;
  ASSERT_EQ(std::sscanf(status_mid.c_str(),
                        "ok | lidar3d %lf Hz, scan2d %lf Hz, gnss %lf Hz, ahrs %lf Hz | frames %llu, incomplete %llu",
                        &r_lidar, &r_scan, &r_gnss, &r_ahrs, &frames, &incomplete),
            6)
      << status_mid;
  // Rates over a 2 s window: one sample more or less at its edges.
  EXPECT_NEAR(r_lidar, 10.0, 0.5);
  EXPECT_NEAR(r_scan, 40.0, 0.5);
  EXPECT_NEAR(r_gnss, 20.0, 0.5);  // GGA and VTG
  EXPECT_NEAR(r_ahrs, 100.0, 0.5);
  EXPECT_GE(frames, 220U);
  EXPECT_EQ(incomplete, 1U);
}

TEST(Synchronizer, GnssTimeCorrectionIsAJumpAndFramesStayComplete) {
  Rig rig;
  const std::int64_t period = 200 * kMs;
  for (int k = 0; k < 100; ++k) {
    const std::int64_t t0 = kT0 + k * period;
    for (int a = 0; a < 20; ++a) rig.ahrs(t0 + a * 10 * kMs);
    for (int s = 0; s < 8; ++s) rig.scan(t0 + s * 25 * kMs);
    for (int g = 0; g < 2; ++g) {
      const std::int64_t tg = t0 + g * 100 * kMs;
      nmea::Gga gga;
      // The receiver's time is 2 s wrong until it corrects itself at 10 s.
      const std::int64_t wrong = tg < kT0 + 10'000 * kMs ? 2'000 * kMs : 0;
      gga.utc_seconds_of_day = static_cast<double>((tg + wrong) % (24 * kHourNs)) * 1e-9;
      rig.sync.push_gnss(nmea::Sentence{gga}, Stamp{rig.rx(tg) + 20 * kMs});
    }
    rig.lidar(static_cast<std::uint64_t>(k), t0, period);
    rig.sync.poll(Stamp{t0 + period}, rig.frames);
  }
  EXPECT_EQ(rig.sync.clock(SensorKind::Gnss).model().jumps(), 1U);
  EXPECT_EQ(rig.sync.health().get(SensorKind::Gnss).errors.clock_jumps, 1U);
  EXPECT_EQ(rig.sync.health().get(SensorKind::Gnss).errors.suspect, 2U);
  EXPECT_GE(rig.frames.size(), 95U);
  // Well after the correction the GNSS samples sit at their true time again.
  const SyncedFrame& f = rig.frames[80];
  ASSERT_FALSE(f.gnss.empty());
  EXPECT_LE(f.gnss.front().time, f.window_start);
  EXPECT_GE(f.gnss.back().time, f.window_end);
  EXPECT_LT(f.window_start.ns - f.gnss.front().time.ns, 101 * kMs);
}

TEST(Synchronizer, SilentSensorIsNamedInTheStatus) {
  Rig rig;
  const std::int64_t period = 200 * kMs;
  std::int64_t t = kT0;
  for (int k = 0; k < 20; ++k, t += period) {
    for (int a = 0; a < 20; ++a) rig.ahrs(t + a * 10 * kMs);
    for (int s = 0; s < 8; ++s) rig.scan(t + s * 25 * kMs);
    if (k < 10) rig.gnss(t);  // the receiver goes silent after 2 s
    if (k < 10) rig.gnss(t + 100 * kMs);
    rig.lidar(static_cast<std::uint64_t>(k), t, period);
    rig.sync.poll(Stamp{t + period}, rig.frames);
  }
  const std::string s = rig.sync.status(Stamp{t});
  EXPECT_EQ(rig.sync.waiting_for(Stamp{t}), SensorKind::Gnss);
  EXPECT_EQ(s.rfind("waiting for gnss (silent 2.", 0), 0U) << s;
  EXPECT_NE(s.find("gnss 0.0 Hz"), std::string::npos) << s;
  // And once the LiDAR stops too, with nothing pending, the LiDAR is what sync waits for.
  std::vector<SyncedFrame> rest;
  rig.sync.poll(Stamp{t + 5'000 * kMs}, rest);
  EXPECT_EQ(rig.sync.waiting_for(Stamp{t + 5'000 * kMs}), SensorKind::Lidar3d);
  EXPECT_EQ(rig.sync.status(Stamp{t + 5'000 * kMs}).rfind("waiting for lidar3d (silent", 0), 0U);
}

TEST(Synchronizer, SamplesWithoutTimeAreCounted) {
  Synchronizer sync;
  xsens::MtData2 m;  // no SampleTimeFine
  sync.push_ahrs(std::move(m), Stamp{kT0});
  sync.push_gnss(nmea::Sentence{nmea::Hdt{}}, Stamp{kT0});  // no fix before it
  LidarFrame f;                                             // sensor stamp unknown
  f.host_stamp = Stamp{kT0};
  sync.push_lidar(std::move(f));
  sync.count_decode_errors(SensorKind::Scan2d, 3);
  EXPECT_EQ(sync.health().get(SensorKind::Ahrs).errors.untimed, 1U);
  EXPECT_EQ(sync.health().get(SensorKind::Gnss).errors.untimed, 1U);
  EXPECT_EQ(sync.health().get(SensorKind::Lidar3d).errors.untimed, 1U);
  EXPECT_EQ(sync.health().get(SensorKind::Scan2d).errors.decode, 3U);
  EXPECT_EQ(sync.assembler().pending(), 0U);
  const std::string s = sync.status(Stamp{kT0});
  EXPECT_NE(s.find("scan2d never heard err 3"), std::string::npos) << s;
  EXPECT_NE(s.find("ahrs 0.5 Hz err 1"), std::string::npos) << s;
}

TEST(HealthMonitor, AgeAndRateOverTheWindow) {
  HealthMonitor h(2.0);
  EXPECT_FALSE(h.age_s(SensorKind::Ahrs, Stamp{kT0}).has_value());
  for (int i = 0; i < 500; ++i) h.sample(SensorKind::Ahrs, Stamp{kT0 + i * 10 * kMs});  // 100 Hz for 5 s
  const Stamp last{kT0 + 499 * 10 * kMs};
  EXPECT_NEAR(*h.age_s(SensorKind::Ahrs, Stamp{last.ns + 250 * kMs}), 0.25, 1e-9);
  EXPECT_NEAR(h.rate_hz(SensorKind::Ahrs, last), 100.0, 0.5);
  EXPECT_NEAR(h.rate_hz(SensorKind::Ahrs, Stamp{last.ns + 1'000 * kMs}), 50.0, 0.5);  // half the window silent
  EXPECT_DOUBLE_EQ(h.rate_hz(SensorKind::Ahrs, Stamp{last.ns + 3'000 * kMs}), 0.0);
  EXPECT_EQ(h.get(SensorKind::Ahrs).samples, 500U);
  EXPECT_THROW(HealthMonitor{0.0}, std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::sync
