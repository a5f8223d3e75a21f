#include "fieldguard/writers/bev.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <utility>

namespace fieldguard::app {
namespace {

constexpr double kHeader = 64.0;   // px: the decision, the frame and its time
constexpr double kLegend = 230.0;  // px: the legend panel right of the map
const char* const kFont = "DejaVu Sans";

struct Rgbf {
  double r, g, b;
};
constexpr Rgbf kBackground{0.07, 0.07, 0.09};
constexpr Rgbf kGrid{0.14, 0.14, 0.17};
constexpr Rgbf kGrid10{0.28, 0.28, 0.32};
constexpr Rgbf kText{0.85, 0.85, 0.88};
constexpr Rgbf kGround{0.24, 0.24, 0.24};
constexpr Rgbf kSmall{1.00, 0.20, 0.20};
constexpr Rgbf kLarge{1.00, 0.59, 0.16};
constexpr Rgbf kHeld{0.24, 0.86, 1.00};
constexpr Rgbf kRoi{0.78, 0.78, 0.24};
constexpr Rgbf kBody{0.31, 0.47, 1.00};
constexpr Rgbf kStop{0.78, 0.16, 0.16};
constexpr Rgbf kGo{0.18, 0.55, 0.22};
constexpr Rgbf kUndecided{0.85, 0.24, 0.78};

void set(cairo_t* cr, Rgbf c, double a = 1.0) { cairo_set_source_rgba(cr, c.r, c.g, c.b, a); }

// Blue (low) -> cyan -> green -> yellow -> red (high), over z in [-1.5, 3] m of the sensor frame.
Rgbf height_colour(float z, double brightness) {
  const double t = std::clamp((static_cast<double>(z) + 1.5) / 4.5, 0.0, 1.0);
  const double r = std::clamp(4.0 * t - 2.0, 0.0, 1.0);
  const double g = std::clamp(t < 0.75 ? 4.0 * t : 4.0 - 4.0 * t, 0.0, 1.0);
  const double b = std::clamp(2.0 - 4.0 * t, 0.0, 1.0);
  auto k = [brightness](double c) { return 0.22 + 0.78 * c * brightness; };
  return {k(r), k(g), k(b)};
}

struct Map {
  const BevView& v;
  double width;
  double height;
  [[nodiscard]] double px(double y) const { return (v.y_half_m - y) * v.px_per_m; }
  [[nodiscard]] double py(double x) const { return kHeader + (v.x_max_m - x) * v.px_per_m; }
  [[nodiscard]] PixelRect rect() const { return {0.0, kHeader, width, kHeader + height}; }
};

void text_at(cairo_t* cr, double x, double y, const std::string& s, double size, bool bold = false) {
  cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL, bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, s.c_str());
}

double text_width(cairo_t* cr, const std::string& s, double size, bool bold = false) {
  cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL, bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  return e.x_advance;
}

void outline(cairo_t* cr, const Map& m, const perception::Box3& b) {
  cairo_rectangle(cr, m.px(b.max[1]), m.py(b.max[0]), (b.max[1] - b.min[1]) * m.v.px_per_m,
                  (b.max[0] - b.min[0]) * m.v.px_per_m);
}

void header(cairo_t* cr, double width, const BevCaption& c) {
  const output::safety::Decision* d = c.decision;
  set(cr, d == nullptr ? Rgbf{0.3, 0.3, 0.33} : d->stop ? kStop : kGo);
  cairo_rectangle(cr, 0, 0, width, kHeader);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 1, 1, 1);
  std::string word = "no decision";
  std::string reason;
  if (d != nullptr) {
    const std::string h = output::safety::headline(*d, c.clear_frames);
    word = d->stop ? "STOP" : "GO";
    reason = h.size() > word.size() ? h.substr(word.size() + 1) : std::string();
  }
  text_at(cr, 14, 42, word, 30, true);
  const double after = 14 + text_width(cr, word, 30, true) + 14;
  text_at(cr, after, 40, reason, 17);
  // The frame and its time (UTC), right-aligned.
  const std::time_t secs = static_cast<std::time_t>(c.stamp.ns / 1'000'000'000);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char when[64];
  std::snprintf(when, sizeof when, "%04d-%02d-%02d %02d:%02d:%02d.%03d UTC", tm.tm_year + 1900, tm.tm_mon + 1,
                tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(c.stamp.ns / 1'000'000 % 1000));
  const std::string frame = "frame " + std::to_string(c.frame) + (c.partial ? " (partial)" : "");
  text_at(cr, width - 12 - text_width(cr, frame, 14, true), 26, frame, 14, true);
  text_at(cr, width - 12 - text_width(cr, when, 13), 48, when, 13);
}

void grid(cairo_t* cr, const Map& m) {
  const BevView& v = m.v;
  cairo_set_line_width(cr, 1.0);
  for (int x = static_cast<int>(std::ceil(v.x_min_m)); x <= static_cast<int>(std::floor(v.x_max_m)); ++x) {
    set(cr, x % 10 == 0 ? kGrid10 : kGrid);
    cairo_move_to(cr, 0, m.py(x) + 0.5);
    cairo_line_to(cr, m.width, m.py(x) + 0.5);
    cairo_stroke(cr);
  }
  for (int y = -static_cast<int>(v.y_half_m); y <= static_cast<int>(v.y_half_m); ++y) {
    set(cr, y % 10 == 0 ? kGrid10 : kGrid);
    cairo_move_to(cr, m.px(y) + 0.5, kHeader);
    cairo_line_to(cr, m.px(y) + 0.5, kHeader + m.height);
    cairo_stroke(cr);
  }
  set(cr, kText, 0.7);
  for (int x = static_cast<int>(std::ceil(v.x_min_m / 10.0)) * 10; x <= static_cast<int>(v.x_max_m); x += 10) {
    text_at(cr, 3, m.py(x) - 3, std::to_string(x) + " m", 11);
  }
}

// Straight into the surface's pixels: tens of thousands of points, each one pixel (two for obstacles).
void points_on(cairo_surface_t* s, const Map& m, std::span<const perception::LabeledPoint> points) {
  cairo_surface_flush(s);
  unsigned char* data = cairo_image_surface_get_data(s);
  const int stride = cairo_image_surface_get_stride(s);
  const auto w = static_cast<int>(m.width);
  const int top = static_cast<int>(kHeader);
  const int bottom = static_cast<int>(kHeader + m.height);
  auto put = [&](int x, int y, Rgbf c) {
    if (x < 0 || x >= w || y < top || y >= bottom) return;
    const auto v = (static_cast<std::uint32_t>(std::lround(c.r * 255)) << 16U) |
                   (static_cast<std::uint32_t>(std::lround(c.g * 255)) << 8U) |
                   static_cast<std::uint32_t>(std::lround(c.b * 255));
    auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
    row[x] = v;
  };
  for (const auto& p : points) {
    const bool ground = p.label == perception::PointLabel::Ground;
    const bool obstacle = p.label == perception::PointLabel::Obstacle;
    const Rgbf c = ground ? kGround : height_colour(p.z, obstacle ? 1.0 : 0.55);
    const auto x = static_cast<int>(std::floor(m.px(static_cast<double>(p.y))));
    const auto y = static_cast<int>(std::floor(m.py(static_cast<double>(p.x))));
    put(x, y, c);
    if (obstacle) put(x + 1, y, c);
  }
  cairo_surface_mark_dirty(s);
}

Rgbf box_colour(const perception::Obstacle& o) {
  return o.held ? kHeld : o.size_class == perception::SizeClass::Small ? kSmall : kLarge;
}

// The oriented box's corners, in pixels.
std::array<std::array<double, 2>, 4> corners(const Map& m, const perception::Obstacle& o) {
  const double cy = std::cos(static_cast<double>(o.obb_yaw_rad));
  const double sy = std::sin(static_cast<double>(o.obb_yaw_rad));
  const double hl = static_cast<double>(o.obb_length_m) / 2.0;
  const double hw = static_cast<double>(o.obb_width_m) / 2.0;
  const double k[4][2] = {{hl, hw}, {-hl, hw}, {-hl, -hw}, {hl, -hw}};
  std::array<std::array<double, 2>, 4> out{};
  for (std::size_t i = 0; i < 4; ++i) {
    const double x = static_cast<double>(o.obb_center[0]) + k[i][0] * cy - k[i][1] * sy;
    const double y = static_cast<double>(o.obb_center[1]) + k[i][0] * sy + k[i][1] * cy;
    out[i] = {m.px(y), m.py(x)};
  }
  return out;
}

// A label's place: beside its box (right, left, above, below), then the same farther out, the first that covers no
// box, no label and stays on the map; the first candidate when none is free.
PixelRect place_label(const PixelRect& box, double w, double h, const std::vector<PixelRect>& boxes,
                      const std::vector<PixelRect>& labels, const PixelRect& map) {
  const double cy = 0.5 * (box.y0 + box.y1);
  const double cx = 0.5 * (box.x0 + box.x1);
  std::optional<PixelRect> first;
  for (int ring = 0; ring < 12; ++ring) {
    const double d = 3.0 + ring * (h + 2.0);
    const PixelRect candidates[] = {
        {box.x1 + 3.0 + ring * 8.0, cy - h / 2 - ring * 0.0, box.x1 + 3.0 + ring * 8.0 + w, cy + h / 2},
        {box.x0 - 3.0 - ring * 8.0 - w, cy - h / 2, box.x0 - 3.0 - ring * 8.0, cy + h / 2},
        {cx - w / 2, box.y0 - d - h, cx + w / 2, box.y0 - d},
        {cx - w / 2, box.y1 + d, cx + w / 2, box.y1 + d + h},
        {box.x1 + 3.0, box.y0 - d - h, box.x1 + 3.0 + w, box.y0 - d},
        {box.x1 + 3.0, box.y1 + d, box.x1 + 3.0 + w, box.y1 + d + h},
        {box.x0 - 3.0 - w, box.y0 - d - h, box.x0 - 3.0, box.y0 - d},
        {box.x0 - 3.0 - w, box.y1 + d, box.x0 - 3.0, box.y1 + d + h},
    };
    for (const PixelRect& c : candidates) {
      if (!first) first = c;
      if (c.x0 < map.x0 || c.x1 > map.x1 || c.y0 < map.y0 || c.y1 > map.y1) continue;
      const auto hits = [&c](const PixelRect& r) { return c.overlaps(r); };
      if (std::any_of(boxes.begin(), boxes.end(), hits) || std::any_of(labels.begin(), labels.end(), hits)) continue;
      return c;
    }
  }
  return *first;
}

void obstacles_on(cairo_t* cr, const Map& m, std::span<const perception::Obstacle> obstacles, Picture& pic) {
  pic.boxes.clear();
  for (const auto& o : obstacles) {
    const auto c = corners(m, o);
    PixelRect r{c[0][0], c[0][1], c[0][0], c[0][1]};
    for (const auto& p : c) {
      r.x0 = std::min(r.x0, p[0]);
      r.y0 = std::min(r.y0, p[1]);
      r.x1 = std::max(r.x1, p[0]);
      r.y1 = std::max(r.y1, p[1]);
    }
    // A box under a pixel still gets a visible square.
    r = {std::min(r.x0, r.x1 - 3), std::min(r.y0, r.y1 - 3), r.x1 + 1, r.y1 + 1};
    pic.boxes.push_back(r);
    cairo_move_to(cr, c[0][0], c[0][1]);
    for (std::size_t i = 1; i < 4; ++i) cairo_line_to(cr, c[i][0], c[i][1]);
    cairo_close_path(cr);
    set(cr, box_colour(o), 0.25);
    cairo_fill_preserve(cr);
    set(cr, box_colour(o));
    cairo_set_line_width(cr, 2.0);
    cairo_stroke(cr);
  }
  pic.labels.clear();
  pic.label_texts.clear();
  constexpr double kSize = 12.0;
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const auto& o = obstacles[i];
    char t[48];
    std::snprintf(t, sizeof t, "%.1f m%s", static_cast<double>(o.distance_m), o.held ? " held" : "");
    const double w = text_width(cr, t, kSize, true) + 6;
    const double h = kSize + 5;
    const PixelRect r = place_label(pic.boxes[i], w, h, pic.boxes, pic.labels, m.rect());
    cairo_rectangle(cr, r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0);
    cairo_set_source_rgba(cr, 0, 0, 0, 0.7);
    cairo_fill(cr);
    set(cr, box_colour(o));
    text_at(cr, r.x0 + 3, r.y1 - 4, t, kSize, true);
    pic.labels.push_back(r);
    pic.label_texts.emplace_back(t);
  }
}

