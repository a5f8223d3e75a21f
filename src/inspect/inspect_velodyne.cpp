// `fieldguard inspect --format velodyne`: a pcap/pcapng of an HDL-32E or VLP-16. One record per data packet
// (with the returns the detected model decodes from it) and per position packet.
//
// The model is detected from the stream (velodyne::Stream, which holds the first packets until its
// ModelDetector decides): data records wait with it, so that each carries its points, and the records are printed
// in the order of the file.

#include <array>
#include <cstdio>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/drivers/velodyne_position.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"
#include "inspect/inspect_format.hpp"
#include "inspect/json_line.hpp"

namespace fieldguard::app::inspect {
namespace {

namespace vd = velodyne;

struct DataPacket {
  double time_s = 0.0;
  std::uint16_t port = 0;
  vd::PacketHeader header;
};

std::string data_record(const DataPacket& p, std::size_t points) {
  JsonLine j;
  j.field("type", "velodyne_data").field("time", p.time_s).field("port", p.port);
  j.field("timestamp_us", p.header.timestamp_us).field("return_mode", vd::to_string(p.header.return_mode));
  j.field("product_byte", p.header.product_byte);
  j.field("first_azimuth_deg", p.header.first_azimuth_cdeg / 100.0);
  j.field("last_azimuth_deg", p.header.last_azimuth_cdeg / 100.0);
  j.field("points", points);
  return std::move(j).str();
}

std::string position_record(double time_s, std::uint16_t port, const vd::PositionPacket& p) {
  JsonLine j;
  j.field("type", "velodyne_position").field("time", time_s).field("port", port);
  j.field("timestamp_us", p.timestamp_us).field("pps", vd::to_string(p.pps));
  if (p.nmea.empty()) {
    j.null("nmea");
  } else {
    j.field("nmea", p.nmea);
  }
  if (p.nmea_error) {
    j.field("nmea_error", nmea::to_string(*p.nmea_error));
  } else {
    j.null("nmea_error");
  }
  if (p.rmc) {
    j.field("lat_deg", p.rmc->lat_deg).field("lon_deg", p.rmc->lon_deg);
  } else {
    j.null("lat_deg").null("lon_deg");
  }
  return std::move(j).str();
}

// Records in file order, data records held until the stream knows the model.
class Printer {
 public:
  Printer(Output& out, Summary& summary) : out_(out), summary_(summary) {}

  // A data packet the stream accepted for decoding (or holds while it detects the model).
  void data(const DataPacket& p, ByteSpan payload) {
    if (decoder_ && pending_.empty()) {
      emit(p, payload);
    } else {
      pending_.push_back({p, std::vector<std::uint8_t>(payload.begin(), payload.end()), {}});
    }
  }
  void position(std::string record) {
    if (pending_.empty()) {
      print(std::move(record), "velodyne_position");
    } else {
      pending_.push_back({{}, {}, std::move(record)});
    }
  }
  // The stream gave up on its `n` oldest held packets (no model): they yield no record.
  void drop_oldest_data(std::uint64_t n) {
    for (auto it = pending_.begin(); n > 0 && it != pending_.end();) {
      if (it->record.empty()) {
        it = pending_.erase(it);
        --n;
      } else {
        ++it;
      }
    }
    flush_positions();
  }
  // The stream knows the model: decode and print what was held.
  void model_known(vd::Model m) {
    if (decoder_) return;
    vd::StreamOptions defaults;  // the stream's own decoder options
    vd::DecoderOptions d;
    d.model = m;
    d.timestamp_reference = defaults.timestamp_reference;
    d.min_range_m = defaults.min_range_m;
    d.max_range_m = defaults.max_range_m;
    decoder_.emplace(vd::default_calibration(m), d);
    for (auto& h : pending_) {
      if (h.record.empty()) {
        emit(h.packet, h.payload);
      } else {
        print(std::move(h.record), "velodyne_position");
      }
    }
    pending_.clear();
  }
  // The end: data packets still held never got a model (the stream counted them as no_model).
  void finish() { drop_oldest_data(pending_.size()); }

 private:
  struct Held {
    DataPacket packet;
    std::vector<std::uint8_t> payload;
    std::string record;  // a position record; empty for a data packet
  };

