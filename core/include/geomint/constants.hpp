#pragma once
// π and 2π, defined once: Boost.Math's constants (the same doubles as the 20-digit literals), as constexpr values so
// that they serve in constant expressions (a scene's default parameters, a period in an angle reduction).
#include <boost/math/constants/constants.hpp>

namespace geomint {

inline constexpr double pi = boost::math::constants::pi<double>();
inline constexpr double two_pi = boost::math::constants::two_pi<double>();

}  // namespace geomint
