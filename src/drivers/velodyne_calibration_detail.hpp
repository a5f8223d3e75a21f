#pragma once
// Private helpers shared by the calibration parsers (velodyne_calibration_ros.cpp, velodyne_calibration_db.cpp).

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/drivers/velodyne_calibration.hpp"

namespace fieldguard::velodyne::detail {

// Collects every problem found in a calibration file; message() lists the first few in one line.
class Issues {
 public:
  void add(std::string what) { items_.push_back(std::move(what)); }
  [[nodiscard]] bool empty() const { return items_.empty(); }
  [[nodiscard]] std::string message() const;

 private:
  std::vector<std::string> items_;
};

// A decimal number in a text field (surrounding blanks allowed, '+' allowed, exponent allowed).
// nullopt for anything else, including inf and nan.
[[nodiscard]] std::optional<double> parse_number(std::string_view text);
// A non-negative integer that fits in an int.
[[nodiscard]] std::optional<int> parse_index(std::string_view text);

// "HDL-32E" for 32, "VLP-16" for 16, nullopt otherwise.
[[nodiscard]] std::optional<Model> model_for_laser_count(std::size_t n);
// "only 32 (HDL-32E) and 16 (VLP-16) lasers are supported"
[[nodiscard]] std::string supported_counts();
// "32 lasers expected for HDL-32E, found 31"
[[nodiscard]] std::string count_mismatch(Model model, std::size_t found);

// Quotes a value for an error message, shortened if long.
[[nodiscard]] std::string quoted(std::string_view text);

// The per-laser table from a file: slots of lasers that were present, indexed by laser id.
struct LaserTable {
  std::vector<std::optional<LaserCorrection>> by_id;
  explicit LaserTable(std::size_t n) : by_id(n) {}
};

// Checks that every id 0..n-1 was filled and builds the calibration (model, resolution, rings).
// Adds to issues and returns an empty calibration if something is missing.
[[nodiscard]] Calibration finish(Model model, double distance_resolution_m, const LaserTable& table, Issues& issues);

}  // namespace fieldguard::velodyne::detail
