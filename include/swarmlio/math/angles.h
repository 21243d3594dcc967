// Degree/radian conversion factor (one definition for the whole library).
#pragma once

#include <cmath>

namespace swarmlio {

inline constexpr double kRadiansPerDegree = M_PI / 180.0;

}  // namespace swarmlio
