#include "io/cm_offset.h"

#include <cmath>
#include <sstream>
#include <string>

#include "io/text_lines.h"

namespace slideid {

std::optional<Eigen::Vector2d> ParseCmOffset(std::string_view text) {
  std::string spaced(text);
  for (char& c : spaced) c = c == ',' ? ' ' : c;
  std::istringstream in(spaced);
  std::string dx, dy, extra;
  in >> dx >> dy;
  const auto x = text::ParseFiniteNumber(dx), y = text::ParseFiniteNumber(dy);
  if (!x || !y || (in >> extra)) return std::nullopt;
  return Eigen::Vector2d(*x, *y);
}

Eigen::Vector2d CmOffsetInWorld(const Eigen::Vector2d& offset, double theta_rad) {
  const double c = std::cos(theta_rad), s = std::sin(theta_rad);
  return {c * offset.x() - s * offset.y(), s * offset.x() + c * offset.y()};
}

}  // namespace slideid
