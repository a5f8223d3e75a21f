#include "fieldguard/drivers/velodyne_stream.hpp"

#include <numeric>
#include <stdexcept>

namespace fieldguard::velodyne {

std::uint64_t StreamCounters::rejected() const {
  return std::accumulate(errors.begin(), errors.end(), std::uint64_t{0});
}

Stream::Stream(StreamOptions options) : options_(std::move(options)), assembler_(options_.rotation_cut_deg) {
  if (options_.calibration && options_.model == Model::Unknown) options_.model = options_.calibration->model;
  if (options_.calibration && options_.calibration->model != options_.model) {
    throw std::invalid_argument("the calibration is for a " + std::string(to_string(options_.calibration->model)) +
                                " but the model is " + std::string(to_string(options_.model)));
  }
  if (options_.model != Model::Unknown) start_decoder(options_.model);
}

std::optional<Model> Stream::model() const {
  if (decoder_) return decoder_->model();
  return std::nullopt;
}

void Stream::start_decoder(Model m) {
  DecoderOptions d;
  d.model = m;
  d.timestamp_reference = options_.timestamp_reference;
  d.min_range_m = options_.min_range_m;
  d.max_range_m = options_.max_range_m;
  decoder_.emplace(options_.calibration ? *options_.calibration : default_calibration(m), d);
}

void Stream::count_frames(const std::vector<LidarFrame>& done, std::size_t from) {
  for (std::size_t i = from; i < done.size(); ++i) {
    ++(done[i].partial ? counters_.partial_rotations : counters_.full_rotations);
  }
}

void Stream::decode_one(ByteSpan payload, const PacketHeader& header, Stamp host_time, std::vector<LidarFrame>& done) {
  if (const auto error = decoder_->accept(header)) {
    ++counters_.errors[static_cast<std::size_t>(*error)];
    return;
  }
  const Stamp sensor = sensor_time_from_hour_offset(header.timestamp_us, host_time);
  // The group azimuths, read once: their bounds for the assembler, the azimuths themselves for the decoder.
  const Decoder::PacketAzimuths azimuths = decoder_->azimuths(payload, header);
  // Decoded straight into the frame under construction: no copy of the points, no initialisation of their room.
  const std::span<LidarPoint> room = assembler_.append_room(Decoder::kMaxPointsPerPacket);
  const std::span<LidarPoint, Decoder::kMaxPointsPerPacket> fixed(room.data(), room.size());
  std::size_t count = 0;
  const std::size_t before = done.size();
  if (const auto offset_s = assembler_.in_frame_offset_s(azimuths.bounds(), sensor)) {
    // Nearly every packet: inside the frame under way, so the decoder writes the frame-relative times itself and
    // the assembler need not go over the points again.
    count = decoder_->decode_accepted(payload, header, azimuths, fixed, offset_s);
    assembler_.commit_in_frame(count, host_time, done);
  } else {
    count = decoder_->decode_accepted(payload, header, azimuths, fixed, std::nullopt);
    assembler_.commit(count, sensor, host_time, done, azimuths.bounds());
  }
  ++counters_.decoded;
  counters_.points += count;
  count_frames(done, before);
}

void Stream::decode_held(const Held& held, std::vector<LidarFrame>& done) {
  // Held packets passed read_packet_header() when they came in.
  if (const auto header = read_packet_header(held.bytes)) decode_one(held.bytes, *header, held.host, done);
}

void Stream::push(ByteSpan payload, Stamp host_time, std::vector<LidarFrame>& done) {
  ++counters_.packets;
  const auto header = read_packet_header(payload);
  if (!header) {
    ++counters_.errors[static_cast<std::size_t>(header.error())];
    return;
  }
  if (!detector_.decided()) detector_.observe(*header);

  if (!decoder_) {
    held_.push_back({std::vector<std::uint8_t>(payload.begin(), payload.end()), host_time});
    std::optional<Model> m = detector_.decided();
    if (!m && held_.size() >= options_.max_undecided_packets) {
      // The spacing never settled (gaps, a stream of one packet per hour...): fall back on the product byte.
      if (header->product_byte == 0x22 || header->product_byte == 0x24) m = Model::VLP16;
      if (header->product_byte == 0x21) m = Model::HDL32E;
    }
    if (!m) {
      if (held_.size() >= options_.max_undecided_packets) {
        ++counters_.errors[static_cast<std::size_t>(DecodeError::NoModel)];
        held_.erase(held_.begin());
      }
      return;
    }
    start_decoder(*m);
    auto held = std::move(held_);
    held_.clear();
    for (const auto& h : held) decode_held(h, done);
    return;
  }
  decode_one(payload, *header, host_time, done);
}

void Stream::finish(std::vector<LidarFrame>& done) {
  if (!decoder_ && !held_.empty()) {
    // Too few packets to measure the spacing: the product byte is all there is.
    const auto header = read_packet_header(held_.front().bytes);
    std::optional<Model> m;
    if (header && (header->product_byte == 0x22 || header->product_byte == 0x24)) m = Model::VLP16;
    if (header && header->product_byte == 0x21) m = Model::HDL32E;
    if (m) {
      start_decoder(*m);
      for (const auto& h : held_) decode_held(h, done);
    } else {
      counters_.errors[static_cast<std::size_t>(DecodeError::NoModel)] += held_.size();
    }
    held_.clear();
  }
  const std::size_t before = done.size();
  assembler_.finish(done);
  count_frames(done, before);
}

}  // namespace fieldguard::velodyne
