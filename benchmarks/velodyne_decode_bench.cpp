// Velodyne decoding throughput on one core, against the sensor's line rate.
//   bench_velodyne_decode [--benchmark_filter=...]
// Captures: tests/data/velodyne_vlp32.pcap (an HDL-32E despite its name) and velodyne_vlp16.pcap (VLP-16);
// see tests/data/PROVENANCE.txt. Each iteration decodes every data packet of the capture once.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fieldguard/drivers/rotation_assembler.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"

namespace {

using namespace fieldguard;
using namespace fieldguard::velodyne;

constexpr double kHdl32LineRate = 1808.0;  // packets/s, single return (1 / (12 * 46.08 us))
constexpr double kVlp16LineRate = 754.0;   // packets/s, single return (1 / (12 * 110.592 us))

struct Packet {
  Stamp host;
  std::vector<std::uint8_t> bytes;
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

void set_counters(benchmark::State& state, std::size_t packets_per_iteration, std::size_t points, double line_rate) {
  const auto packets = static_cast<double>(state.iterations()) * static_cast<double>(packets_per_iteration);
  state.counters["packets_per_s"] = benchmark::Counter(packets, benchmark::Counter::kIsRate);
  state.counters["x_line_rate"] = benchmark::Counter(packets / line_rate, benchmark::Counter::kIsRate);
  state.counters["points_per_packet"] = static_cast<double>(points) / static_cast<double>(packets_per_iteration);
}

void decode_only(benchmark::State& state, const char* file, Model model, double line_rate) {
  const auto packets = load(file);
  if (packets.empty()) {
    state.SkipWithError("capture not found or empty");
    return;
  }
  DecoderOptions o;
  o.model = model;
  const Decoder decoder(default_calibration(model), o);
  std::vector<LidarPoint> points;
  points.reserve(12 * 32 * 2);
  std::size_t per_iteration = 0;
  for (auto _ : state) {
    per_iteration = 0;
    for (const auto& p : packets) {
      points.clear();
      const auto h = decoder.decode(p.bytes, points);
      benchmark::DoNotOptimize(h);
      benchmark::DoNotOptimize(points.data());
      per_iteration += points.size();
    }
  }
  set_counters(state, packets.size(), per_iteration, line_rate);
}

void BM_DecodeHdl32e(benchmark::State& state) {
  decode_only(state, "velodyne_vlp32.pcap", Model::HDL32E, kHdl32LineRate);
}
void BM_DecodeVlp16(benchmark::State& state) {
  decode_only(state, "velodyne_vlp16.pcap", Model::VLP16, kVlp16LineRate);
}

// Decode, sensor time and rotation assembly: what the daemon does per packet before the frame queue.
void BM_DecodeAndAssembleHdl32e(benchmark::State& state) {
  const auto packets = load("velodyne_vlp32.pcap");
  if (packets.empty()) {
    state.SkipWithError("capture not found or empty");
    return;
  }
  DecoderOptions o;
  o.model = Model::HDL32E;
  const Decoder decoder(default_calibration(Model::HDL32E), o);
  std::vector<LidarPoint> points;
  std::vector<LidarFrame> frames;
  std::size_t per_iteration = 0;
  for (auto _ : state) {
    RotationAssembler assembler(0.0);
    frames.clear();
    per_iteration = 0;
    for (const auto& p : packets) {
      points.clear();
      const auto h = decoder.decode(p.bytes, points);
      if (!h) continue;
      assembler.push(points, sensor_time_from_hour_offset(h->timestamp_us, p.host), p.host, frames);
      per_iteration += points.size();
    }
    assembler.finish(frames);
    benchmark::DoNotOptimize(frames.data());
  }
  set_counters(state, packets.size(), per_iteration, kHdl32LineRate);
}

BENCHMARK(BM_DecodeHdl32e);
BENCHMARK(BM_DecodeVlp16);
BENCHMARK(BM_DecodeAndAssembleHdl32e);

}  // namespace

BENCHMARK_MAIN();
