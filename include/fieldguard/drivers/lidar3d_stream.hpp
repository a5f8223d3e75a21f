#pragma once
// The 3D LiDAR, whichever is attached: Velodyne HDL-32E or VLP-16 (data packets, port 2368) or RoboSense
// RS-LiDAR-32 (MSOP, port 6699, and DIFOP, port 7788). Datagrams in by destination port, rotations out, every
// datagram counted by outcome. With Model::Auto the first datagram that names a sensor decides which one it is
// (reason()); datagrams of the other family after that are counted and dropped. Packets of RoboSense models other
// than the RS-32 (other MSOP headers, other model bytes) are refused and named, never decoded as RS-32 ones.
// Pure and push-style (no I/O); one producer: not thread-safe.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/drivers/robosense_stream.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"

namespace fieldguard::lidar3d {

enum class Model : std::uint8_t { Auto = 0, HDL32E, VLP16, RS32 };
[[nodiscard]] std::string_view to_string(Model m);  // "auto", "HDL-32E", "VLP-16", "RS-32"

enum class Family : std::uint8_t { Undecided = 0, Velodyne, RoboSense };

// Whether a receiver configured for `m` listens on `f`'s ports: its own family's, both while auto finds it out.
[[nodiscard]] constexpr bool listens_for(Model m, Family f) {
  if (m == Model::Auto) return true;
  return (m == Model::RS32) == (f == Family::RoboSense);
}

struct Ports {
  std::uint16_t data = velodyne::kDefaultDataPort;  // Velodyne data packets
  std::uint16_t msop = robosense::kDefaultMsopPort;
  std::uint16_t difop = robosense::kDefaultDifopPort;
};

struct StreamOptions {
  Model model = Model::Auto;
  Ports ports;
  velodyne::StreamOptions velodyne;  // its model is taken from `model`
  robosense::StreamOptions robosense;
};

// A model's nominal ring elevations (degrees, lowest first): the built-in tables (an RS-32's: its nominal one,
// until a DIFOP brings the unit's own). Empty for Auto.
[[nodiscard]] std::vector<double> ring_elevations_deg(Model m);

// The kind of datagram a port carries. Live, each receiver knows its own; a capture tells it by the destination
// port (Stream::channel_of()).
enum class Channel : std::uint8_t { VelodyneData = 0, Msop, Difop };

// What a datagram to one of the LiDAR's ports was, once its sensor is known. A RoboSense MSOP header that is not
// an RS-32's names what it is (RoboSense::which_msop()).
enum class Outcome : std::uint8_t {
  Data,         // a data packet (Velodyne data, RS-32 MSOP) handed to its decoder (which may still reject it)
  Info,         // an RS-32 DIFOP handed to its decoder
  OtherFamily,  // a packet of the family not in use (auto decided for the other, or the model says otherwise)
  Refused,      // an MSOP of another RoboSense model, or an MSOP header no RoboSense model has
  BadLength,    // to a LiDAR port but not the length of a packet sent there
  NotLidar,     // to none of the LiDAR's ports
};

// Which RoboSense sensor an MSOP header names: "RS-32" for the RS-LiDAR-32 (header 55 AA 05 0A 5A A5 50 A0 and
// model byte 0x02 at offset 30), the name of another model it is known to be, or nullopt when it is no RoboSense
// MSOP header or its model byte is unknown (`detail` says which). The model bytes: snark's robosense driver
// (0x01 RS-LiDAR-16, 0x02 RS-LiDAR-32, 0x03 RS-Bpearl, 0x04 RS-Ruby, 0x05 RS-Ruby Lite, 0x06 RS-Helios); the
// Helios family's 4-byte header 55 AA 05 5A: rs_driver (protocols.md §2.5).
struct MsopIdentity {
  bool rs32 = false;
  bool msop_header = false;  // the 8-byte header of the RS-LiDAR-16/32 family (whatever the model byte)
  std::string name;          // "RS-LiDAR-32", "RS-LiDAR-16", "RS-Helios", ... or "" when unknown
  std::string detail;        // "model byte 0x02", "header 55 AA 05 5A", ...
};
[[nodiscard]] MsopIdentity identify_msop(ByteSpan payload);

struct Counters {
  std::uint64_t data_packets = 0;  // data packets handed to the decoder in use
  std::uint64_t decoded = 0;       // of those, decoded
  std::uint64_t info_packets = 0;  // RS-32 DIFOP handed to the decoder
  std::uint64_t other_family = 0;
  std::uint64_t refused = 0;
  std::uint64_t bad_length = 0;
  std::uint64_t points = 0;
  std::uint64_t full_rotations = 0;
  std::uint64_t partial_rotations = 0;
  [[nodiscard]] std::uint64_t rejected() const { return data_packets - decoded; }
  [[nodiscard]] std::uint64_t rotations() const { return full_rotations + partial_rotations; }
};

class Stream {
 public:
  // Throws std::invalid_argument for an impossible configuration (the decoders' checks).
  explicit Stream(StreamOptions options);

  // The channel of a destination port by the configured ports; nullopt for any other port.
  [[nodiscard]] std::optional<Channel> channel_of(std::uint16_t port) const;
  Outcome push(Channel channel, ByteSpan payload, Stamp host, std::vector<LidarFrame>& done);
  void finish(std::vector<LidarFrame>& done);
  void recycle(LidarFrame&& frame);
  std::size_t trim_spares();

  [[nodiscard]] Family family() const { return family_; }
  // The sensor the packets are decoded as: configured or detected; nullopt while undecided.
  [[nodiscard]] std::optional<Model> model() const;
  // Why: "configured", or what the datagrams showed ("MSOP on port 6699, model byte 0x02").
  [[nodiscard]] std::string reason() const;
  // The last refused MSOP's identity (what to tell the user), when there was one.
  [[nodiscard]] const std::optional<MsopIdentity>& refused_as() const { return refused_as_; }
  // Elevation of each ring (degrees, up positive), lowest first, from the decoder's table (built-in, calibration
  // file or DIFOP): empty while the sensor is undecided.
  [[nodiscard]] std::vector<double> ring_elevations_deg() const;
  [[nodiscard]] Counters counters() const;

  [[nodiscard]] const velodyne::Stream& velodyne() const { return velodyne_; }
  [[nodiscard]] const robosense::Stream& robosense() const { return robosense_; }

 private:
  // BadLength when the payload is not `packet_size` long, OtherFamily when the sensor in use is `other` (each
  // counted); nullopt when the packet goes on.
  std::optional<Outcome> screen(ByteSpan payload, std::size_t packet_size, Family other);
  Outcome push_velodyne(ByteSpan payload, Stamp host, std::vector<LidarFrame>& done);
  Outcome push_msop(ByteSpan payload, Stamp host, std::vector<LidarFrame>& done);
  void decide(Family f, std::string why);

  StreamOptions options_;
  Family family_ = Family::Undecided;
  std::string why_;
  std::optional<MsopIdentity> refused_as_;
  velodyne::Stream velodyne_;
  robosense::Stream robosense_;
  Counters own_;  // what this class counts itself (other_family, refused, bad_length)
};

}  // namespace fieldguard::lidar3d
