#include "datasets/noise_spec.h"

#include <cinttypes>
#include <cmath>

#include "forward_model/number_format.h"

namespace slideid {
namespace {

/// The numeric fields with their metadata names, in the order they are written.
std::vector<std::pair<const char*, double>> Fields(const NoiseSpec& n) {
  return {{"pose_m", n.pose_m},
          {"angle_rad", n.angle_rad},
          {"velocity_mps", n.velocity_mps},
          {"spin_radps", n.spin_radps},
          {"force_relative", n.force_relative},
          {"force_n", n.force_n},
          {"push_point_m", n.push_point_m},
          {"outlier_fraction", n.outlier_fraction},
          {"outlier_m", n.outlier_m}};
}

/// The push stream's defects with their metadata names (without the noise_ prefix).
std::vector<std::pair<const char*, double>> AllDefects(const NoiseSpec& n) {
  return {{"force_bias_x_n", n.force_bias_x_n},
          {"force_bias_y_n", n.force_bias_y_n},
          {"force_delay_s", n.force_delay_s}};
}

/// The defects that are set.
std::vector<std::pair<const char*, double>> Defects(const NoiseSpec& n) {
  std::vector<std::pair<const char*, double>> out;
  for (const auto& [name, value] : AllDefects(n)) {
    if (value != 0.0) out.emplace_back(name, value);
  }
  return out;
}

}  // namespace

bool NoiseSpec::HasDefects() const {
  return force_bias_x_n != 0 || force_bias_y_n != 0 || force_delay_s != 0;
}

bool NoiseSpec::IsZero() const {
  return pose_m == 0 && angle_rad == 0 && velocity_mps == 0 && spin_radps == 0 &&
         force_relative == 0 && force_n == 0 && push_point_m == 0 && outlier_fraction == 0;
}

bool NoiseSpec::IsValid(std::string* why) const {
  for (const auto& [name, value] : Fields(*this)) {
    if (!(std::isfinite(value) && value >= 0.0)) {
      if (why) {
        *why = std::string("noise ") + name + " = " + ExactNumber(value) + ": must be >= 0";
      }
      return false;
    }
  }
  for (const auto& [name, value] : AllDefects(*this)) {
    if (!std::isfinite(value)) {
      if (why) {
        *why = std::string("noise ") + name + " = " + ExactNumber(value) + ": must be finite";
      }
      return false;
    }
  }
  if (outlier_fraction > 1.0) {
    if (why) {
      *why = "noise outlier_fraction = " + ExactNumber(outlier_fraction) + ": must be <= 1";
    }
    return false;
  }
  return true;
}

std::vector<std::pair<std::string, std::string>> NoiseSpec::Metadata() const {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [name, value] : Fields(*this)) {
    out.emplace_back(std::string("noise_") + name, ExactNumber(value));
  }
  out.emplace_back("noise_seed", std::to_string(seed));
  for (const auto& [name, value] : Defects(*this)) {
    out.emplace_back(std::string("noise_") + name, ExactNumber(value));
  }
  return out;
}

std::string NoiseSpec::Describe() const {
  std::string out;
  for (const auto& [name, value] : Fields(*this)) {
    out += std::string(name) + "=" + ExactNumber(value) + " ";
  }
  out += "seed=" + std::to_string(seed);
  for (const auto& [name, value] : Defects(*this)) {
    out += std::string(" ") + name + "=" + ExactNumber(value);
  }
  return out;
}

}  // namespace slideid
