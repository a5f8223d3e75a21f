// The 3D LiDAR, whichever is attached: routing by port, model decision, the two families' streams.
#include "fieldguard/drivers/lidar3d_stream.hpp"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "fieldguard/drivers/velodyne_calibration.hpp"

namespace fieldguard::lidar3d {

namespace {

constexpr std::array<std::uint8_t, 8> kMsopHeader = {0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0};
constexpr std::array<std::uint8_t, 4> kHeliosHeader = {0x55, 0xAA, 0x05, 0x5A};
constexpr std::size_t kModelByteOffset = 30;

std::string hex_byte(std::uint8_t b) {
  std::array<char, 8> s{};
  std::snprintf(s.data(), s.size(), "0x%02X", b);
  return s.data();
}

velodyne::Model velodyne_model(Model m) {
  switch (m) {
    case Model::HDL32E: return velodyne::Model::HDL32E;
    case Model::VLP16: return velodyne::Model::VLP16;
    default: return velodyne::Model::Unknown;
  }
}

}  // namespace

std::string_view to_string(Model m) {
  switch (m) {
    case Model::Auto: return "auto";
    case Model::HDL32E: return "HDL-32E";
    case Model::VLP16: return "VLP-16";
    case Model::RS32: return "RS-32";
  }
  return "?";
}

std::vector<double> ring_elevations_deg(Model m) {
  std::vector<double> out;
  if (m == Model::RS32) {
    const auto& v = robosense::nominal_calibration().vert_deg;
    out.assign(v.begin(), v.end());
  } else if (m != Model::Auto) {
    for (const auto& l : velodyne::default_calibration(velodyne_model(m)).lasers) out.push_back(l.vert_deg);
  }
  std::sort(out.begin(), out.end());
  return out;
}

MsopIdentity identify_msop(ByteSpan p) {
  MsopIdentity id;
  if (p.size() > kModelByteOffset && std::equal(kMsopHeader.begin(), kMsopHeader.end(), p.begin())) {
    const std::uint8_t b = p[kModelByteOffset];
    id.msop_header = true;
    id.detail = "model byte " + hex_byte(b);
    static constexpr std::array<const char*, 7> kNames = {"",        "RS-LiDAR-16",  "RS-LiDAR-32", "RS-Bpearl",
                                                          "RS-Ruby", "RS-Ruby Lite", "RS-Helios"};
    if (b < kNames.size()) id.name = kNames[b];
    if (id.name.empty()) id.detail += ", which names no RoboSense model (lidar.model: RS-32 takes it for one)";
    id.rs32 = b == 0x02;
    return id;
  }
  if (p.size() >= kHeliosHeader.size() && std::equal(kHeliosHeader.begin(), kHeliosHeader.end(), p.begin())) {
    id.name = "RS-Helios";
    id.detail = "header 55 AA 05 5A";
    return id;
  }
  id.detail = p.size() >= 4 ? "header " + hex_byte(p[0]).substr(2) + " " + hex_byte(p[1]).substr(2) + " " +
                                  hex_byte(p[2]).substr(2) + " " + hex_byte(p[3]).substr(2)
                            : "a " + std::to_string(p.size()) + "-byte datagram";
  return id;
}

Stream::Stream(StreamOptions options)
    : options_(std::move(options)),
      velodyne_([this] {
        velodyne::StreamOptions o = options_.velodyne;
        o.model = velodyne_model(options_.model);
        return o;
      }()),
      robosense_(options_.robosense) {
  if (options_.model == Model::RS32) decide(Family::RoboSense, "configured (lidar.model)");
  if (options_.model == Model::HDL32E || options_.model == Model::VLP16) {
    decide(Family::Velodyne, "configured (lidar.model)");
  }
}

void Stream::decide(Family f, std::string why) {
  family_ = f;
  why_ = std::move(why);
}

std::optional<Channel> Stream::channel_of(std::uint16_t port) const {
  const Ports& ports = options_.ports;
  if (port == ports.data) return Channel::VelodyneData;
  if (port == ports.msop) return Channel::Msop;
  if (port == ports.difop) return Channel::Difop;
  return std::nullopt;
}

Outcome Stream::push(Channel channel, ByteSpan payload, Stamp host, std::vector<LidarFrame>& done) {
  if (channel == Channel::VelodyneData) return push_velodyne(payload, host, done);
  if (channel == Channel::Msop) return push_msop(payload, host, done);
  if (const auto no = screen(payload, robosense::kPacketSize, Family::Velodyne)) return *no;
  // A DIFOP before the sensor is decided too: the decoder keeps what it says (angles, return mode) for the MSOP.
  robosense_.push_difop(payload);
  return Outcome::Info;
}

std::optional<Outcome> Stream::screen(ByteSpan payload, std::size_t packet_size, Family other) {
  if (payload.size() != packet_size) {
    ++own_.bad_length;
    return Outcome::BadLength;
  }
  if (family_ == other) {
    ++own_.other_family;
    return Outcome::OtherFamily;
  }
  return std::nullopt;
}

Outcome Stream::push_velodyne(ByteSpan payload, Stamp host, std::vector<LidarFrame>& done) {
  if (const auto no = screen(payload, velodyne::kDataPacketSize, Family::RoboSense)) return *no;
  if (family_ == Family::Undecided) {
    decide(Family::Velodyne, "Velodyne data packets (1206 bytes) on port " + std::to_string(options_.ports.data));
  }
  velodyne_.push(payload, host, done);
  return Outcome::Data;
}

Outcome Stream::push_msop(ByteSpan payload, Stamp host, std::vector<LidarFrame>& done) {
  if (const auto no = screen(payload, robosense::kPacketSize, Family::Velodyne)) return *no;
  MsopIdentity id = identify_msop(payload);
  // A configured RS-32 takes an unknown model byte (firmware that leaves it unset); a known other model never.
  const bool accept = id.rs32 || (options_.model == Model::RS32 && id.msop_header && id.name.empty());
  if (!accept) {
    ++own_.refused;
    refused_as_ = std::move(id);
    return Outcome::Refused;
  }
  if (family_ == Family::Undecided) {
    decide(Family::RoboSense, "RS-32 MSOP packets on port " + std::to_string(options_.ports.msop) +
                                  " (header 55 AA 05 0A "
                                  "5A A5 50 A0, " +
                                  id.detail + ")");
  }
  robosense_.push_msop(payload, host, done);
  return Outcome::Data;
}

void Stream::finish(std::vector<LidarFrame>& done) {
  if (family_ == Family::RoboSense) {
    robosense_.finish(done);
  } else {
    velodyne_.finish(done);
  }
}

void Stream::recycle(LidarFrame&& frame) {
  if (family_ == Family::RoboSense) {
    robosense_.recycle(std::move(frame));
  } else {
    velodyne_.recycle(std::move(frame));
  }
}

std::size_t Stream::trim_spares() { return velodyne_.trim_spares() + robosense_.trim_spares(); }

std::optional<Model> Stream::model() const {
  if (family_ == Family::RoboSense) return Model::RS32;
  if (family_ != Family::Velodyne) return std::nullopt;
  const auto m = velodyne_.model();
  if (!m) return std::nullopt;
  return *m == velodyne::Model::VLP16 ? Model::VLP16 : Model::HDL32E;
}

std::string Stream::reason() const {
  if (family_ == Family::Velodyne && options_.model == Model::Auto && !velodyne_.detector().reason().empty()) {
    return why_ + "; " + velodyne_.detector().reason();
  }
  return why_;
}

std::vector<double> Stream::ring_elevations_deg() const {
  std::vector<double> out;
  if (family_ == Family::RoboSense) {
    if (const auto& c = robosense_.decoder().calibration()) out.assign(c->vert_deg.begin(), c->vert_deg.end());
  } else if (const auto m = model()) {
    if (!options_.velodyne.calibration) return lidar3d::ring_elevations_deg(*m);  // the built-in table
    for (const velodyne::LaserCorrection& l : options_.velodyne.calibration->lasers) out.push_back(l.vert_deg);
  }
  std::sort(out.begin(), out.end());
  return out;
}

Counters Stream::counters() const {
  Counters c = own_;
  if (family_ == Family::RoboSense) {
    const robosense::StreamCounters& r = robosense_.counters();
    c.data_packets = r.msop_packets;
    c.decoded = r.msop_decoded;
    c.points = r.points;
    c.full_rotations = r.full_rotations;
    c.partial_rotations = r.partial_rotations;
  } else {
    const velodyne::StreamCounters& v = velodyne_.counters();
    c.data_packets = v.packets;
    c.decoded = v.decoded;
    c.points = v.points;
    c.full_rotations = v.full_rotations;
    c.partial_rotations = v.partial_rotations;
  }
  c.info_packets = robosense_.counters().difop_packets;
  return c;
}

}  // namespace fieldguard::lidar3d
