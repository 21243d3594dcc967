// Smallest-three quaternion codes (quaternion_codec.h).
#include "src/net/quaternion_codec.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "swarmlio/net/wire_format.h"

namespace swarmlio::net::internal {
namespace {

/// The restored coefficient, and whether it is strictly the largest.
bool Restore(const std::array<int16_t, 3>& sent, double* largest) {
  double sum = 0.0;
  double biggest_sent = 0.0;
  for (int16_t code : sent) {
    const double c = code / kQuaternionScale;
    sum += c * c;
    biggest_sent = std::max(biggest_sent, std::abs(c));
  }
  *largest = std::sqrt(std::max(0.0, 1.0 - sum));
  return *largest > biggest_sent;
}

}  // namespace

QuaternionCodes EncodeQuaternion(const Eigen::Quaterniond& q) {
  Eigen::Vector4d c = q.coeffs() / q.coeffs().norm();  // x y z w
  int largest = 0;
  for (int i = 1; i < 4; ++i) {
    if (std::abs(c[i]) > std::abs(c[largest])) largest = i;
  }
  if (c[largest] < 0.0) c = -c;
  QuaternionCodes codes;
  codes.largest = static_cast<uint8_t>(largest);
  for (int i = 0, k = 0; i < 4; ++i) {
    if (i == largest) continue;
    const long code = std::lround(c[i] * kQuaternionScale);
    codes.sent[k++] =
        static_cast<int16_t>(std::clamp<long>(code, -kQuaternionMaxCode, kQuaternionMaxCode));
  }
  double restored = 0.0;
  while (!Restore(codes.sent, &restored)) {  // a near-tie: shrink the biggest sent code
    int16_t& biggest =
        *std::max_element(codes.sent.begin(), codes.sent.end(),
                          [](int16_t a, int16_t b) { return std::abs(a) < std::abs(b); });
    biggest = static_cast<int16_t>(biggest > 0 ? biggest - 1 : biggest + 1);
  }
  return codes;
}

bool DecodeQuaternion(const QuaternionCodes& codes, Eigen::Quaterniond* q) {
  if (codes.largest > 3) return false;
  for (int16_t code : codes.sent) {
    if (code < -kQuaternionMaxCode) return false;
  }
  double restored = 0.0;
  if (!Restore(codes.sent, &restored)) return false;
  Eigen::Vector4d c;
  for (int i = 0, k = 0; i < 4; ++i) {
    c[i] = i == codes.largest ? restored : codes.sent[k++] / kQuaternionScale;
  }
  *q = Eigen::Quaterniond(c[3], c[0], c[1], c[2]);
  return true;
}

}  // namespace swarmlio::net::internal
