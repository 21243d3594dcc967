// Wire helpers shared by the payload codecs: quaternions (x y z w, float32)
// and symmetric matrices as float32 upper triangles (row-major).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "src/net/wire_reader.h"
#include "src/net/wire_writer.h"
#include "swarmlio/common/status.h"

namespace swarmlio::net::internal {

inline void WriteQuaternionF32(const Eigen::Quaterniond& q, WireWriter* w) {
  w->F32(q.x());
  w->F32(q.y());
  w->F32(q.z());
  w->F32(q.w());
}

/// Error messages index the coefficients in wire order: [0..3] = x y z w.
inline Status ReadQuaternionF32(const char* field, WireReader* r, Eigen::Quaterniond* q) {
  double x = 0, y = 0, z = 0, qw = 0;
  SWARMLIO_RETURN_IF_ERROR(r->F32(field, 0, &x));
  SWARMLIO_RETURN_IF_ERROR(r->F32(field, 1, &y));
  SWARMLIO_RETURN_IF_ERROR(r->F32(field, 2, &z));
  SWARMLIO_RETURN_IF_ERROR(r->F32(field, 3, &qw));
  *q = Eigen::Quaterniond(qw, x, y, z);
  return Status::Ok();
}

inline void WriteVectorF32(const Eigen::Vector3d& v, WireWriter* w) {
  for (int i = 0; i < 3; ++i) w->F32(v[i]);
}
inline void WriteVectorF64(const Eigen::Vector3d& v, WireWriter* w) {
  for (int i = 0; i < 3; ++i) w->F64(v[i]);
}

inline Status ReadVectorF32(const char* field, WireReader* r, Eigen::Vector3d* v) {
  for (int i = 0; i < 3; ++i) SWARMLIO_RETURN_IF_ERROR(r->F32(field, i, &(*v)[i]));
  return Status::Ok();
}
inline Status ReadVectorF64(const char* field, WireReader* r, Eigen::Vector3d* v) {
  for (int i = 0; i < 3; ++i) SWARMLIO_RETURN_IF_ERROR(r->F64(field, i, &(*v)[i]));
  return Status::Ok();
}

/// Writes the N(N+1)/2 upper-triangle entries (row-major); the lower triangle is ignored.
template <int N>
void WriteUpperTriangleF32(const Eigen::Matrix<double, N, N>& m, WireWriter* w) {
  for (int row = 0; row < N; ++row) {
    for (int col = row; col < N; ++col) w->F32(m(row, col));
  }
}

/// Reads an upper triangle and mirrors it into a symmetric matrix. Error
/// messages index the entries in wire order (upper triangle, row-major).
template <int N>
Status ReadUpperTriangleF32(const char* field, WireReader* r, Eigen::Matrix<double, N, N>* m) {
  int index = 0;
  for (int row = 0; row < N; ++row) {
    for (int col = row; col < N; ++col) {
      double value = 0.0;
      SWARMLIO_RETURN_IF_ERROR(r->F32(field, index++, &value));
      (*m)(row, col) = value;
      (*m)(col, row) = value;
    }
  }
  return Status::Ok();
}

}  // namespace swarmlio::net::internal
