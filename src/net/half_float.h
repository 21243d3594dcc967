// IEEE-754 binary16 ("half") <-> double, written out with integer and
// power-of-two arithmetic only, so that the bits do not depend on the host's
// F16C support or rounding of intermediate floats. Rounding is to nearest,
// ties to even, directly from double (no double rounding through float32).
#pragma once

#include <cmath>
#include <cstdint>

namespace swarmlio::net::internal {

/// Largest finite half: 65504. Values with |x| >= kHalfOverflow round to Inf.
inline constexpr double kHalfMax = 65504.0;
inline constexpr double kHalfOverflow = 65520.0;

/// True when `x` rounds to a finite half.
inline bool FitsHalf(double x) { return std::isfinite(x) && std::abs(x) < kHalfOverflow; }

/// Round half to even of a non-negative double below 2^31 (x - floor(x) is
/// exact there).
inline uint32_t RoundHalfEven(double x) {
  const double floor_x = std::floor(x);
  const double fraction = x - floor_x;  // exact
  auto result = static_cast<uint32_t>(floor_x);
  if (fraction > 0.5 || (fraction == 0.5 && (result & 1u) != 0)) ++result;
  return result;
}

/// Precondition: FitsHalf(x).
inline uint16_t HalfFromDouble(double x) {
  const uint16_t sign = std::signbit(x) ? 0x8000 : 0;
  const double a = std::abs(x);
  if (a < 0x1.0p-14) {  // subnormal (or zero): units of 2^-24; 1024 carries into the exponent
    return static_cast<uint16_t>(sign | RoundHalfEven(a * 0x1.0p24));
  }
  int exponent = 0;
  std::frexp(a, &exponent);    // a = f * 2^exponent, f in [0.5, 1)
  const int e = exponent - 1;  // a in [2^e, 2^(e+1)), e in [-14, 15]
  // Significand with the implicit bit, 11 bits: [1024, 2048]; 2048 carries.
  const uint32_t significand = RoundHalfEven(std::ldexp(a, 10 - e));
  const uint32_t biased = static_cast<uint32_t>(e + 15);
  return static_cast<uint16_t>(sign | ((biased << 10) + (significand - 1024)));
}

/// Inf and NaN bit patterns (exponent 31) are reported by IsFiniteHalf.
inline bool IsFiniteHalf(uint16_t bits) { return (bits & 0x7C00) != 0x7C00; }

inline double DoubleFromHalf(uint16_t bits) {
  const double sign = (bits & 0x8000) != 0 ? -1.0 : 1.0;
  const int biased = (bits >> 10) & 0x1F;
  const int mantissa = bits & 0x3FF;
  if (biased == 0) return sign * std::ldexp(static_cast<double>(mantissa), -24);
  return sign * std::ldexp(static_cast<double>(1024 + mantissa), biased - 25);
}

}  // namespace swarmlio::net::internal
