#pragma once
// Test support shared by the replay --can-log and `fieldguard run` end-to-end tests: a simulator capture of the
// pedestrian scene with its truth, file reading, and a reader of candump -L logs.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fieldguard/output/can_frame.hpp"
#include "io/pcap_builder.hpp"

namespace fieldguard::testing {

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::size_t count_lines(const std::string& s) {
  return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
}

// `fieldguard-sim --scene pedestrian --rotations N` into a temporary directory (a few seconds: write it once per
// test suite). `ok` says whether the simulator succeeded; `command` is what was run.
struct PedestrianCapture {
  // `sensor`: fieldguard-sim's --sensor (hdl32e, vlp16, rs32).
  explicit PedestrianCapture(int rotations, const std::string& sensor = "hdl32e")
      : pcap((dir.path() / "ped.pcap").string()), truth((dir.path() / "ped.truth.jsonl").string()) {
    command = std::string("'") + FIELDGUARD_SIM + "' --scene pedestrian --rotations " + std::to_string(rotations) +
              " --sensor " + sensor + " --quiet --pcap '" + pcap + "' --truth '" + truth + "'";
    ok = std::system(command.c_str()) == 0;
  }
  TempDir dir;
  std::string pcap;
  std::string truth;
  std::string command;
  bool ok = false;
};

// A recorded session of the simulator's uneven drive (every sensor: lidar.pcap and the byte logs), in a temporary
// directory: what a fused replay reads.
struct FusedSession {
  explicit FusedSession(int rotations) : path((dir.path() / "s").string()) {
    command = std::string("'") + FIELDGUARD_SIM + "' --scene uneven-drive --rotations " + std::to_string(rotations) +
              " --quiet --session '" + path + "'";
    ok = std::system(command.c_str()) == 0;
  }
  TempDir dir;
  std::string path;
  std::string command;
  bool ok = false;
};

struct LogFrame {
  long long us = 0;  // stamp, microseconds
  std::string iface;
  std::uint32_t id = 0;
  std::vector<std::uint8_t> data;
};

// "(0000001700.123456) can0 18FF1080#010000000000053E"; fails the test on any other line.
inline std::vector<LogFrame> read_candump(const std::string& text) {
  std::vector<LogFrame> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    LogFrame f;
    long long s = 0;
    long long us = 0;
    char iface[32] = {};
    char id[16] = {};
    char data[32] = {};
    const int n = std::sscanf(line.c_str(), "(%lld.%lld) %31s %15[0-9A-F]#%31[0-9A-F]", &s, &us, iface, id, data);
    EXPECT_EQ(n, 5) << "not a candump -L line: " << line;
    if (n != 5) continue;
    EXPECT_EQ(std::string(id).size(), 8U) << line;
    f.us = s * 1000000 + us;
    f.iface = iface;
    f.id = static_cast<std::uint32_t>(std::stoul(id, nullptr, 16));
    for (std::size_t i = 0; i + 1 < std::strlen(data); i += 2) {
      f.data.push_back(static_cast<std::uint8_t>(std::stoul(std::string(data + i, 2), nullptr, 16)));
    }
    out.push_back(std::move(f));
  }
  return out;
}

// The J1939 node's own frames (output/j1939_node.hpp: Address Claimed, requests, acknowledgements, transport,
// DM1/DM2, identifications), which fieldguard.dbc does not describe: its messages are the pipeline's.
inline bool is_node_frame(std::uint32_t id) {
  switch (output::j1939_fields(id).pgn) {
    case 0xE800:
    case 0xEA00:
    case 0xEB00:
    case 0xEC00:
    case 0xEE00:
    case 0xFECA:
    case 0xFECB:
    case 0xFEDA:
    case 0xFEEB: return true;
    default: return false;
  }
}

}  // namespace fieldguard::testing