void scale_bar(cairo_t* cr, const Map& m) {
  const double len = 5.0 * m.v.px_per_m;
  const double x0 = 12;
  const double y = kHeader + m.height - 14;
  cairo_set_source_rgba(cr, 0, 0, 0, 0.6);
  cairo_rectangle(cr, x0 - 6, y - 18, len + 44, 26);
  cairo_fill(cr);
  set(cr, kText);
  cairo_set_line_width(cr, 2.0);
  cairo_move_to(cr, x0, y - 5);
  cairo_line_to(cr, x0, y);
  cairo_line_to(cr, x0 + len, y);
  cairo_line_to(cr, x0 + len, y - 5);
  cairo_stroke(cr);
  text_at(cr, x0 + len + 6, y, "5 m", 12, true);
}

void legend(cairo_t* cr, double x, const BevCaption& c) {
  double y = kHeader + 26;
  set(cr, kText);
  text_at(cr, x, y, "Legend", 15, true);
  y += 22;
  const auto item = [&](Rgbf colour, bool filled, const std::string& what) {
    set(cr, colour, filled ? 0.35 : 1.0);
    cairo_rectangle(cr, x, y - 10, 18, 12);
    if (filled) {
      cairo_fill_preserve(cr);
      set(cr, colour);
    }
    cairo_set_line_width(cr, 2.0);
    cairo_stroke(cr);
    set(cr, kText);
    text_at(cr, x + 26, y, what, 12);
    y += 21;
  };
  item(kSmall, true, "obstacle, person-sized");
  item(kLarge, true, "obstacle, large");
  item(kHeld, true, "obstacle held (thin rotation)");
  const Rgbf zone = c.decision == nullptr ? kUndecided : c.decision->stop ? kStop : kGo;
  item(zone, false, c.decision == nullptr ? "stop zone" : c.decision->stop ? "stop zone (STOP)" : "stop zone (GO)");
  item(kRoi, false, "region of interest");
  item(kBody, false, "tractor body");
  y += 8;
  text_at(cr, x, y, "points by height above the LiDAR", 12);
  y += 8;
  for (int i = 0; i < 100; ++i) {
    const Rgbf col = height_colour(static_cast<float>(-1.5 + 4.5 * i / 99.0), 1.0);
    set(cr, col);
    cairo_rectangle(cr, x + i * 1.8, y, 1.9, 10);
    cairo_fill(cr);
  }
  y += 24;
  set(cr, kText);
  text_at(cr, x, y, "-1.5 m", 11);
  text_at(cr, x + 150, y, "+3 m", 11);
  y += 20;
  set(cr, kGround);
  cairo_rectangle(cr, x, y - 10, 18, 12);
  cairo_fill(cr);
  set(cr, kText);
  text_at(cr, x + 26, y, "ground", 12);
  y += 21;
  text_at(cr, x, y, "dim: clustered, not an obstacle", 12);
  y += 21;
  text_at(cr, x, y, "grid 1 m, bright every 10 m", 12);
  y += 21;
  text_at(cr, x, y, "x ahead (up), y left", 12);
}

}  // namespace

