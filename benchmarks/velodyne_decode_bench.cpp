// Velodyne decoding and rotation assembly throughput on one core, against the sensor's line rate.
//   bench_velodyne_decode [--benchmark_filter=...] [--benchmark_repetitions=5 --benchmark_report_aggregates_only=true]
//
// Inputs (tests/data/PROVENANCE.txt):
//  - hdl32e_monterey_600.pcap: 540 real HDL-32E data packets (strongest return, ~11.7 Hz, ~3.5 rotations);
//  - vlp16_veloview_300.pcap: 253 real VLP-16 data packets (early firmware, ~20 Hz);
//  - velodyne_vlp32.pcap: 91 real HDL-32E data packets (the capture this benchmark used first; kept to compare);
//  - "rotation5hz": one 5 Hz HDL-32E rotation synthesized from the Monterey packets (synth_rotation() below):
//    362 packets (1808 packets/s / 5 Hz) whose every one of the 384 slots holds a return in range = 139,008 points,
//    the "139,000-point rotation" of issue 3; the 414-packet variant (158,976 points) is the pessimistic reading
//    "414 packets, every slot a return" of the same budget.
//
// Benchmarks, each on every input (an iteration = every packet of the input once):
//  - Decode: Decoder::decode() of every packet into a reused vector.
//  - DecodeRoom: Decoder::decode() into a fixed room of one packet's points: decoding alone.
//  - DecodeAssemble: Decoder::decode() into a vector, then RotationAssembler::push() (the two-step way).
//  - DecodeInPlace: the decoder writes straight into the frame (RotationAssembler::append_room() / commit()).
//  - Stream: velodyne::Stream::push(), the production path replay runs (header check, model detection, decode
//    in place, sensor time, assembly).
//  - ...Recycle: the same, the consumer handing its frames back (recycle()) instead of freeing them.
// Assemblers and streams live across iterations (steady state: a capture is replayed in a loop; a rotation input
// yields one frame per iteration); the frames of an iteration are dropped (or recycled) at the next one, as a
// consumer would. Build with -DFIELDGUARD_BENCH_BEFORE_IN_PLACE_API to run only Decode, DecodeAssemble and
// Stream, which also compile against the code before the in-place API (for before/after figures).
//
// Counters (plain numbers, computed from this thread's CPU time over the whole timed loop):
//   packets_per_s, ns_per_point, x_line_rate (packets_per_s / the model's single-return packet rate),
//   ms_per_rotation (rotation inputs: CPU time per iteration = per rotation), points_per_packet.
#include <benchmark/benchmark.h>
#include <time.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fieldguard/drivers/rotation_assembler.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"

