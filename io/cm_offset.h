#pragma once
// The CM of a slider whose pose is that of another frame (motion capture tracks a rigid
// body's own origin): where the CM sits in that frame, as a log's `cm_offset` metadata and
// the objects table's `cm_offset` column give it (docs/log-format.md, docs/real-data.md).

#include <Eigen/Core>
#include <optional>
#include <string_view>

namespace slideid {

/// "DX DY" [m, the frame's axes], the two separated by blanks or a comma; nullopt unless it
/// is exactly two finite numbers.
std::optional<Eigen::Vector2d> ParseCmOffset(std::string_view text);

/// The offset in world axes for the frame at heading `theta_rad`: R(theta) offset, what the
/// CM lies from the frame's origin.
Eigen::Vector2d CmOffsetInWorld(const Eigen::Vector2d& offset, double theta_rad);

}  // namespace slideid
