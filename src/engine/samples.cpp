#include "fieldguard/engine/samples.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <variant>
#include <vector>

#include "fieldguard/drivers/nmea_stream.hpp"
#include "fieldguard/drivers/scip_session.hpp"
#include "fieldguard/drivers/velodyne_position.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"
#include "fieldguard/drivers/xsens_stream.hpp"

namespace fieldguard::app {
namespace {

// FNV-1a over bytes: a digest of a frame's or a scan's contents, to compare them without printing them.
struct Digest {
  std::uint64_t h = 1469598103934665603ULL;
  void add(const void* p, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ULL;
  }
  [[nodiscard]] std::string hex() const {
    char buf[20];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
  }
};

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}
std::string opt(const std::optional<double>& v) { return v ? num(*v) : "null"; }

}  // namespace

scip::ClientConfig scip_client_config(const Scan2dConfig& c) {
  scip::ClientConfig cc;
  cc.scan.first_step = static_cast<std::uint16_t>(c.start_step);
  cc.scan.last_step = static_cast<std::uint16_t>(c.end_step);
  cc.intensity = c.intensity;
  return cc;
}

lidar3d::StreamOptions lidar3d_stream_options(const LidarConfig& c) {
  lidar3d::StreamOptions o;
  o.model = c.model;
  o.ports = {c.data_port, c.msop_port, c.difop_port};
  velodyne::StreamOptions& v = o.velodyne;
  if (c.has_calibration) v.calibration = c.calibration;
  v.timestamp_reference = c.timestamp_reference;
  v.min_range_m = c.min_range_m;
  v.max_range_m = c.max_range_m;
  v.rotation_cut_deg = c.rotation_cut_deg;
  robosense::StreamOptions& r = o.robosense;
  r.decoder.calibration = c.rs32_calibration;
  r.decoder.nominal_until_difop = true;
  r.decoder.min_range_m = std::max(c.min_range_m, robosense::DecoderOptions{}.min_range_m);
  r.decoder.max_range_m = c.max_range_m;
  r.rotation_cut_deg = c.rotation_cut_deg;
  return o;
}

struct SampleDecoder::Impl {
  Impl(const Config& c, std::ostream* o)
      : config(c), out(o), stream(lidar3d_stream_options(c.lidar)), session(scip_client_config(c.scan2d)) {}

  Config config;
  std::ostream* out;
  lidar3d::Stream stream;
  scip::Session session;
  nmea::StreamParser nmea_parser;
  xsens::StreamParser xsens_parser;
  std::vector<LidarFrame> frames;
  std::vector<nmea::Sentence> sentences;
  std::vector<xsens::StreamItem> items;
  SampleCounts counts;

  void line(const std::string& s) const {
    if (out != nullptr) *out << s << '\n';
  }

  void emit_frames() {
    for (auto& f : frames) {
      Digest d;
      for (const auto& p : f.points) d.add(&p, sizeof p);
      ++counts.lidar_frames;
      line("{\"sensor\":\"lidar\",\"frame\":" + std::to_string(f.index) +
           ",\"stamp_ns\":" + std::to_string(f.host_stamp.ns) + ",\"partial\":" + (f.partial ? "true" : "false") +
           ",\"points\":" + std::to_string(f.points.size()) + ",\"digest\":\"" + d.hex() + "\"}");
      stream.recycle(std::move(f));
    }
    frames.clear();
  }

  void emit_sentences() {
    for (const auto& s : sentences) {
      ++counts.gnss;
      std::string l = "{\"sensor\":\"gnss\"";
      if (const auto* g = std::get_if<nmea::Gga>(&s)) {
        l += ",\"type\":\"" + g->talker + "GGA\",\"time\":" + opt(g->utc_seconds_of_day) +
             ",\"lat_deg\":" + opt(g->lat_deg) + ",\"lon_deg\":" + opt(g->lon_deg) + ",\"alt_m\":" + opt(g->alt_m) +
             ",\"quality\":" + (g->quality ? std::to_string(*g->quality) : "null");
      } else if (const auto* r = std::get_if<nmea::Rmc>(&s)) {
        l += ",\"type\":\"" + r->talker + "RMC\",\"time\":" + opt(r->utc_seconds_of_day) +
             ",\"valid\":" + (r->valid ? "true" : "false") + ",\"lat_deg\":" + opt(r->lat_deg) +
             ",\"lon_deg\":" + opt(r->lon_deg) + ",\"speed_mps\":" + opt(r->speed_mps);
      } else {
        l += ",\"type\":\"other\",\"index\":" + std::to_string(s.index());
      }
      line(l + "}");
    }
    sentences.clear();
  }

