#pragma once
// The mathematical constants every room uses, defined once (C++17 has no std::numbers).

namespace slideid {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kRadToDeg = 180.0 / kPi;  ///< degrees per radian

}  // namespace slideid