  void emit(const DataPacket& p, ByteSpan payload) {
    points_.clear();
    if (!decoder_->decode(payload, points_)) return;  // the stream counted the same error
    print(data_record(p, points_.size()), "velodyne_data");
  }
  void print(std::string record, const char* kind) {
    ++summary_.kinds[kind];
    out_.line(std::move(record));
  }
  void flush_positions() {
    while (!pending_.empty() && !pending_.front().record.empty()) {
      print(std::move(pending_.front().record), "velodyne_position");
      pending_.pop_front();
    }
  }

  Output& out_;
  Summary& summary_;
  std::optional<vd::Decoder> decoder_;
  std::deque<Held> pending_;
  std::vector<LidarPoint> points_;
};

std::string model_note(const vd::Stream& stream, std::optional<std::uint8_t> product_byte) {
  const auto& why = stream.detector().reason();
  const auto model = stream.model();
  if (model && stream.detector().decided()) return std::string(vd::to_string(*model)) + " (" + why + ")";
  std::array<char, 8> byte{};
  if (product_byte) std::snprintf(byte.data(), byte.size(), "0x%02X", unsigned{*product_byte});
  if (model) {
    return std::string(vd::to_string(*model)) + " (from the product byte " + byte.data() + " alone; " +
           (why.empty() ? std::string("too few packets to measure the packet spacing") : why) + ")";
  }
  if (!product_byte) return "undecided (no valid data packet)";
  return "undecided (" +
         (why.empty() ? "product byte " + std::string(byte.data()) + " names no supported model" : why) + ")";
}

}  // namespace

void inspect_velodyne(Capture& in, Output& out, Summary& summary) {
  auto reader = open_pcap(in, summary);
  if (!reader) return;
  const std::uint16_t data_port = in.ports.data.value_or(vd::kDefaultDataPort);
  const std::uint16_t position_port = in.ports.position.value_or(vd::kDefaultPositionPort);

  vd::Stream stream(vd::StreamOptions{});
  Printer printer(out, summary);
  summary.kinds["velodyne_data"] = 0;
  summary.kinds["velodyne_position"] = 0;
  std::vector<LidarFrame> frames;
  std::uint64_t other_port = 0;
  std::uint64_t position_bad_length = 0;
  std::optional<std::uint8_t> product_byte;
  const auto no_model = [&] { return stream.counters().errors[static_cast<std::size_t>(vd::DecodeError::NoModel)]; };
  const auto recycle = [&] {
    for (auto& f : frames) stream.recycle(std::move(f));
    frames.clear();
  };

  while (const auto d = reader->next()) {
    if (d->dst_port == data_port) {
      const auto header = vd::read_packet_header(d->payload);
      const std::uint64_t dropped_before = no_model();
      stream.push(d->payload, d->host_time, frames);
      recycle();
      if (!header) continue;  // counted by the stream
      product_byte = header->product_byte;
      printer.data({seconds_of(d->host_time), d->dst_port, *header}, d->payload);
      printer.drop_oldest_data(no_model() - dropped_before);
      if (const auto m = stream.model()) printer.model_known(*m);
    } else if (d->dst_port == position_port) {
      const auto p = vd::decode_position_packet(d->payload);
      if (!p) {
        ++position_bad_length;  // the only error a position packet has
        continue;
      }
      printer.position(position_record(seconds_of(d->host_time), d->dst_port, *p));
    } else {
      ++other_port;
    }
  }
  stream.finish(frames);
  recycle();
  if (const auto m = stream.model()) printer.model_known(*m);
  printer.finish();

  const auto& c = stream.counters();
  summary.rejections = pcap_drops(reader->stats());
  summary.rejections.emplace_back("other_port", other_port);
  for (std::size_t i = 0; i < vd::kDecodeErrorCount; ++i) {
    summary.rejections.emplace_back(std::string(vd::to_string(static_cast<vd::DecodeError>(i))), c.errors[i]);
  }
  summary.rejections.emplace_back("position_bad_length", position_bad_length);
  add_pcap_stats(reader->stats(), summary);
  summary.extra.emplace_back("data_packets", c.packets);
  summary.extra.emplace_back("points", c.points);
  summary.extra.emplace_back("rotations_full", c.full_rotations);
  summary.extra.emplace_back("rotations_partial", c.partial_rotations);
  summary.notes.emplace_back("model", model_note(stream, product_byte));
  summary.notes.emplace_back("ports",
                             "data " + std::to_string(data_port) + ", position " + std::to_string(position_port));
}

}  // namespace fieldguard::app::inspect
