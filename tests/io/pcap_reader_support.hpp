#pragma once
// Shared by the PcapReader tests: datagrams to write, and reading a whole file back.

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "fieldguard/io/pcap_reader.hpp"
#include "io/pcap_builder.hpp"

namespace fieldguard::io::reader_test {

using testing::Bytes;

inline constexpr std::int64_t kT0 = 1'700'000'000'123'456'789;  // ns; sub-µs digits show the resolution

inline Bytes datagram(std::uint16_t port, std::size_t size, std::uint8_t seed = 0) {
  testing::Ipv4Udp d;
  d.src_port = port;
  d.dst_port = port;
  d.payload = testing::pattern(size, seed);
  return testing::build(d);
}

inline Bytes eth(std::uint16_t port, std::size_t size, std::uint8_t seed = 0) {
  return testing::ethernet(datagram(port, size, seed));
}

// Reads everything; returns the datagrams' (port, payload size, time) in order.
struct Seen {
  std::uint16_t port;
  std::size_t size;
  std::int64_t ns;
  friend bool operator==(const Seen&, const Seen&) = default;
};

inline std::vector<Seen> drain(PcapReader& r) {
  std::vector<Seen> seen;
  while (auto d = r.next()) seen.push_back({d->dst_port, d->payload.size(), d->host_time.ns});
  return seen;
}

// Opens a file the test expects to be good. On failure the test fails and gets a reader of an empty
// capture, so that it goes on without touching an error as a value.
inline PcapReader open_ok(const std::string& path) {
  auto r = PcapReader::open(path);
  if (r) return std::move(r).value();
  ADD_FAILURE() << r.error();
  static Bytes empty_capture = testing::ClassicPcap().bytes();
  auto fallback = PcapReader::open(::fmemopen(empty_capture.data(), empty_capture.size(), "rb"), "empty capture");
  return std::move(fallback).value();
}

inline std::uint64_t drops(const PcapReader& r, FrameDrop d) { return r.stats().drops[static_cast<std::size_t>(d)]; }

inline Bytes head(const Bytes& b, std::size_t n) { return {b.begin(), b.begin() + static_cast<std::ptrdiff_t>(n)}; }

}  // namespace fieldguard::io::reader_test