Picture::Picture(int width, int height) : surface_(cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height)) {}
Picture::~Picture() {
  if (surface_ != nullptr) cairo_surface_destroy(surface_);
}
Picture::Picture(Picture&& o) noexcept
    : boxes(std::move(o.boxes)),
      labels(std::move(o.labels)),
      label_texts(std::move(o.label_texts)),
      surface_(std::exchange(o.surface_, nullptr)) {}
Picture& Picture::operator=(Picture&& o) noexcept {
  if (this != &o) {
    if (surface_ != nullptr) cairo_surface_destroy(surface_);
    surface_ = std::exchange(o.surface_, nullptr);
    boxes = std::move(o.boxes);
    labels = std::move(o.labels);
    label_texts = std::move(o.label_texts);
  }
  return *this;
}

int Picture::width() const { return surface_ != nullptr ? cairo_image_surface_get_width(surface_) : 0; }
int Picture::height() const { return surface_ != nullptr ? cairo_image_surface_get_height(surface_) : 0; }

std::array<std::uint8_t, 3> Picture::pixel(int x, int y) const {
  if (surface_ == nullptr || x < 0 || y < 0 || x >= width() || y >= height()) return {0, 0, 0};
  cairo_surface_flush(surface_);
  const unsigned char* data = cairo_image_surface_get_data(surface_);
  const auto v = *reinterpret_cast<const std::uint32_t*>(
      data + static_cast<std::ptrdiff_t>(y) * cairo_image_surface_get_stride(surface_) + x * 4);
  return {static_cast<std::uint8_t>(v >> 16U), static_cast<std::uint8_t>(v >> 8U), static_cast<std::uint8_t>(v)};
}