  void emit_items() {
    for (const auto& it : items) {
      const auto* m = std::get_if<xsens::MtData2>(&it);
      if (m == nullptr) continue;
      ++counts.ahrs;
      std::string l =
          "{\"sensor\":\"ahrs\",\"packet_counter\":" +
          (m->packet_counter ? std::to_string(*m->packet_counter) : std::string("null")) +
          ",\"sample_time_fine\":" + (m->sample_time_fine ? std::to_string(*m->sample_time_fine) : std::string("null"));
      if (m->euler_deg) {
        l += ",\"euler_deg\":[" + num(m->euler_deg->x) + "," + num(m->euler_deg->y) + "," + num(m->euler_deg->z) + "]";
      }
      line(l + "}");
    }
    items.clear();
  }
};

SampleDecoder::SampleDecoder(const Config& config, std::ostream* out) : impl_(std::make_unique<Impl>(config, out)) {}
SampleDecoder::~SampleDecoder() = default;

void SampleDecoder::lidar(const io::UdpDatagram& d) {
  if (d.dst_port == impl_->config.lidar.position_port) {
    auto p = velodyne::decode_position_packet(d.payload);
    if (!p) return;
    ++impl_->counts.lidar_positions;
    impl_->line("{\"sensor\":\"lidar_position\",\"timestamp_us\":" + std::to_string(p->timestamp_us) + ",\"pps\":\"" +
                std::string(velodyne::to_string(p->pps)) + "\",\"rmc\":" + (p->rmc ? "true" : "false") + "}");
  } else if (const auto channel = impl_->stream.channel_of(d.dst_port)) {
    if (impl_->stream.push(*channel, d.payload, d.host_time, impl_->frames) == lidar3d::Outcome::Data) {
      impl_->emit_frames();
    }
  }
}

void SampleDecoder::scan2d(ByteSpan bytes, bool to_sensor) {
  if (to_sensor) {
    // The client opens every connection with SCIP2.0: that is where the live session was reset.
    static constexpr char kFirst[] = "SCIP2.0";
    if (bytes.size() >= 7 && std::memcmp(bytes.data(), kFirst, 7) == 0) (void)impl_->session.connect();
    return;
  }
  const scip::SessionEvents ev = impl_->session.on_bytes(bytes);
  for (const auto& s : ev.scans) {
    Digest d;
    d.add(s.ranges_mm.data(), s.ranges_mm.size() * sizeof(s.ranges_mm[0]));
    d.add(s.intensities.data(), s.intensities.size() * sizeof(s.intensities[0]));
    ++impl_->counts.scans;
    impl_->line("{\"sensor\":\"scan2d\",\"timestamp_ms\":" + std::to_string(s.timestamp_ms) +
                ",\"first_step\":" + std::to_string(s.first_step) +
                ",\"values\":" + std::to_string(s.ranges_mm.size()) + ",\"digest\":\"" + d.hex() + "\"}");
  }
}

void SampleDecoder::gnss(ByteSpan bytes) {
  impl_->nmea_parser.push(bytes, impl_->sentences);
  impl_->emit_sentences();
}

void SampleDecoder::ahrs(ByteSpan bytes) {
  impl_->xsens_parser.push(bytes, impl_->items);
  impl_->emit_items();
}

void SampleDecoder::finish() {
  impl_->stream.finish(impl_->frames);
  impl_->emit_frames();
  impl_->nmea_parser.finish(impl_->sentences);
  impl_->emit_sentences();
  impl_->xsens_parser.finish(impl_->items);
  impl_->emit_items();
}

const SampleCounts& SampleDecoder::counts() const { return impl_->counts; }

}  // namespace fieldguard::app
