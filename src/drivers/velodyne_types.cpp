#include "fieldguard/drivers/velodyne_types.hpp"

namespace fieldguard::velodyne {

std::string_view to_string(Model m) {
  switch (m) {
    case Model::HDL32E: return "HDL-32E";
    case Model::VLP16: return "VLP-16";
    case Model::Unknown: break;
  }
  return "unknown";
}

std::string_view to_string(ReturnMode m) {
  switch (m) {
    case ReturnMode::Strongest: return "strongest";
    case ReturnMode::Last: return "last";
    case ReturnMode::Dual: return "dual";
  }
  return "unknown";
}

std::optional<Model> model_from_string(std::string_view s) {
  if (s == "HDL-32E") return Model::HDL32E;
  if (s == "VLP-16") return Model::VLP16;
  if (s == "auto") return Model::Unknown;
  return std::nullopt;
}

std::string_view to_string(DecodeError e) {
  switch (e) {
    case DecodeError::BadLength: return "bad_length";
    case DecodeError::BadBlockFlag: return "bad_block_flag";
    case DecodeError::BadAzimuth: return "bad_azimuth";
    case DecodeError::BadReturnMode: return "bad_return_mode";
    case DecodeError::ModelMismatch: return "model_mismatch";
    case DecodeError::NoModel: return "no_model";
  }
  return "unknown";
}

}  // namespace fieldguard::velodyne