std::string Picture::write_png(const std::string& path) const {
  const cairo_status_t s = cairo_surface_write_to_png(surface_, path.c_str());
  return s == CAIRO_STATUS_SUCCESS ? std::string() : "cannot write " + path + ": " + cairo_status_to_string(s);
}

std::vector<std::uint8_t> Picture::png() const {
  std::vector<std::uint8_t> out;
  const auto append = [](void* closure, const unsigned char* data, unsigned int length) {
    auto* v = static_cast<std::vector<std::uint8_t>*>(closure);
    v->insert(v->end(), data, data + length);
    return CAIRO_STATUS_SUCCESS;
  };
  if (cairo_surface_write_to_png_stream(surface_, append, &out) != CAIRO_STATUS_SUCCESS) out.clear();
  return out;
}

perception::Box3 stop_zone_box(const output::safety::Zone& z) {
  return {{z.x_min_m, -z.half_width_m, -10.0}, {z.x_max_m, z.half_width_m, 10.0}};
}

Picture render_bev(std::span<const perception::LabeledPoint> points, std::span<const perception::Obstacle> obstacles,
                   const perception::PipelineParams& params, const std::optional<perception::Box3>& stop_zone,
                   const BevCaption& caption, const BevView& view) {
  const Map m{view, 2.0 * view.y_half_m * view.px_per_m, (view.x_max_m - view.x_min_m) * view.px_per_m};
  const auto width = static_cast<int>(std::ceil(m.width + kLegend));
  const auto height = static_cast<int>(std::ceil(kHeader + m.height));
  Picture pic(width, height);
  cairo_t* cr = cairo_create(pic.surface());
  set(cr, kBackground);
  cairo_paint(cr);
  header(cr, width, caption);

  cairo_save(cr);
  cairo_rectangle(cr, 0, kHeader, m.width, m.height);
  cairo_clip(cr);
  grid(cr, m);
  cairo_surface_flush(pic.surface());
  points_on(pic.surface(), m, points);
  cairo_set_line_width(cr, 1.5);
  const double dashes[] = {6.0, 4.0};
  cairo_set_dash(cr, dashes, 2, 0);
  set(cr, kRoi);
  outline(cr, m, params.roi);
  cairo_stroke(cr);
  cairo_set_dash(cr, nullptr, 0, 0);
  set(cr, kBody);
  outline(cr, m, params.body);
  cairo_stroke(cr);
  if (stop_zone) {
    set(cr, caption.decision == nullptr ? kUndecided : caption.decision->stop ? kStop : kGo);
    cairo_set_line_width(cr, 2.5);
    outline(cr, m, *stop_zone);
    cairo_stroke(cr);
  }
  obstacles_on(cr, m, obstacles, pic);
  scale_bar(cr, m);
  cairo_restore(cr);

  // The map's edge and the legend beside it.
  set(cr, kGrid10);
  cairo_set_line_width(cr, 1.0);
  cairo_move_to(cr, m.width + 0.5, kHeader);
  cairo_line_to(cr, m.width + 0.5, height);
  cairo_stroke(cr);
  legend(cr, m.width + 14, caption);
  cairo_destroy(cr);
  cairo_surface_flush(pic.surface());
  return pic;
}

}  // namespace fieldguard::app
