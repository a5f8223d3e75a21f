#pragma once
// A small RGB image and a PNG writer on zlib (no image library in a headless daemon).

#include <cstdint>
#include <string>
#include <vector>

namespace fieldguard::app {

struct Rgb {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
};

class Image {
 public:
  Image(int width, int height, Rgb fill);
  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  // Out-of-image pixels are ignored, so callers can draw shapes that leave the picture.
  void set(int x, int y, Rgb c);
  [[nodiscard]] Rgb get(int x, int y) const;
  void line(int x0, int y0, int x1, int y1, Rgb c);
  // 5x7 pixel glyphs for digits, '.', '-', 'm' and a few letters; others are drawn as a blank.
  void text(int x, int y, const std::string& s, Rgb c);
  [[nodiscard]] const std::vector<std::uint8_t>& rgb() const { return pixels_; }

 private:
  int width_;
  int height_;
  std::vector<std::uint8_t> pixels_;  // row-major RGB
};

// The PNG file's bytes; empty when zlib fails.
[[nodiscard]] std::vector<std::uint8_t> encode_png(const Image& image);
// Returns "" on success, else what went wrong.
[[nodiscard]] std::string write_png(const std::string& path, const Image& image);

}  // namespace fieldguard::app
