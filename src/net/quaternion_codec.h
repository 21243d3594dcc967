// Unit quaternions <-> "smallest three" codes (wire_format.h): the
// coefficient of largest magnitude is made positive and dropped, the other
// three travel as int16 codes round(c * kQuaternionScale) in coefficient
// order (x y z w without the dropped one), and the receiver restores the
// dropped one as sqrt(1 - sum c^2).
//
// Codes are canonical: the restored coefficient is strictly larger than the
// three sent ones (the encoder moves a sent code one step towards zero in
// the rare ties where rounding would break this; the decoder rejects codes
// that break it). So a decoded quaternion re-encodes to the same codes.
// Angular error of a round trip (one step is 1 / (32767 sqrt2) = 2.2e-5 per
// coefficient): at most 6.7e-5 rad, mean 2.4e-5 rad over 200 000 random
// rotations (tests/net/codec_fields_test.cc; the test's bound is 1.2e-4).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>

namespace swarmlio::net::internal {

/// The low two bits of a payload's bits byte: QuaternionCodes::largest.
constexpr uint8_t kQuaternionLargestMask = 0x03;

struct QuaternionCodes {
  uint8_t largest = 3;  // index (x y z w = 0 1 2 3) of the dropped coefficient
  std::array<int16_t, 3> sent = {0, 0, 0};
};

/// Precondition: finite, nonzero norm (normalized here).
QuaternionCodes EncodeQuaternion(const Eigen::Quaterniond& q);

/// False if a code is -32768 (outside +-kQuaternionMaxCode), `largest` > 3,
/// or the codes are not canonical (the restored coefficient would not be
/// strictly the largest; this includes sum c^2 >= 1).
bool DecodeQuaternion(const QuaternionCodes& codes, Eigen::Quaterniond* q);

}  // namespace swarmlio::net::internal