namespace {

using namespace fieldguard;
using namespace fieldguard::velodyne;

constexpr double kHdl32LineRate = 1808.0;  // packets/s, single return (1 / (12 * 46.08 us))
constexpr double kVlp16LineRate = 754.0;   // packets/s, single return (1 / (12 * 110.592 us))

struct Packet {
  Stamp host;
  std::vector<std::uint8_t> bytes;
};

struct Input {
  std::vector<Packet> packets;
  Model model = Model::HDL32E;
  double line_rate = kHdl32LineRate;
  bool rotation = false;  // one whole rotation: keep the assembler across iterations
};

// Classic little-endian pcap, Ethernet, IPv4 without options: the 1206-byte UDP payloads at offset 42.
// Benchmark scaffolding only; the product reads captures through the io module.
std::vector<Packet> load(const std::string& name) {
  std::ifstream in(std::string(FIELDGUARD_TEST_DATA) + "/" + name, std::ios::binary);
  const std::vector<std::uint8_t> f((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<Packet> out;
  const ByteSpan all(f);
  if (f.size() < 24 || load_le32(all, 0) != 0xA1B2C3D4U) return out;
  for (std::size_t off = 24; off + 16 <= f.size();) {
    const std::uint32_t sec = load_le32(all, off);
    const std::uint32_t usec = load_le32(all, off + 4);
    const std::uint32_t incl = load_le32(all, off + 8);
    off += 16;
    if (incl > f.size() - off) break;
    if (incl == 42 + kDataPacketSize) {
      const ByteSpan payload = all.subspan(off + 42, kDataPacketSize);
      out.push_back({Stamp{static_cast<std::int64_t>(sec) * 1'000'000'000 + static_cast<std::int64_t>(usec) * 1000},
                     std::vector<std::uint8_t>(payload.begin(), payload.end())});
    }
    off += incl;
  }
  return out;
}

void put16(std::vector<std::uint8_t>& b, std::size_t off, std::uint32_t v) {
  b[off] = static_cast<std::uint8_t>(v & 0xFFU);
  b[off + 1] = static_cast<std::uint8_t>((v >> 8) & 0xFFU);
}

// One 5 Hz HDL-32E rotation of `count` packets, every slot a return between 0.5 and 130 m (so every slot becomes a
// point with the default range limits). Made from the real Monterey packets, in order (wrapping around if more are
// needed): their real ranges and intensities are kept where they are in range; a slot without a return, or with a
// range outside 0.5..130 m, gets a synthetic 10.0-12.8 m range (5000 + 37 * slot + 11 * block, 2 mm units). The
// block azimuths are rewritten to advance evenly over one turn, starting at 0 degrees (7-8 cdeg per block, as at
// 5 Hz), and the timestamps to 552.96 us per packet (rounded to whole us, as the sensor writes them).
std::vector<Packet> synth_rotation(std::size_t count) {
  const std::vector<Packet> real = load("hdl32e_monterey_600.pcap");
  std::vector<Packet> out;
  if (real.empty()) return out;
  const std::size_t blocks = count * kBlocksPerPacket;
  const std::int64_t host0 = real.front().host.ns;
  constexpr std::uint32_t kStartUs = 1'000'000'000U;  // 16:40 past the hour
  for (std::size_t i = 0; i < count; ++i) {
    Packet p = real[i % real.size()];
    for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
      const std::size_t k = i * kBlocksPerPacket + b;
      put16(p.bytes, b * kBlockSize + 2, static_cast<std::uint32_t>(k * 36000 / blocks));
      for (std::size_t s = 0; s < kSlotsPerBlock; ++s) {
        const std::size_t off = b * kBlockSize + 4 + 3 * s;
        const std::uint16_t raw = load_le16(p.bytes, off);
        if (raw < 250 || raw > 65000) put16(p.bytes, off, static_cast<std::uint32_t>(5000 + 37 * s + 11 * b));
      }
    }
    const auto t_us = static_cast<std::uint32_t>(kStartUs + (i * 552960 + 500) / 1000);
    for (std::size_t k = 0; k < 4; ++k) p.bytes[1200 + k] = static_cast<std::uint8_t>((t_us >> (8 * k)) & 0xFFU);
    p.host = Stamp{host0 + static_cast<std::int64_t>(i) * 552'960};
    out.push_back(std::move(p));
  }
  return out;
}

const Input& input(const std::string& name) {
  static std::vector<std::pair<std::string, Input>> cache;
  for (const auto& [n, in] : cache) {
    if (n == name) return in;
  }
  Input in;
  if (name == "monterey_hdl32e") {
    in.packets = load("hdl32e_monterey_600.pcap");
  } else if (name == "veloview_vlp16") {
    in.packets = load("vlp16_veloview_300.pcap");
    in.model = Model::VLP16;
    in.line_rate = kVlp16LineRate;
  } else if (name == "vlp32file_hdl32e") {
    in.packets = load("velodyne_vlp32.pcap");
  } else if (name == "rotation5hz_362") {
    in.packets = synth_rotation(362);
    in.rotation = true;
  } else if (name == "rotation5hz_414") {
    in.packets = synth_rotation(414);
    in.rotation = true;
  }
  cache.emplace_back(name, std::move(in));
  return cache.back().second;
}

double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// Counters from the CPU time of the whole timed loop (so they are plain numbers, not "/s" rates).
void report(benchmark::State& state, const Input& in, double seconds, std::size_t points_per_iteration) {
  const auto iterations = static_cast<double>(state.iterations());
  const double packets = iterations * static_cast<double>(in.packets.size());
  const double points = iterations * static_cast<double>(points_per_iteration);
  if (seconds <= 0.0 || packets <= 0.0) return;
  state.counters["packets_per_s"] = packets / seconds;
  state.counters["ns_per_point"] = points > 0.0 ? seconds * 1e9 / points : 0.0;
  state.counters["x_line_rate"] = packets / seconds / in.line_rate;
  state.counters["points_per_packet"] =
      static_cast<double>(points_per_iteration) / static_cast<double>(in.packets.size());
  if (in.rotation) state.counters["ms_per_rotation"] = seconds * 1e3 / iterations;
}

bool usable(benchmark::State& state, const Input& in) {
  if (in.packets.empty()) {
    state.SkipWithError("capture not found or empty");
    return false;
  }
  return true;
}

Decoder make_decoder(Model model) {
  DecoderOptions o;
  o.model = model;
  return Decoder(default_calibration(model), o);
}

StreamOptions stream_options(Model model) {
  StreamOptions o;
  o.model = model;
  return o;
}

void BM_Decode(benchmark::State& state, const std::string& name) {
  const Input& in = input(name);
  if (!usable(state, in)) return;
  const Decoder decoder = make_decoder(in.model);
  std::vector<LidarPoint> points;
  points.reserve(12 * 32 * 2);
  std::size_t per_iteration = 0;
  const double t0 = thread_cpu_s();
  for (auto _ : state) {
    per_iteration = 0;
    for (const auto& p : in.packets) {
      points.clear();
      const auto h = decoder.decode(p.bytes, points);
      benchmark::DoNotOptimize(h);
      benchmark::DoNotOptimize(points.data());
      per_iteration += points.size();
    }
  }
  report(state, in, thread_cpu_s() - t0, per_iteration);
}

// Decode into a vector, then push it to the assembler: the two-step way.
void BM_DecodeAssemble(benchmark::State& state, const std::string& name) {
  const Input& in = input(name);
  if (!usable(state, in)) return;
  const Decoder decoder = make_decoder(in.model);
  std::vector<LidarPoint> points;
  std::vector<LidarFrame> frames;
  std::size_t per_iteration = 0;
  RotationAssembler assembler(0.0);
  const double t0 = thread_cpu_s();
  for (auto _ : state) {
    frames.clear();  // the consumer is done with the previous iteration's frames
    per_iteration = 0;
    for (const auto& p : in.packets) {
      points.clear();
      const auto h = decoder.decode(p.bytes, points);
      if (!h) continue;
      assembler.push(points, sensor_time_from_hour_offset(h->timestamp_us, p.host), p.host, frames);
      per_iteration += points.size();
    }
    benchmark::DoNotOptimize(frames.data());
  }
  report(state, in, thread_cpu_s() - t0, per_iteration);
}

// The production path: velodyne::Stream (replay and the daemon push packets into it).
void stream_bench(benchmark::State& state, const std::string& name, bool recycle) {
  const Input& in = input(name);
  if (!usable(state, in)) return;
  std::vector<LidarFrame> frames;
  std::size_t per_iteration = 0;
  Stream stream(stream_options(in.model));
  const double t0 = thread_cpu_s();
  for (auto _ : state) {
    // The consumer is done with the previous iteration's frames.
    if (recycle) {
#ifndef FIELDGUARD_BENCH_BEFORE_IN_PLACE_API
      for (auto& f : frames) stream.recycle(std::move(f));
#endif
    }
    frames.clear();
    const std::uint64_t before = stream.counters().points;
    for (const auto& p : in.packets) stream.push(p.bytes, p.host, frames);
    per_iteration = static_cast<std::size_t>(stream.counters().points - before);
    benchmark::DoNotOptimize(frames.data());
  }
  report(state, in, thread_cpu_s() - t0, per_iteration);
}
void BM_Stream(benchmark::State& state, const std::string& name) { stream_bench(state, name, false); }

#define FG_ON_EVERY_INPUT(fn)                                               \
  BENCHMARK_CAPTURE(fn, monterey_hdl32e, std::string("monterey_hdl32e"));   \
  BENCHMARK_CAPTURE(fn, veloview_vlp16, std::string("veloview_vlp16"));     \
  BENCHMARK_CAPTURE(fn, vlp32file_hdl32e, std::string("vlp32file_hdl32e")); \
  BENCHMARK_CAPTURE(fn, rotation5hz_362, std::string("rotation5hz_362"));   \
  BENCHMARK_CAPTURE(fn, rotation5hz_414, std::string("rotation5hz_414"))

FG_ON_EVERY_INPUT(BM_Decode);
FG_ON_EVERY_INPUT(BM_DecodeAssemble);
FG_ON_EVERY_INPUT(BM_Stream);

// ---- The in-place API: decoding into given room, straight into the frame, recycled frame buffers ----
// (Left out with -DFIELDGUARD_BENCH_BEFORE_IN_PLACE_API, to run the benchmarks above on the code before it.)
#ifndef FIELDGUARD_BENCH_BEFORE_IN_PLACE_API

// Decoding alone: into a fixed room of one packet (no vector bookkeeping, no initialisation).
void BM_DecodeRoom(benchmark::State& state, const std::string& name) {
  const Input& in = input(name);
  if (!usable(state, in)) return;
  const Decoder decoder = make_decoder(in.model);
  std::vector<LidarPoint> room(Decoder::kMaxPointsPerPacket);
  const std::span<LidarPoint, Decoder::kMaxPointsPerPacket> span(room.data(), room.size());
  std::size_t per_iteration = 0;
  const double t0 = thread_cpu_s();
  for (auto _ : state) {
    per_iteration = 0;
    for (const auto& p : in.packets) {
      std::size_t count = 0;
      const auto h = decoder.decode(p.bytes, span, count);
      benchmark::DoNotOptimize(h);
      benchmark::DoNotOptimize(room.data());
      per_iteration += count;
    }
  }
  report(state, in, thread_cpu_s() - t0, per_iteration);
}

// Decoder and assembler joined by hand with the in-place API (what Stream does, without its header check and
// model detection), frames dropped or recycled by the consumer.
void in_place_bench(benchmark::State& state, const std::string& name, bool recycle) {
  const Input& in = input(name);
  if (!usable(state, in)) return;
  const Decoder decoder = make_decoder(in.model);
  std::vector<LidarFrame> frames;
  std::size_t per_iteration = 0;
  RotationAssembler assembler(0.0);
  const double t0 = thread_cpu_s();
  for (auto _ : state) {
    if (recycle) {
      for (auto& f : frames) assembler.recycle(std::move(f));
    }
    frames.clear();
    per_iteration = 0;
    for (const auto& p : in.packets) {
      const std::span<LidarPoint> room = assembler.append_room(Decoder::kMaxPointsPerPacket);
      std::size_t count = 0;
      const auto h =
          decoder.decode(p.bytes, std::span<LidarPoint, Decoder::kMaxPointsPerPacket>(room.data(), room.size()), count);
      if (!h) continue;
      assembler.commit(count, sensor_time_from_hour_offset(h->timestamp_us, p.host), p.host, frames);
      per_iteration += count;
    }
    benchmark::DoNotOptimize(frames.data());
  }
  report(state, in, thread_cpu_s() - t0, per_iteration);
}
void BM_DecodeInPlace(benchmark::State& state, const std::string& name) { in_place_bench(state, name, false); }
void BM_DecodeInPlaceRecycle(benchmark::State& state, const std::string& name) { in_place_bench(state, name, true); }
void BM_StreamRecycle(benchmark::State& state, const std::string& name) { stream_bench(state, name, true); }

FG_ON_EVERY_INPUT(BM_DecodeRoom);
FG_ON_EVERY_INPUT(BM_DecodeInPlace);
FG_ON_EVERY_INPUT(BM_DecodeInPlaceRecycle);
FG_ON_EVERY_INPUT(BM_StreamRecycle);

#endif  // FIELDGUARD_BENCH_BEFORE_IN_PLACE_API

}  // namespace

BENCHMARK_MAIN();
