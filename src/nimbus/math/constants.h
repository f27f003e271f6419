#pragma once

#include <limits>
#include <numbers>

namespace nimbus {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kInvPi = std::numbers::inv_pi;
inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kInv4Pi = 0.25 * std::numbers::inv_pi;  // the isotropic phase function

}  // namespace nimbus
