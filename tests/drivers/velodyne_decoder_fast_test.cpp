// The fast decoder (azimuth table, vectorised per-slot loops, decoding into given room) against the decoder it
// replaced (velodyne_reference_impl.hpp), point by point: every field identical except x and y, which may differ by
// the azimuth table's interpolation error (velodyne_decoder.cpp, azimuth_table()), measured and bounded here.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "drivers/velodyne_reference_impl.hpp"
#include "drivers/velodyne_test_support.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"

namespace fieldguard::velodyne {
namespace {

using test::PacketBuilder;

// x, y of the fast decoder may differ from the reference's by the two cos/sin evaluations' errors, times the
// horizontal distance: the table's (< 1.5e-7, velodyne_decoder.cpp and AzimuthTableErrorAt130m below) and the
// reference's, which computed the angle in float (azimuth * float(pi / 18000): two roundings of up to 3.7e-7 rad
// each near 2 pi) before cosf/sinf. 1e-6 of the range plus the products' rounding: 0.13 mm at 130 m.
double xy_tolerance(const LidarPoint& p) { return 1e-6 * static_cast<double>(p.range_m) + 4e-6; }

struct Diff {
  std::size_t points = 0;
  double max_xy_m = 0.0;      // largest |(x, y) fast - (x, y) reference|
  double max_xy_ratio = 0.0;  // ... relative to xy_tolerance()
  std::size_t packets = 0;    // decoded without an error
  std::size_t bounded = 0;    // ... of them with azimuth bounds narrower than every azimuth (AzimuthRange)
};

// Everything but x and y bit for bit; x and y within xy_tolerance().
void expect_same_points(const std::vector<LidarPoint>& fast, const std::vector<LidarPoint>& ref, Diff& diff,
                        const std::string& what) {
  ASSERT_EQ(fast.size(), ref.size()) << what;
  for (std::size_t i = 0; i < fast.size(); ++i) {
    const LidarPoint& a = fast[i];
    const LidarPoint& b = ref[i];
    ASSERT_EQ(a.z, b.z) << what << " point " << i;
    ASSERT_EQ(a.intensity, b.intensity) << what << " point " << i;
    ASSERT_EQ(a.time_s, b.time_s) << what << " point " << i;
    ASSERT_EQ(a.range_m, b.range_m) << what << " point " << i;
    ASSERT_EQ(a.azimuth_cdeg, b.azimuth_cdeg) << what << " point " << i;
    ASSERT_EQ(a.ring, b.ring) << what << " point " << i;
    ASSERT_EQ(a.return_type, b.return_type) << what << " point " << i;
    ASSERT_EQ(a.source, 0);
    ASSERT_EQ(a.reserved1, 0);
    const double d = std::hypot(static_cast<double>(a.x) - static_cast<double>(b.x),
                                static_cast<double>(a.y) - static_cast<double>(b.y));
    ASSERT_LE(d, xy_tolerance(b)) << what << " point " << i << " range " << b.range_m << " azimuth " << b.azimuth_cdeg;
    diff.max_xy_m = std::max(diff.max_xy_m, d);
    diff.max_xy_ratio = std::max(diff.max_xy_ratio, d / xy_tolerance(b));
  }
  diff.points += fast.size();
}

// Decodes every packet with the fast decoder (both APIs) and the reference, and compares.
void compare_packets(const std::vector<std::vector<std::uint8_t>>& packets, const Calibration& cal,
                     const DecoderOptions& options, Diff& diff, const std::string& what) {
  const Decoder fast(cal, options);
  const reference::Decoder ref(cal, options);
  std::vector<LidarPoint> a;
  std::vector<LidarPoint> b;
  std::vector<LidarPoint> room(Decoder::kMaxPointsPerPacket);
  for (std::size_t k = 0; k < packets.size(); ++k) {
    a.clear();
    b.clear();
    const auto h = fast.decode(packets[k], a);
    // Room filled with garbage first: decode() must write every field of every point it keeps.
    std::memset(static_cast<void*>(room.data()), 0xA5, room.size() * sizeof(LidarPoint));
    std::size_t count = 999;
    const auto h2 = fast.decode(packets[k], std::span<LidarPoint, Decoder::kMaxPointsPerPacket>(room), count);
    ASSERT_EQ(h.has_value(), h2.has_value()) << what;
    if (!h) {
      EXPECT_TRUE(a.empty());
      EXPECT_EQ(count, 0U);
      EXPECT_EQ(h.error(), h2.error());
      AzimuthRange bounds{123, 45};
      count = 999;
      const auto h3 = fast.decode(packets[k], std::span<LidarPoint, Decoder::kMaxPointsPerPacket>(room), count, bounds);
      ASSERT_FALSE(h3.has_value()) << what;
      EXPECT_EQ(count, 0U);
      EXPECT_EQ(bounds.min_cdeg, 0);  // an error leaves no bounds: every azimuth
      EXPECT_EQ(bounds.max_cdeg, 0xFFFF);
      continue;
    }
    ASSERT_EQ(count, a.size()) << what << " packet " << k;
    ASSERT_EQ(std::memcmp(static_cast<const void*>(room.data()), static_cast<const void*>(a.data()),
                          count * sizeof(LidarPoint)),
              0)
        << what << " packet " << k << ": the two decode() overloads differ";
    // The overload that also gives azimuth bounds: the same points, each azimuth inside the bounds.
    std::memset(static_cast<void*>(room.data()), 0x3C, room.size() * sizeof(LidarPoint));
    AzimuthRange bounds{123, 45};
    const auto h3 = fast.decode(packets[k], std::span<LidarPoint, Decoder::kMaxPointsPerPacket>(room), count, bounds);
    ASSERT_TRUE(h3.has_value()) << what;
    ASSERT_EQ(count, a.size()) << what << " packet " << k;
    ASSERT_EQ(std::memcmp(static_cast<const void*>(room.data()), static_cast<const void*>(a.data()),
                          count * sizeof(LidarPoint)),
              0)
        << what << " packet " << k << ": decode() with azimuth bounds differs";
    ASSERT_LE(bounds.min_cdeg, bounds.max_cdeg) << what << " packet " << k;
    for (std::size_t i = 0; i < count; ++i) {
      ASSERT_GE(a[i].azimuth_cdeg, bounds.min_cdeg) << what << " packet " << k << " point " << i;
      ASSERT_LE(a[i].azimuth_cdeg, bounds.max_cdeg) << what << " packet " << k << " point " << i;
    }
    ++diff.packets;
    if (bounds.min_cdeg > 0 || bounds.max_cdeg < 0xFFFF) {
      ++diff.bounded;
      EXPECT_LT(bounds.max_cdeg, 36000) << what << " packet " << k;
    }
    // velodyne::Stream's steps: the same bounds from the azimuths alone (azimuths(), read once), the same points
    // byte for byte from decode_accepted() with those azimuths, and with a time offset the times
    // RotationAssembler::commit() would make of them, nothing else changed.
    const Decoder::PacketAzimuths early = fast.azimuths(packets[k], *h);
    EXPECT_EQ(early.bounds().min_cdeg, bounds.min_cdeg) << what << " packet " << k;
    EXPECT_EQ(early.bounds().max_cdeg, bounds.max_cdeg) << what << " packet " << k;
    const std::span<LidarPoint, Decoder::kMaxPointsPerPacket> fixed(room);
    std::memset(static_cast<void*>(room.data()), 0x5A, room.size() * sizeof(LidarPoint));
    ASSERT_EQ(fast.decode_accepted(packets[k], *h, early, fixed, std::nullopt), a.size()) << what << " packet " << k;
    ASSERT_EQ(std::memcmp(static_cast<const void*>(room.data()), static_cast<const void*>(a.data()),
                          a.size() * sizeof(LidarPoint)),
              0)
        << what << " packet " << k << ": decode_accepted() differs";
    for (const double offset : {0.1234567891, -0.0421, 0.0}) {
      std::memset(static_cast<void*>(room.data()), 0x77, room.size() * sizeof(LidarPoint));
      ASSERT_EQ(fast.decode_accepted(packets[k], *h, early, fixed, offset), a.size()) << what << " packet " << k;
      std::vector<LidarPoint> shifted = a;
      for (auto& p : shifted) p.time_s = static_cast<float>(offset + static_cast<double>(p.time_s));
      ASSERT_EQ(std::memcmp(static_cast<const void*>(room.data()), static_cast<const void*>(shifted.data()),
                            a.size() * sizeof(LidarPoint)),
                0)
          << what << " packet " << k << ": decode_accepted() with time offset " << offset << " differs";
    }
    ref.decode(packets[k], *h, b);
    expect_same_points(a, b, diff, what + " packet " + std::to_string(k));
    if (testing::Test::HasFatalFailure()) return;
  }
}

std::vector<std::vector<std::uint8_t>> capture(const char* file) {
  std::vector<std::vector<std::uint8_t>> out;
  for (auto& r : test::read_data_packets(test::test_data(file))) out.push_back(std::move(r.payload));
  return out;
}

// Per-laser corrections of every kind on every laser (within what real calibration files hold).
Calibration corrected(Model m) {
  Calibration cal = default_calibration(m);
  for (std::size_t i = 0; i < cal.lasers.size(); ++i) {
    const double k = static_cast<double>(i);
    cal.lasers[i].rot_deg = std::fmod(k * 0.37, 3.0) - 1.5;
    cal.lasers[i].dist_m = std::fmod(k * 0.013, 0.1) - 0.05;
    cal.lasers[i].vert_offset_m = std::fmod(k * 0.007, 0.04) - 0.02;
    cal.lasers[i].horiz_offset_m = std::fmod(k * 0.011, 0.06) - 0.03;
  }
  return cal;
}

// Azimuth corrections beyond 350 degrees (as the fuzzer feeds): the decoder's general wrapping path.
Calibration huge_rotations(Model m) {
  Calibration cal = corrected(m);
  for (std::size_t i = 0; i < cal.lasers.size(); ++i) {
    cal.lasers[i].rot_deg = (i % 2 == 0 ? -1.0 : 1.0) * 725.3 * static_cast<double>(i % 3);
  }
  return cal;
}

TEST(VelodyneDecoderFast, RealCapturesMatchTheReferenceDecoder) {
  struct Case {
    const char* file;
    Model model;
  };
  Diff diff;
  for (const Case& c : {Case{"hdl32e_monterey_600.pcap", Model::HDL32E}, Case{"velodyne_vlp32.pcap", Model::HDL32E},
                        Case{"vlp16_veloview_300.pcap", Model::VLP16}, Case{"velodyne_vlp16.pcap", Model::VLP16},
                        Case{"velodyne_example.pcap", Model::VLP16}}) {
    const auto packets = capture(c.file);
    ASSERT_FALSE(packets.empty()) << c.file;
    for (auto ref : {TimestampReference::FirstFiring, TimestampReference::LastFiring}) {
      for (int calib = 0; calib < 3; ++calib) {
        DecoderOptions o;
        o.model = c.model;
        o.timestamp_reference = ref;
        const Calibration cal = calib == 0   ? default_calibration(c.model)
                                : calib == 1 ? corrected(c.model)
                                             : huge_rotations(c.model);
        compare_packets(packets, cal, o, diff, std::string(c.file) + " calibration " + std::to_string(calib));
        if (HasFatalFailure()) return;
      }
    }
  }
  std::cout << "[fast vs reference decoder, real captures] " << diff.points << " points, largest x/y difference "
            << diff.max_xy_m * 1000.0 << " mm (" << diff.max_xy_ratio * 100.0 << " % of the tolerance)\n";
  RecordProperty("max_xy_difference_mm", std::to_string(diff.max_xy_m * 1000.0));
  EXPECT_GT(diff.points, 1'000'000U);
  // Bounds for all but the packets whose firings wrap past 0 (about one per rotation) and those decoded with
  // corrections beyond 350 degrees (a third of the runs): RotationAssembler::commit() relies on them for speed.
  std::cout << "[azimuth bounds, real captures] " << diff.bounded << " of " << diff.packets << " packets bounded\n";
  EXPECT_GT(diff.bounded, diff.packets * 6 / 10);
}

// A calibration whose azimuth corrections (up to 160 degrees) wrap many firings past 0, still on the decoder's
// fast wrapping path (under 350 degrees).
Calibration large_rotations(Model m) {
  Calibration cal = corrected(m);
  for (std::size_t i = 0; i < cal.lasers.size(); ++i) {
    cal.lasers[i].rot_deg = (i % 2 == 0 ? -1.0 : 1.0) * 40.0 * static_cast<double>(i % 5);
  }
  return cal;
}

// Azimuth bounds where corrections make firings wrap: bounded only where no firing wraps, and then right.
TEST(VelodyneDecoderFast, AzimuthBoundsHoldEveryPointWithLargeCorrections) {
  Diff diff;
  for (const char* file : {"hdl32e_monterey_600.pcap", "vlp16_veloview_300.pcap"}) {
    const Model m = std::string(file).starts_with("vlp16") ? Model::VLP16 : Model::HDL32E;
    DecoderOptions o;
    o.model = m;
    compare_packets(capture(file), large_rotations(m), o, diff, std::string(file) + " large rotations");
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(diff.packets, 500U);
  EXPECT_GT(diff.bounded, 0U);
  EXPECT_LT(diff.bounded, diff.packets);
}

// Random packets: every return mode and layout, azimuth steps across 0 and corrupted ones, ranges at and beyond
// the limits, dual pairs with equal and different returns, both models, three calibrations.
TEST(VelodyneDecoderFast, RandomPacketsMatchTheReferenceDecoder) {
  std::mt19937 rng(20240611);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  Diff diff;
  for (Model m : {Model::HDL32E, Model::VLP16}) {
    for (int mode = 0; mode < 5; ++mode) {  // strongest, last, dual, dual by layout only, unset byte
      std::vector<std::vector<std::uint8_t>> packets;
      for (int k = 0; k < 150; ++k) {
        PacketBuilder p;
        const bool dual = mode == 2 || mode == 3;
        const int step = k % 10 == 0 ? uniform(0, 2000) : uniform(0, 120);  // some beyond the 500 plausible
        p.azimuths(uniform(0, 35999), step, dual);
        const std::uint8_t return_byte = mode == 0 ? 0x37 : mode == 1 ? 0x38 : mode == 2 ? 0x39 : mode == 3 ? 0x55 : 0;
        p.factory(return_byte, m == Model::VLP16 ? 0x22 : 0x21);
        p.timestamp(static_cast<std::uint32_t>(uniform(0, 2'000'000'000)));
        for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
          for (std::size_t s = 0; s < kSlotsPerBlock; ++s) {
            const int kind = uniform(0, 9);
            const int raw = kind == 0   ? 0
                            : kind == 1 ? uniform(1, 300)
                            : kind == 2 ? uniform(64900, 65535)
                                        : uniform(1, 65535);
            p.slot(b, s, static_cast<std::uint16_t>(raw), static_cast<std::uint8_t>(uniform(0, 255)));
          }
        }
        if (dual) {  // a third of the pairs: one echo, both blocks equal
          for (std::size_t b = 0; b < kBlocksPerPacket; b += 2) {
            for (std::size_t s = 0; s < kSlotsPerBlock; ++s) {
              if (uniform(0, 2) != 0) continue;
              const std::size_t off = b * kBlockSize + 4 + 3 * s;
              std::copy_n(p.bytes().begin() + static_cast<std::ptrdiff_t>(off), 3,
                          p.bytes().begin() + static_cast<std::ptrdiff_t>(off + kBlockSize));
            }
          }
        }
        packets.push_back(p.bytes());
      }
      for (int calib = 0; calib < 3; ++calib) {
        for (auto ref : {TimestampReference::FirstFiring, TimestampReference::LastFiring}) {
          DecoderOptions o;
          o.model = m;
          o.timestamp_reference = ref;
          o.min_range_m = calib == 1 ? 0.0 : 0.5;
          const Calibration cal = calib == 0 ? default_calibration(m) : calib == 1 ? corrected(m) : huge_rotations(m);
          compare_packets(
              packets, cal, o, diff,
              std::string(to_string(m)) + " mode " + std::to_string(mode) + " calibration " + std::to_string(calib));
          if (HasFatalFailure()) return;
        }
      }
    }
  }
  std::cout << "[fast vs reference decoder, random packets] " << diff.points << " points, largest x/y difference "
            << diff.max_xy_m * 1000.0 << " mm\n";
  EXPECT_GT(diff.points, 500'000U);
}

// The azimuth table's own error: every whole and many fractional azimuths at 130 m, against cos/sin in double of
// the very float azimuth the decoder computes (replicated here), so that only the table's error is measured.
// decode_accepted() is for packets read_packet_header() and accept() passed, with their azimuths(): anything else
// decodes to nothing.
TEST(VelodyneDecoderFast, DecodeAcceptedRefusesWhatDecodeRefuses) {
  const auto packets = capture("hdl32e_monterey_600.pcap");
  ASSERT_FALSE(packets.empty());
  const auto header = read_packet_header(packets.front());
  ASSERT_TRUE(header.has_value());
  std::vector<LidarPoint> room(Decoder::kMaxPointsPerPacket);
  const std::span<LidarPoint, Decoder::kMaxPointsPerPacket> fixed(room);
  DecoderOptions o;
  o.model = Model::HDL32E;
  const Decoder hdl(default_calibration(Model::HDL32E), o);
  EXPECT_FALSE(hdl.accept(*header).has_value());
  const Decoder::PacketAzimuths az = hdl.azimuths(packets.front(), *header);
  EXPECT_GT(hdl.decode_accepted(packets.front(), *header, az, fixed, std::nullopt), 0U);
  // Too short a payload for the header it is given.
  const std::vector<std::uint8_t> cut(packets.front().begin(), packets.front().begin() + 600);
  EXPECT_EQ(hdl.decode_accepted(cut, *header, az, fixed, 0.5), 0U);
  const Decoder::PacketAzimuths cut_az = hdl.azimuths(cut, *header);
  EXPECT_EQ(cut_az.bounds().min_cdeg, 0);
  EXPECT_EQ(cut_az.bounds().max_cdeg, 0xFFFF);
  EXPECT_EQ(hdl.decode_accepted(packets.front(), *header, cut_az, fixed, 0.5), 0U);
  // Azimuths made by no decoder.
  EXPECT_EQ(hdl.decode_accepted(packets.front(), *header, Decoder::PacketAzimuths{}, fixed, std::nullopt), 0U);
  // Azimuths of the other return layout (dual: 6 groups, not 12).
  PacketHeader dual = *header;
  dual.return_mode = ReturnMode::Dual;
  EXPECT_EQ(hdl.decode_accepted(packets.front(), dual, az, fixed, std::nullopt), 0U);
  EXPECT_EQ(hdl.decode_accepted(packets.front(), *header, hdl.azimuths(packets.front(), dual), fixed, std::nullopt),
            0U);
  // A block azimuth read_packet_header() would refuse (36000 or more): no bounds, nothing decoded.
  std::vector<std::uint8_t> bad_azimuth = packets.front();
  bad_azimuth[kBlockSize * 5 + 2] = 0xFF;
  bad_azimuth[kBlockSize * 5 + 3] = 0xFF;
  ASSERT_FALSE(read_packet_header(bad_azimuth).has_value());
  const Decoder::PacketAzimuths bad_az = hdl.azimuths(bad_azimuth, *header);
  EXPECT_EQ(bad_az.bounds().max_cdeg, 0xFFFF);
  EXPECT_EQ(hdl.decode_accepted(bad_azimuth, *header, bad_az, fixed, std::nullopt), 0U);
  // A product byte of another sensor: ModelMismatch, as decode() says.
  PacketHeader other = *header;
  other.product_byte = 0x28;
  EXPECT_EQ(hdl.accept(other), DecodeError::ModelMismatch);
  EXPECT_EQ(hdl.decode_accepted(packets.front(), other, az, fixed, std::nullopt), 0U);
  // No model: NoModel.
  o.model = Model::Unknown;
  const Decoder none(default_calibration(Model::HDL32E), o);
  EXPECT_EQ(none.accept(*header), DecodeError::NoModel);
  EXPECT_EQ(none.decode_accepted(packets.front(), *header, az, fixed, std::nullopt), 0U);
}

// A decoder given the azimuths another decoder read (other azimuth corrections) does not trust their bounds: its
// points are still exactly its own decode()'s, also where its corrections carry firings across 0 that the other
// decoder's bounds would call unwrapped.
TEST(VelodyneDecoderFast, DecodeAcceptedIgnoresBoundsOfOtherCorrections) {
  DecoderOptions o;
  o.model = Model::HDL32E;
  const Decoder plain(default_calibration(Model::HDL32E), o);
  Calibration turned = default_calibration(Model::HDL32E);
  for (auto& laser : turned.lasers) laser.rot_deg = 20.0;  // every firing 20 degrees back: past 0 near azimuth 0
  const Decoder shifted(turned, o);
  std::vector<LidarPoint> room(Decoder::kMaxPointsPerPacket);
  const std::span<LidarPoint, Decoder::kMaxPointsPerPacket> fixed(room);
  std::vector<LidarPoint> want;
  std::size_t compared = 0;
  for (const int first_cdeg : {5, 300, 1000, 1900, 2100, 18000, 35900}) {
    PacketBuilder b;
    for (std::size_t blk = 0; blk < kBlocksPerPacket; ++blk) {
      b.azimuth(blk, static_cast<std::uint16_t>((first_cdeg + static_cast<int>(blk) * 9) % 36000));
      for (std::size_t slot = 0; slot < kSlotsPerBlock; ++slot) {
        b.slot(blk, slot, static_cast<std::uint16_t>(1000 + 37 * slot + blk), static_cast<std::uint8_t>(slot));
      }
    }
    const std::vector<std::uint8_t> packet = b.bytes();
    const auto h = read_packet_header(packet);
    ASSERT_TRUE(h.has_value());
    const Decoder::PacketAzimuths foreign = plain.azimuths(packet, *h);
    want.clear();
    ASSERT_TRUE(shifted.decode(packet, want).has_value());
    std::memset(static_cast<void*>(room.data()), 0x11, room.size() * sizeof(LidarPoint));
    ASSERT_EQ(shifted.decode_accepted(packet, *h, foreign, fixed, std::nullopt), want.size()) << first_cdeg;
    ASSERT_FALSE(want.empty());
    EXPECT_EQ(std::memcmp(static_cast<const void*>(room.data()), static_cast<const void*>(want.data()),
                          want.size() * sizeof(LidarPoint)),
              0)
        << "first azimuth " << first_cdeg;
    compared += want.size();
  }
  EXPECT_GT(compared, 0U);
}

// The integer range test (raw distance bounds per slot, worked out at construction) keeps exactly the returns the
// float test keeps, for every raw distance of every slot, under calibrations and limits that put the bounds
// anywhere: none kept, all kept, a distance correction that keeps or drops raw 0's range, non-finite limits.
TEST(VelodyneDecoderFast, RangeTestInIntegersMatchesFloatTest) {
  struct Case {
    double dist_m;  // every laser's distance correction
    double min_m;
    double max_m;
    double resolution_m;
  };
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Case cases[] = {{0.0, 0.5, 130.0, 0.002}, {1.2, 0.5, 130.0, 0.002},   {-0.3, 0.0, 130.0, 0.002},
                        {0.0, 0.0, inf, 0.002},   {0.0, 131.0, 130.0, 0.002}, {0.0, 0.5, 130.0, 0.004},
                        {0.0, nan, 130.0, 0.002}, {0.0, 0.5, nan, 0.002},     {2.0, 2.0, 2.0, 0.002},
                        {0.0, 0.5, 1e-3, 1e-7},   {-inf, 0.5, 130.0, 0.002},  {nan, 0.5, 130.0, 0.002}};
  std::size_t cases_run = 0;
  for (const Case& c : cases) {
    Calibration cal = default_calibration(Model::VLP16);
    cal.distance_resolution_m = c.resolution_m;
    for (std::size_t j = 0; j < cal.lasers.size(); ++j) {
      cal.lasers[j].dist_m = c.dist_m + (std::isfinite(c.dist_m) ? 0.001 * static_cast<double>(j) : 0.0);
    }
    DecoderOptions o;
    o.model = Model::VLP16;
    o.min_range_m = c.min_m;
    o.max_range_m = c.max_m;
    const Decoder d(cal, o);
    // Every raw distance 0..65535 in some slot of some block: 12 blocks x 32 slots per packet, the raw values
    // stepped so that each slot meets every value across the packets.
    std::vector<LidarPoint> got;
    const auto res = static_cast<float>(c.resolution_m);
    const auto min_r = static_cast<float>(c.min_m);
    const auto max_r = static_cast<float>(c.max_m);
    std::size_t kept_want = 0;
    std::size_t kept_got = 0;
    for (std::uint32_t base = 0; base < 0x10000; base += kBlocksPerPacket) {
      PacketBuilder b;
      for (std::size_t blk = 0; blk < kBlocksPerPacket; ++blk) {
        b.azimuth(blk, static_cast<std::uint16_t>(18000 + 10 * blk));
        for (std::size_t slot = 0; slot < kSlotsPerBlock; ++slot) {
          const auto raw = static_cast<std::uint16_t>((base + blk + 4096 * (slot % 16)) & 0xFFFF);
          b.slot(blk, slot, raw, 7);
          const float dist = static_cast<float>(cal.lasers[slot % 16].dist_m);
          const float range = static_cast<float>(raw) * res + dist;
          if (raw != 0 && range >= min_r && range <= max_r) ++kept_want;
        }
      }
      got.clear();
      ASSERT_TRUE(d.decode(b.bytes(), got).has_value());
      kept_got += got.size();
    }
    EXPECT_EQ(kept_got, kept_want) << "dist " << c.dist_m << " limits " << c.min_m << ".." << c.max_m;
    ++cases_run;
  }
  EXPECT_EQ(cases_run, std::size(cases));
}

TEST(VelodyneDecoderFast, AzimuthTableErrorAt130m) {
  DecoderOptions o;
  o.model = Model::HDL32E;
  o.timestamp_reference = TimestampReference::FirstFiring;
  const Calibration cal = default_calibration(Model::HDL32E);
  const Decoder d(cal, o);
  const reference::Decoder ref(cal, o);
  constexpr std::uint16_t kRaw = 65000;  // 130 m
  double max_err_m = 0.0;
  double max_err_rel = 0.0;
  double ref_max_err_m = 0.0;
  std::size_t points = 0;
  std::vector<LidarPoint> pts;
  std::vector<LidarPoint> ref_pts;
  for (int step : {1, 7, 43, 499}) {  // block azimuth steps: whole azimuths at slot 0, fractional at the others
    for (int start = 0; start < 36000; start += 12 * step + 1) {
      PacketBuilder p;
      p.azimuths(start, step);
      for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
        for (std::size_t s = 0; s < kSlotsPerBlock; ++s) p.slot(b, s, kRaw, 1);
      }
      pts.clear();
      const auto h = d.decode(p.span(), pts);
      ASSERT_TRUE(h.has_value());
      ASSERT_EQ(pts.size(), kBlocksPerPacket * kSlotsPerBlock);
      ref_pts.clear();
      ref.decode(p.span(), *h, ref_pts);
      ASSERT_EQ(ref_pts.size(), pts.size());
      for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
        const int az = (start + step * static_cast<int>(b)) % 36000;
        const int next = (start + step * static_cast<int>(std::min<std::size_t>(b + 1, 11))) % 36000;
        const int raw_step = (next - az + 36000) % 36000;
        const float delta = static_cast<float>(b == 11 ? step : raw_step);
        for (std::size_t s = 0; s < kSlotsPerBlock; ++s) {
          // The decoder's float azimuth (velodyne_decoder.cpp): block azimuth + step * share of the block.
          const float in_block_us = static_cast<float>(s) * 1.152F;
          float a = static_cast<float>(az) + delta * (in_block_us / 46.08F);
          if (a >= 36000.F) a -= 36000.F;
          const double rad = static_cast<double>(a) * std::numbers::pi / 18000.0;
          const LidarPoint& q = pts[b * kSlotsPerBlock + s];
          const double w = cal.lasers[s].vert_deg * std::numbers::pi / 180.0;
          const double xy = static_cast<double>(q.range_m) * static_cast<double>(static_cast<float>(std::cos(w)));
          const double err =
              std::hypot(static_cast<double>(q.x) - xy * std::cos(rad), static_cast<double>(q.y) + xy * std::sin(rad));
          max_err_m = std::max(max_err_m, err);
          max_err_rel = std::max(max_err_rel, err / xy);
          const LidarPoint& r = ref_pts[b * kSlotsPerBlock + s];
          ref_max_err_m = std::max(ref_max_err_m, std::hypot(static_cast<double>(r.x) - xy * std::cos(rad),
                                                             static_cast<double>(r.y) + xy * std::sin(rad)));
          ++points;
        }
      }
    }
  }
  std::cout << "[azimuth table] " << points << " points at 130 m: largest error " << max_err_m * 1000.0 << " mm ("
            << max_err_rel << " of the horizontal distance); the reference decoder's (libm on a float angle): "
            << ref_max_err_m * 1000.0 << " mm\n";
  RecordProperty("table_max_error_mm_at_130m", std::to_string(max_err_m * 1000.0));
  RecordProperty("reference_max_error_mm_at_130m", std::to_string(ref_max_err_m * 1000.0));
  // The table errs by under 1e-7 (0.013 mm at 130 m); the float products x = xy cos a add up to 1.5 ulp of 130 m.
  EXPECT_LT(max_err_m, 0.013e-3 + 1.5 * 1.53e-5);
}

}  // namespace
}  // namespace fieldguard::velodyne
