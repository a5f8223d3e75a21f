// Frame assembly on synthetic mapped streams: 10 Hz and 5 Hz rotations, 40 Hz 2D scans, 10 Hz GNSS, 100 Hz AHRS.

#include "fieldguard/sync/frame_assembler.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <variant>
#include <vector>

namespace fieldguard::sync {
namespace {

constexpr std::int64_t kT0 = 1'718'449'170'000'000'000LL;
constexpr std::int64_t kMs = 1'000'000;

// A rotation of `period_ms` starting at `start`, 100 points evenly spread, tagged by index in `intensity`.
LidarRotation rotation(std::uint64_t index, std::int64_t start, std::int64_t period_ns, bool partial = false) {
  LidarRotation r;
  r.index = index;
  r.start = Stamp{start};
  r.end = Stamp{start + period_ns * 99 / 100};
  r.host = Stamp{start + period_ns};
  r.partial = partial;
  for (int i = 0; i < 100; ++i) {
    LidarPoint p;
    p.time_s = static_cast<float>(static_cast<double>(period_ns) * 1e-9 * i / 100.0);
    p.intensity = static_cast<float>(index);
    p.azimuth_cdeg = static_cast<std::uint16_t>(i * 360);
    r.points.push_back(p);
  }
  return r;
}

TimedScan scan_at(std::int64_t t) {
  TimedScan s;
  s.time = Stamp{t};
  s.host = Stamp{t + 2 * kMs};
  s.scan.timestamp_ms = static_cast<std::uint32_t>((t / kMs) & 0xFFFFFF);
  return s;
}
TimedGnss gnss_at(std::int64_t t) {
  nmea::Gga g;
  g.utc_seconds_of_day = static_cast<double>(t % 86'400'000'000'000LL) * 1e-9;
  return TimedGnss{Stamp{t}, Stamp{t + 40 * kMs}, g};
}
TimedAttitude ahrs_at(std::int64_t t) {
  TimedAttitude a;
  a.time = Stamp{t};
  a.host = Stamp{t + kMs};
  a.data.sample_time_fine = static_cast<std::uint32_t>(t / 100'000);
  return a;
}

// Everything a synthetic run produced, as events ordered by receive time.
struct Event {
  std::int64_t rx = 0;
  int kind = 0;  // 0 rotation, 1 scan, 2 gnss, 3 ahrs
  std::int64_t t = 0;
  std::uint64_t index = 0;
};

struct Scenario {
  std::int64_t rotation_ns = 100 * kMs;  // 10 Hz spin
  double seconds = 3.0;
  bool with_scan = true, with_gnss = true, with_ahrs = true;
  std::int64_t scan_offset = 3 * kMs;  // 2D scans not aligned with the rotations
  std::int64_t gnss_delay = 40 * kMs, ahrs_delay = kMs, scan_delay = 2 * kMs;
};

std::vector<Event> events(const Scenario& sc) {
  std::vector<Event> ev;
  const auto end = kT0 + static_cast<std::int64_t>(sc.seconds * 1e9);
  std::uint64_t i = 0;
  for (std::int64_t t = kT0; t + sc.rotation_ns <= end; t += sc.rotation_ns, ++i) {
    ev.push_back({t + sc.rotation_ns + kMs, 0, t, i});
  }
  if (sc.with_scan) {
    for (std::int64_t t = kT0 + sc.scan_offset; t < end; t += 25 * kMs) ev.push_back({t + sc.scan_delay, 1, t, 0});
  }
  if (sc.with_gnss) {
    for (std::int64_t t = kT0 - 50 * kMs; t < end + 200 * kMs; t += 100 * kMs)
      ev.push_back({t + sc.gnss_delay, 2, t, 0});
  }
  if (sc.with_ahrs) {
    for (std::int64_t t = kT0 - 10 * kMs; t < end + 200 * kMs; t += 10 * kMs)
      ev.push_back({t + sc.ahrs_delay, 3, t, 0});
  }
  std::stable_sort(ev.begin(), ev.end(), [](const Event& a, const Event& b) { return a.rx < b.rx; });
  return ev;
}

// One event into the assembler.
void feed(FrameAssembler& fa, const Scenario& sc, const Event& e) {
  switch (e.kind) {
    case 0: fa.add_rotation(rotation(e.index, e.t, sc.rotation_ns)); break;
    case 1: fa.add_scan(scan_at(e.t)); break;
    case 2: fa.add_gnss(gnss_at(e.t)); break;
    default: fa.add_attitude(ahrs_at(e.t)); break;
  }
}

std::vector<SyncedFrame> run(FrameAssembler& fa, const Scenario& sc, const std::vector<Event>& ev, bool finish = true) {
  std::vector<SyncedFrame> out;
  for (const Event& e : ev) {
    feed(fa, sc, e);
    fa.poll(Stamp{e.rx}, out);
  }
  if (finish) fa.finish(out);
  return out;
}

// Points: every rotation of the window, times relative to the window's start and increasing.
void check_frame_points(const SyncedFrame& f, std::int64_t rotation_ns) {
  SCOPED_TRACE(f.seq);
  ASSERT_EQ(f.points.size(), 100U * f.rotations);
  for (std::size_t i = 1; i < f.points.size(); ++i) ASSERT_GT(f.points[i].time_s, f.points[i - 1].time_s);
  EXPECT_FLOAT_EQ(f.points.front().time_s, 0.F);
  EXPECT_NEAR(f.points.back().time_s, static_cast<double>(f.rotations * rotation_ns - rotation_ns / 100) * 1e-9, 1e-5);
}

void check_frame(const SyncedFrame& f, std::int64_t rotation_ns) {
  SCOPED_TRACE(f.seq);
  check_frame_points(f, rotation_ns);
  // The scan nearest to the middle: scans are 25 ms apart, so within 12.5 ms, and no other is nearer.
  ASSERT_TRUE(f.scan2d.has_value());
  const std::int64_t d = std::llabs(f.scan2d->time.ns - f.middle().ns);
  EXPECT_LE(d, 12'500'000);
  // GNSS and AHRS bracket the window: first at or before the start, last at or after the end, all in between.
  for (const auto* v : {&f.gnss}) {
    ASSERT_GE(v->size(), 2U);
    EXPECT_LE(v->front().time, f.window_start);
    EXPECT_GT(v->front().time.ns, f.window_start.ns - 100 * kMs);
    EXPECT_GE(v->back().time, f.window_end);
    EXPECT_LT(v->back().time.ns, f.window_end.ns + 100 * kMs);
  }
  ASSERT_GE(f.ahrs.size(), 2U);
  EXPECT_LE(f.ahrs.front().time, f.window_start);
  EXPECT_GE(f.ahrs.back().time, f.window_end);
  for (std::size_t i = 1; i < f.ahrs.size(); ++i) EXPECT_EQ(f.ahrs[i].time.ns - f.ahrs[i - 1].time.ns, 10 * kMs);
  EXPECT_EQ(f.ahrs.size(), static_cast<std::size_t>((f.ahrs.back().time.ns - f.ahrs.front().time.ns) / (10 * kMs) + 1));
}

TEST(FrameAssembler, TenHertzSpinGivesTwoRotationsPerFrame) {
  Scenario sc;
  FrameAssembler fa;
  const auto frames = run(fa, sc, events(sc), false);
  ASSERT_EQ(frames.size(), 15U);  // 30 rotations in 3 s
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const SyncedFrame& f = frames[k];
    EXPECT_EQ(f.seq, k);
    EXPECT_EQ(f.rotations, 2U);
    EXPECT_EQ(f.window_start.ns, kT0 + static_cast<std::int64_t>(k) * 200 * kMs);
    EXPECT_EQ(f.missing, 0);
    EXPECT_FALSE(f.timed_out);
    EXPECT_FALSE(f.partial);
    // Rotation 2k then 2k+1, in order.
    EXPECT_EQ(f.points.front().intensity, static_cast<float>(2 * k));
    EXPECT_EQ(f.points.back().intensity, static_cast<float>(2 * k + 1));
    check_frame(f, sc.rotation_ns);
  }
  EXPECT_EQ(fa.counters().complete, 15U);
}

TEST(FrameAssembler, FiveHertzSpinGivesOneWholeRotationPerFrame) {
  Scenario sc;
  sc.rotation_ns = 200'170'000;  // 4.9957 Hz, a shade slower than the frame rate
  FrameAssembler fa;
  const auto frames = run(fa, sc, events(sc), false);
  ASSERT_EQ(frames.size(), 14U);
  for (const SyncedFrame& f : frames) {
    EXPECT_EQ(f.rotations, 1U);
    EXPECT_EQ(f.missing, 0);
    check_frame(f, sc.rotation_ns);
  }
}

TEST(FrameAssembler, NearestScanIsChosen) {
  FrameAssembler fa;
  fa.add_rotation(rotation(0, kT0, 200 * kMs));  // window kT0 .. kT0+198 ms, middle kT0+99 ms
  for (std::int64_t t : {60, 85, 108, 140}) fa.add_scan(scan_at(kT0 + t * kMs));
  for (std::int64_t t : {-50, 150, 250}) fa.add_gnss(gnss_at(kT0 + t * kMs));
  for (std::int64_t t = -10; t <= 210; t += 10) fa.add_attitude(ahrs_at(kT0 + t * kMs));
  std::vector<SyncedFrame> out;
  fa.poll(Stamp{kT0 + 260 * kMs}, out);
  ASSERT_EQ(out.size(), 1U);
  ASSERT_TRUE(out[0].scan2d);
  EXPECT_EQ(out[0].scan2d->time.ns, kT0 + 108 * kMs);  // 9 ms from the middle; 85 is 14 ms away
  EXPECT_EQ(out[0].gnss.size(), 3U);
}

TEST(FrameAssembler, MissingGnssTimesOutAndIsNamed) {
  Scenario sc;
  sc.with_gnss = false;
  FrameAssembler fa;
  std::vector<SyncedFrame> out;
  const auto ev = events(sc);
  bool saw_waiting = false;
  for (const Event& e : ev) {
    switch (e.kind) {
      case 0: fa.add_rotation(rotation(e.index, e.t, sc.rotation_ns)); break;
      case 1: fa.add_scan(scan_at(e.t)); break;
      default: fa.add_attitude(ahrs_at(e.t)); break;
    }
    const std::size_t before = out.size();
    fa.poll(Stamp{e.rx}, out);
    // Nothing leaves before its timeout.
    for (std::size_t i = before; i < out.size(); ++i) EXPECT_GT(e.rx - out[i].window_end.ns, 500 * kMs);
    if (fa.pending() > 0) {
      EXPECT_EQ(fa.waiting_for(), SensorKind::Gnss);
      saw_waiting = true;
    }
  }
  EXPECT_TRUE(saw_waiting);
  ASSERT_GE(out.size(), 12U);
  for (const SyncedFrame& f : out) {
    EXPECT_TRUE(f.timed_out);
    EXPECT_EQ(f.missing, bit(SensorKind::Gnss));
    EXPECT_TRUE(f.gnss.empty());
    EXPECT_TRUE(f.scan2d.has_value());
  }
  EXPECT_EQ(fa.counters().missing[static_cast<std::size_t>(SensorKind::Gnss)], out.size());
}

TEST(FrameAssembler, NotRequiredSensorIsNotWaitedFor) {
  Scenario sc;
  sc.with_scan = false;
  AssemblerParams p;
  p.require_scan2d = false;
  FrameAssembler fa(p);
  const auto frames = run(fa, sc, events(sc), false);
  ASSERT_EQ(frames.size(), 15U);
  for (const SyncedFrame& f : frames) {
    EXPECT_EQ(f.missing, 0);
    EXPECT_FALSE(f.timed_out);
    EXPECT_FALSE(f.scan2d.has_value());
  }
}

TEST(FrameAssembler, DeadScannerAfterAWhileIsMarkedPerFrame) {
  FrameAssembler fa;
  std::vector<SyncedFrame> out;
  for (int k = 0; k < 6; ++k) {
    const std::int64_t t = kT0 + k * 200 * kMs;
    fa.add_rotation(rotation(static_cast<std::uint64_t>(k), t, 200 * kMs));
    for (std::int64_t s = 0; s < 200 && k < 3; s += 25) fa.add_scan(scan_at(t + s * kMs));
    for (std::int64_t s = -100; s <= 200; s += 100) fa.add_gnss(gnss_at(t + s * kMs));
    for (std::int64_t s = -10; s <= 200; s += 10) fa.add_attitude(ahrs_at(t + s * kMs));
    fa.poll(Stamp{t + 250 * kMs}, out);
  }
  fa.poll(Stamp{kT0 + 10'000 * kMs}, out);
  ASSERT_EQ(out.size(), 6U);
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(out[static_cast<std::size_t>(k)].is_missing(SensorKind::Scan2d), k >= 3) << k;
    EXPECT_EQ(out[static_cast<std::size_t>(k)].missing & ~bit(SensorKind::Scan2d), 0) << k;
  }
}

// Each sensor behind or ahead of the others, and samples of a sensor swapped in pairs: the same frames as when
// everything arrives in time order.
TEST(FrameAssembler, OutOfOrderArrivalGivesTheSameFrames) {
  Scenario sc;
  FrameAssembler in_order;
  const auto expected = run(in_order, sc, events(sc));

  Scenario late = sc;
  late.gnss_delay = 180 * kMs;  // GNSS arrives well after the rotation it brackets
  late.scan_delay = 60 * kMs;
  auto ev = events(late);
  std::mt19937 rng(3);
  // Neighbours of different sensors swapped at random (a serial or TCP stream keeps its own order).
  for (std::size_t i = 0; i + 1 < ev.size(); ++i) {
    if (ev[i].kind != ev[i + 1].kind && rng() % 3 == 0) std::swap(ev[i], ev[i + 1]);
  }
  FrameAssembler shuffled;
  const auto got = run(shuffled, late, ev);
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t k = 0; k < got.size(); ++k) {
    SCOPED_TRACE(k);
    EXPECT_EQ(got[k].window_start, expected[k].window_start);
    EXPECT_EQ(got[k].window_end, expected[k].window_end);
    EXPECT_EQ(got[k].points.size(), expected[k].points.size());
    EXPECT_EQ(got[k].missing, expected[k].missing);
    ASSERT_EQ(got[k].scan2d.has_value(), expected[k].scan2d.has_value());
    if (got[k].scan2d) {
      EXPECT_EQ(got[k].scan2d->time, expected[k].scan2d->time);
    }
    ASSERT_EQ(got[k].gnss.size(), expected[k].gnss.size());
    for (std::size_t i = 0; i < got[k].gnss.size(); ++i) EXPECT_EQ(got[k].gnss[i].time, expected[k].gnss[i].time);
    ASSERT_EQ(got[k].ahrs.size(), expected[k].ahrs.size());
    for (std::size_t i = 0; i < got[k].ahrs.size(); ++i) EXPECT_EQ(got[k].ahrs[i].time, expected[k].ahrs[i].time);
  }
  EXPECT_EQ(shuffled.counters().late_samples, 0U);
}

TEST(FrameAssembler, PartialRotationIsAFrameOfItsOwnAndALostRotationClosesShort) {
  FrameAssembler fa;
  std::vector<SyncedFrame> out;
  const std::int64_t r = 100 * kMs;
  fa.add_rotation(rotation(0, kT0, r, true));  // stream start: partial
  fa.add_rotation(rotation(1, kT0 + r, r));
  fa.add_rotation(rotation(2, kT0 + 2 * r, r));  // completes a 2-rotation window
  fa.add_rotation(rotation(3, kT0 + 3 * r, r));
  fa.add_rotation(rotation(5, kT0 + 5 * r, r));  // rotation 4 lost: 3 closes alone, short
  fa.add_rotation(rotation(6, kT0 + 6 * r, r));
  fa.finish(out);
  ASSERT_EQ(out.size(), 4U);
  EXPECT_TRUE(out[0].partial);
  EXPECT_EQ(out[0].rotations, 1U);
  EXPECT_FALSE(out[1].partial);
  EXPECT_EQ(out[1].rotations, 2U);
  EXPECT_TRUE(out[2].partial);
  EXPECT_EQ(out[2].rotations, 1U);
  EXPECT_EQ(out[2].points.front().intensity, 3.F);
  EXPECT_FALSE(out[3].partial);
  EXPECT_EQ(out[3].rotations, 2U);
  for (const SyncedFrame& f : out) EXPECT_TRUE(f.timed_out);  // no other sensor at all
  EXPECT_EQ(fa.counters().frames, 4U);
}

TEST(FrameAssembler, LateRotationAndLateSamplesAreCountedAndDropped) {
  FrameAssembler fa;
  std::vector<SyncedFrame> out;
  fa.add_rotation(rotation(0, kT0, 200 * kMs));
  fa.add_rotation(rotation(1, kT0 + 200 * kMs, 200 * kMs));
  fa.add_rotation(rotation(0, kT0, 200 * kMs));  // again: before the end of the last one
  EXPECT_EQ(fa.counters().late_rotations, 1U);
  fa.poll(Stamp{kT0 + 5'000 * kMs}, out);
  ASSERT_EQ(out.size(), 2U);
  fa.add_gnss(gnss_at(kT0 - 4'000 * kMs));  // far behind what was emitted
  EXPECT_EQ(fa.counters().late_samples, 1U);
}

// A sensor's own samples out of order (before any window needs them) are kept sorted.
TEST(FrameAssembler, SamplesOfOneSensorAreSortedOnArrival) {
  FrameAssembler fa;
  for (std::int64_t t = 210; t >= -10; t -= 10) fa.add_attitude(ahrs_at(kT0 + t * kMs));
  for (std::int64_t t : {250, -50, 150}) fa.add_gnss(gnss_at(kT0 + t * kMs));
  for (std::int64_t t : {140, 60, 108, 85}) fa.add_scan(scan_at(kT0 + t * kMs));
  fa.add_rotation(rotation(0, kT0, 200 * kMs));
  std::vector<SyncedFrame> out;
  fa.poll(Stamp{kT0 + 260 * kMs}, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].missing, 0);
  ASSERT_TRUE(out[0].scan2d);
  EXPECT_EQ(out[0].scan2d->time.ns, kT0 + 108 * kMs);
  ASSERT_EQ(out[0].gnss.size(), 3U);
  EXPECT_EQ(out[0].gnss[1].time.ns, kT0 + 150 * kMs);
  ASSERT_EQ(out[0].ahrs.size(), 21U);  // 0 .. 200 ms
  for (std::size_t i = 0; i < out[0].ahrs.size(); ++i) {
    EXPECT_EQ(out[0].ahrs[i].time.ns, kT0 + static_cast<std::int64_t>(i) * 10 * kMs);
  }
}

TEST(FrameAssembler, TooManyPendingWindowsAreEmittedOldestFirst) {
  AssemblerParams p;
  p.max_pending = 2;
  p.timeout_s = 5.0;
  p.history_s = 5.0;
  FrameAssembler fa(p);
  std::vector<SyncedFrame> out;
  for (int k = 0; k < 5; ++k) {
    fa.add_rotation(rotation(static_cast<std::uint64_t>(k), kT0 + k * 200 * kMs, 200 * kMs));
    fa.poll(Stamp{kT0 + (k + 1) * 200 * kMs}, out);
  }
  EXPECT_EQ(out.size(), 3U);
  EXPECT_EQ(fa.counters().overflowed, 3U);
  for (std::size_t k = 0; k < out.size(); ++k) EXPECT_EQ(out[k].seq, k);
}

TEST(FrameAssembler, BuffersStayBoundedWhileTheLidarIsSilent) {
  FrameAssembler fa;  // history_s 3
  for (std::int64_t t = 0; t < 60'000; t += 10) fa.add_attitude(ahrs_at(kT0 + t * kMs));
  for (std::int64_t t = 0; t < 60'000; t += 25) fa.add_scan(scan_at(kT0 + t * kMs));
  for (std::int64_t t = 0; t < 60'000; t += 100) fa.add_gnss(gnss_at(kT0 + t * kMs));
  EXPECT_EQ(fa.buffered(SensorKind::Ahrs), 302U);  // 3 s at 100 Hz, both ends, and the one before
  EXPECT_EQ(fa.buffered(SensorKind::Scan2d), 121U);
  EXPECT_EQ(fa.buffered(SensorKind::Gnss), 32U);
  EXPECT_EQ(fa.buffered(SensorKind::Lidar3d), 0U);
  // The LiDAR comes back: its frame still finds what it needs.
  fa.add_rotation(rotation(0, kT0 + 59'500 * kMs, 200 * kMs));
  for (std::int64_t t = 60'000; t < 61'000; t += 10) fa.add_attitude(ahrs_at(kT0 + t * kMs));
  for (std::int64_t t = 60'000; t < 61'000; t += 100) fa.add_gnss(gnss_at(kT0 + t * kMs));
  std::vector<SyncedFrame> out;
  fa.poll(Stamp{kT0 + 61'000 * kMs}, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].missing, 0);
}

TEST(AssemblerParams, RejectsNonsense) {
  AssemblerParams p;
  EXPECT_TRUE(p.validate().empty());
  p.rate_hz = 0.0;
  p.max_pending = 0;
  EXPECT_EQ(p.validate().size(), 2U);
  EXPECT_THROW(FrameAssembler{p}, std::invalid_argument);
}

// Frames of `run`, each with the receive time of the event after which it left.
struct Left {
  SyncedFrame frame;
  std::int64_t at = 0;
};
std::vector<Left> run_timed(FrameAssembler& fa, const Scenario& sc, const std::vector<Event>& ev) {
  std::vector<Left> left;
  std::vector<SyncedFrame> out;
  for (const Event& e : ev) {
    feed(fa, sc, e);
    fa.poll(Stamp{e.rx}, out);
    for (SyncedFrame& f : out) left.push_back({std::move(f), e.rx});
    out.clear();
  }
  return left;
}

// With a lead, a frame need not wait for the GNSS fix after its end (10 Hz fixes, 40 ms late here): it leaves with
// the rotation that closes it, complete, with the two newest epochs to extrapolate from; the same points as when it
// waits.
TEST(FrameAssembler, WithALeadAFrameLeavesWhenItsLastRotationIsWhole) {
  Scenario sc;
  AssemblerParams lead;
  lead.gnss_lead_s = 0.25;
  lead.ahrs_lead_s = 0.02;
  FrameAssembler early(lead);
  FrameAssembler waiting;
  const auto ev = events(sc);
  const auto a = run_timed(early, sc, ev);
  const auto b = run_timed(waiting, sc, ev);
  ASSERT_EQ(a.size(), 15U);
  ASSERT_EQ(b.size(), 15U);
  for (std::size_t k = 0; k < a.size(); ++k) {
    SCOPED_TRACE(k);
    const SyncedFrame& f = a[k].frame;
    // The closing rotation arrives 1 ms after its end: that is when the frame leaves.
    EXPECT_EQ(a[k].at, f.window_end.ns + sc.rotation_ns / 100 + kMs);
    EXPECT_GT(b[k].at, a[k].at + 20 * kMs) << "waiting, it left with a later fix";
    EXPECT_EQ(f.missing, 0);
    EXPECT_FALSE(f.timed_out);
    ASSERT_EQ(f.points.size(), b[k].frame.points.size());
    EXPECT_EQ(f.window_end, b[k].frame.window_end);
    // From the epoch at or before the start, and the one before it (the first frame has none), to the newest: all
    // before the end.
    ASSERT_GE(f.gnss.size(), 2U);
    EXPECT_LE(f.gnss.front().time.ns, f.window_start.ns - (k == 0 ? 0 : 100 * kMs));
    EXPECT_LT(f.gnss.back().time, f.window_end);
    EXPECT_GE(f.gnss.back().time.ns, f.window_end.ns - 250 * kMs);
    EXPECT_LE(f.ahrs.front().time, f.window_start);
    EXPECT_GE(f.ahrs.back().time.ns, f.window_end.ns - 20 * kMs);
  }
  EXPECT_EQ(early.counters().complete, 15U);
}

// The lead is no licence to go without: a single fix gives no motion to extrapolate, and a newest fix older than the
// lead is waited for; the frame then leaves when the fix comes, or at its timeout, lacking GNSS.
TEST(FrameAssembler, ALeadNeedsTwoRecentEpochs) {
  AssemblerParams lead;
  lead.gnss_lead_s = 0.25;
  lead.require_scan2d = false;
  lead.require_ahrs = false;
  {
    FrameAssembler fa(lead);
    fa.add_gnss(gnss_at(kT0 - 50 * kMs));
    fa.add_rotation(rotation(0, kT0, 200 * kMs));
    std::vector<SyncedFrame> out;
    fa.poll(Stamp{kT0 + 210 * kMs}, out);
    EXPECT_TRUE(out.empty()) << "one epoch";
    fa.add_gnss(gnss_at(kT0 + 50 * kMs));
    fa.poll(Stamp{kT0 + 211 * kMs}, out);
    ASSERT_EQ(out.size(), 1U) << "two epochs, the newest 148 ms before the end";
    EXPECT_EQ(out[0].missing, 0);
    EXPECT_EQ(out[0].gnss.size(), 2U);
  }
  {
    FrameAssembler fa(lead);
    fa.add_gnss(gnss_at(kT0 - 350 * kMs));
    fa.add_gnss(gnss_at(kT0 - 250 * kMs));
    fa.add_rotation(rotation(0, kT0, 200 * kMs));
    std::vector<SyncedFrame> out;
    fa.poll(Stamp{kT0 + 210 * kMs}, out);
    EXPECT_TRUE(out.empty()) << "the newest fix 448 ms before the end";
    fa.poll(Stamp{kT0 + 700 * kMs}, out);
    ASSERT_EQ(out.size(), 1U);
    EXPECT_TRUE(out[0].timed_out);
    EXPECT_TRUE(out[0].is_missing(SensorKind::Gnss));
  }
}

// Frames handed back (recycle()) hold later frames, and the rotations copied into a frame come back for the
// rotation assembler (take_spare_points()): once warm, a stream of two-rotation frames uses the same few buffers,
// and each frame's buffer is its own first rotation's (only the second rotation copied), the buffers handed back
// having room for a frame.
TEST(FrameAssembler, RecycledFramesAndRotationBuffersAreReused) {
  Scenario sc;
  sc.with_scan = false;
  AssemblerParams p;
  p.require_scan2d = false;
  FrameAssembler fa(p);
  std::vector<SyncedFrame> out;
  std::vector<std::vector<LidarPoint>> spare;  // what a rotation assembler would reuse
  std::vector<const LidarPoint*> frame_buffers;
  std::vector<const LidarPoint*> rotation_buffers;  // as added, in order
  std::size_t frames = 0;
  std::size_t own_buffer = 0;
  for (const Event& e : events(sc)) {
    switch (e.kind) {
      case 0: {
        LidarRotation r = rotation(e.index, e.t, sc.rotation_ns);
        if (rotation_buffers.empty()) r.points.reserve(20 * r.points.size());  // a buffer an overlong rotation grew
        if (!spare.empty()) {  // the points go into a handed-back buffer, as RotationAssembler::recycle() does
          std::vector<LidarPoint> b = std::move(spare.back());
          spare.pop_back();
          b.assign(r.points.begin(), r.points.end());
          r.points = std::move(b);
        }
        rotation_buffers.push_back(r.points.data());
        fa.add_rotation(std::move(r));
        break;
      }
      case 2: fa.add_gnss(gnss_at(e.t)); break;
      case 3: fa.add_attitude(ahrs_at(e.t)); break;
      default: break;
    }
    fa.poll(Stamp{e.rx}, out);
    for (SyncedFrame& f : out) {
      check_frame_points(f, sc.rotation_ns);
      if (++frames > 3) {
        frame_buffers.push_back(f.points.data());
        const auto recent = rotation_buffers.end() - std::min<std::ptrdiff_t>(3, std::ssize(rotation_buffers));
        if (std::find(recent, rotation_buffers.end(), f.points.data()) != rotation_buffers.end()) ++own_buffer;
      }
      fa.recycle(std::move(f));
    }
    out.clear();
    std::vector<LidarPoint> b;
    while (fa.take_spare_points(b)) {
      // Room for a frame (two rotations and an eighth), not what the overlong rotation left.
      const std::size_t rotation_points = rotation(0, 0, sc.rotation_ns).points.size();
      EXPECT_LE(b.capacity(), 2 * (2 * rotation_points + 2 * rotation_points / 8));
      spare.push_back(std::move(b));
    }
  }
  ASSERT_GE(frames, 14U);
  std::sort(frame_buffers.begin(), frame_buffers.end());
  const auto distinct = std::unique(frame_buffers.begin(), frame_buffers.end()) - frame_buffers.begin();
  EXPECT_LE(distinct, 4) << "frames after the third in new buffers";
  EXPECT_EQ(own_buffer, frame_buffers.size()) << "frames after the third copied their first rotation";
}

TEST(AssemblerParams, ALeadIsWithinTheBracketGap) {
  AssemblerParams p;
  p.gnss_lead_s = -0.1;
  p.ahrs_lead_s = 2.0;  // more than max_bracket_gap_s 1.0
  EXPECT_EQ(p.validate().size(), 2U);
}

}  // namespace
}  // namespace fieldguard::sync
