// SCIP 2.0 scans: MD/ME/MS/GD/GE/GS replies to ranges (and intensities), step angles, 2D points, the 24-bit clock.
#include <cmath>
#include <numbers>

#include "fieldguard/drivers/scip_data.hpp"

namespace fieldguard::scip {

namespace {

std::uint32_t digits(std::string_view s) {
  std::uint32_t v = 0;
  for (char c : s) v = v * 10 + static_cast<std::uint32_t>(c - '0');
  return v;
}

}  // namespace

std::size_t values_in_scan(std::uint16_t first_step, std::uint16_t last_step, std::uint8_t cluster) {
  if (last_step < first_step) return 0;
  const std::size_t steps = static_cast<std::size_t>(last_step - first_step) + 1;
  const std::size_t c = cluster == 0 ? 1 : cluster;
  return (steps + c - 1) / c;
}

Expected<Scan, Error> decode_scan(const Reply& reply) {
  const Command c = reply.command;
  const bool continuous = c == Command::MD || c == Command::ME || c == Command::MS;
  const bool single = c == Command::GD || c == Command::GE || c == Command::GS;
  if (!continuous && !single) return Unexpected{Error::NotThisReply};
  if (reply.status != (continuous ? "99" : "00") || (single && reply.lines.empty())) {
    return Unexpected{Error::NotThisReply};
  }
  // The parser only passes echoes of the command's exact form; a hand-made Reply may not be one.
  const std::string_view echo = reply.echo;
  if (command_of_echo(echo) != c) return Unexpected{Error::BadEcho};

  Scan s;
  s.command = c;
  s.status = reply.status;
  s.first_step = static_cast<std::uint16_t>(digits(echo.substr(2, 4)));
  s.last_step = static_cast<std::uint16_t>(digits(echo.substr(6, 4)));
  const auto cluster = static_cast<std::uint8_t>(digits(echo.substr(10, 2)));
  s.cluster = cluster == 0 ? std::uint8_t{1} : cluster;
  if (continuous) s.remaining_scans = static_cast<std::uint8_t>(digits(echo.substr(13, 2)));
  if (s.last_step < s.first_step) return Unexpected{Error::BadEcho};

  // Timestamp line, then data lines of 64 characters (the last one may be shorter).
  if (reply.lines.size() < 2 || reply.lines[0].size() != 4) return Unexpected{Error::BadDataLength};
  const auto ts = decode_chars(reply.lines[0]);
  if (!ts) return Unexpected{Error::BadCharacter};
  s.timestamp_ms = *ts;
  std::string data;
  data.reserve((reply.lines.size() - 1) * kDataCharsPerLine);
  for (std::size_t i = 1; i < reply.lines.size(); ++i) {
    const std::size_t n = reply.lines[i].size();
    const bool last = i + 1 == reply.lines.size();
    if (n > kDataCharsPerLine || (!last && n != kDataCharsPerLine)) return Unexpected{Error::BadDataLength};
    data += reply.lines[i];
  }

  const std::size_t width = (c == Command::MS || c == Command::GS) ? 2 : 3;
  const bool intensity = c == Command::ME || c == Command::GE;
  const std::size_t per_value = intensity ? 2 * width : width;
  if (data.size() % per_value != 0) return Unexpected{Error::BadDataLength};
  const std::size_t count = data.size() / per_value;
  // ceil((last - first + 1) / cluster) values; floor is accepted too, as the spec's rounding is not confirmed.
  const std::size_t steps = static_cast<std::size_t>(s.last_step - s.first_step) + 1;
  if (count != values_in_scan(s.first_step, s.last_step, s.cluster) && count != steps / s.cluster) {
    return Unexpected{Error::BadDataLength};
  }

  const std::string_view all = data;
  s.ranges_mm.reserve(count);
  if (intensity) s.intensities.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const auto r = decode_chars(all.substr(i * per_value, width));
    if (!r) return Unexpected{Error::BadCharacter};
    s.ranges_mm.push_back(*r);
    if (intensity) {
      const auto v = decode_chars(all.substr(i * per_value + width, width));
      if (!v) return Unexpected{Error::BadCharacter};
      s.intensities.push_back(*v);
    }
  }
  return s;
}

Geometry Geometry::from(const Parameters& p) {
  return Geometry{.dmin_mm = p.dmin_mm,
                  .dmax_mm = p.dmax_mm,
                  .front_step = static_cast<double>(p.afrt),
                  .steps_per_turn = static_cast<double>(p.ares)};
}

double step_angle_rad(double step, const Geometry& g) {
  return (step - g.front_step) * 2.0 * std::numbers::pi / g.steps_per_turn;
}

double step_angle_deg(double step, const Geometry& g) { return (step - g.front_step) * 360.0 / g.steps_per_turn; }

void scan_to_points(const Scan& scan, const Geometry& g, std::vector<Point2>& out) {
  for (std::size_t i = 0; i < scan.ranges_mm.size(); ++i) {
    const std::uint32_t r = scan.ranges_mm[i];
    if (r < g.dmin_mm || r > g.dmax_mm) continue;  // error codes, not distances
    const std::uint16_t step = scan.step_of(i);
    const double a = step_angle_rad(step, g);
    const double m = static_cast<double>(r) * 1e-3;
    Point2 p;
    p.x_m = static_cast<float>(m * std::cos(a));
    p.y_m = static_cast<float>(m * std::sin(a));
    p.range_m = static_cast<float>(m);
    p.angle_rad = static_cast<float>(a);
    p.step = step;
    p.intensity = i < scan.intensities.size() ? scan.intensities[i] : 0;
    out.push_back(p);
  }
}

std::uint64_t TimestampUnwrapper::unwrap(std::uint32_t raw_ms) {
  constexpr std::uint32_t kRange = 1U << 24;
  raw_ms &= kRange - 1;
  if (last_ && raw_ms<*last_&& * last_ - raw_ms> kRange / 2) ++wraps_;
  last_ = raw_ms;
  return wraps_ * kRange + raw_ms;
}

}  // namespace fieldguard::scip
