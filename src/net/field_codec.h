// Wire helpers shared by the payload codecs: the field encodings of
// wire_format.h (float32 and float16 vectors, scaled int16 vectors,
// smallest-three quaternions, log-variance / partial-correlation covariances)
// on top of PacketWriter / PacketReader. Readers check every decoded code's range
// and return DataLoss naming the field.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>

#include "src/net/covariance_codec.h"
#include "src/net/half_float.h"
#include "src/net/packet_reader.h"
#include "src/net/packet_writer.h"
#include "src/net/quaternion_codec.h"
#include "swarmlio/common/status.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::net::internal {

inline void WriteVectorF32(const Eigen::Vector3d& v, PacketWriter* w) {
  for (int i = 0; i < 3; ++i) w->F32(v[i]);
}
inline Status ReadVectorF32(const char* field, PacketReader* r, Eigen::Vector3d* v) {
  for (int i = 0; i < 3; ++i) SWARMLIO_RETURN_IF_ERROR(r->F32(field, i, &(*v)[i]));
  return Status::Ok();
}

/// Precondition: FitsHalf for every coefficient.
inline void WriteVectorF16(const Eigen::Vector3d& v, PacketWriter* w) {
  for (int i = 0; i < 3; ++i) w->U16(HalfFromDouble(v[i]));
}
inline Status ReadVectorF16(const char* field, PacketReader* r, Eigen::Vector3d* v) {
  for (int i = 0; i < 3; ++i) SWARMLIO_RETURN_IF_ERROR(r->F16(field, i, &(*v)[i]));
  return Status::Ok();
}

/// int16 codes round(v / step); precondition: |v / step| rounds to <= 32767.
inline void WriteScaledVectorI16(const Eigen::Vector3d& v, double step, PacketWriter* w) {
  for (int i = 0; i < 3; ++i) w->I16(static_cast<int16_t>(std::lround(v[i] / step)));
}
/// Rejects the code -32768 (the range is symmetric, +-32767 steps).
inline Status ReadScaledVectorI16(const char* field,
                                  double step,
                                  PacketReader* r,
                                  Eigen::Vector3d* v) {
  for (int i = 0; i < 3; ++i) {
    int16_t code = 0;
    SWARMLIO_RETURN_IF_ERROR(r->I16(field, i, &code));
    if (code == INT16_MIN) return r->Invalid(field, i, "has the out-of-range code -32768");
    (*v)[i] = code * step;
  }
  return Status::Ok();
}

/// The three sent coefficients; codes.largest travels in the caller's flags byte.
inline void WriteQuaternion(const QuaternionCodes& codes, PacketWriter* w) {
  for (int16_t c : codes.sent) w->I16(c);
}
/// Error messages index the sent codes [0..2].
inline Status ReadQuaternion(const char* field,
                             uint8_t largest,
                             PacketReader* r,
                             Eigen::Quaterniond* q) {
  QuaternionCodes codes;
  codes.largest = largest;
  for (int i = 0; i < 3; ++i) SWARMLIO_RETURN_IF_ERROR(r->I16(field, i, &codes.sent[i]));
  if (!DecodeQuaternion(codes, q)) {
    return r->Invalid(field, -1,
                      "is not a canonical smallest-three code (a code of -32768, or a sent "
                      "coefficient not below the restored one)");
  }
  return Status::Ok();
}

/// Precondition: the upper triangle is finite, the diagonal in
/// [0, MaxEncodableVariance()] (CheckMessage).
template <int N>
void WriteCovariance(const Eigen::Matrix<double, N, N>& m, PacketWriter* w) {
  uint8_t codes[CovarianceBytes(N)];
  EncodeCovariance<N>(m, codes);
  for (uint8_t c : codes) w->U8(c);
}
/// Error messages index the codes in wire order (variances, then correlations).
template <int N>
Status ReadCovariance(const char* field, PacketReader* r, Eigen::Matrix<double, N, N>* m) {
  uint8_t codes[CovarianceBytes(N)];
  for (size_t i = 0; i < CovarianceBytes(N); ++i) {
    SWARMLIO_RETURN_IF_ERROR(r->U8(field, static_cast<int>(i), &codes[i]));
  }
  int bad = -1;
  if (!DecodeCovariance<N>(codes, m, &bad)) {
    return r->Invalid(field, bad, "has the out-of-range correlation code -128");
  }
  return Status::Ok();
}

}  // namespace swarmlio::net::internal
