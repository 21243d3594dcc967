#include "swarmlio/sim/trajectory.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "swarmlio/common/check.h"
#include "swarmlio/math/so3.h"

namespace swarmlio::sim {
namespace {

// Uniform quintic B-spline basis: blend_j(u) = sum_p u^p M[p][j] / 120.
constexpr double kBasis[6][6] = {
    {1, 26, 66, 26, 1, 0},   {-5, -50, 0, 50, 5, 0}, {10, 20, -60, 20, 10, 0},
    {-10, 20, 0, -20, 10, 0}, {5, -20, 30, -20, 5, 0}, {-1, 5, -10, 10, -5, 1}};

// Second-order truncated Taylor number: value and first two time derivatives.
struct Taylor2 {
  double v = 0.0, d = 0.0, dd = 0.0;
};
Taylor2 operator+(const Taylor2& a, const Taylor2& b) { return {a.v + b.v, a.d + b.d, a.dd + b.dd}; }
Taylor2 operator-(const Taylor2& a, const Taylor2& b) { return {a.v - b.v, a.d - b.d, a.dd - b.dd}; }
Taylor2 operator*(const Taylor2& a, const Taylor2& b) {
  return {a.v * b.v, a.d * b.v + a.v * b.d, a.dd * b.v + 2.0 * a.d * b.d + a.v * b.dd};
}
Taylor2 Sqrt(const Taylor2& a) {
  const double s = std::sqrt(a.v);
  return {s, a.d / (2.0 * s), a.dd / (2.0 * s) - a.d * a.d / (4.0 * s * s * s)};
}
Taylor2 Inverse(const Taylor2& a) {
  const double i = 1.0 / a.v;
  return {i, -a.d * i * i, (2.0 * a.d * a.d * i - a.dd) * i * i};
}
Taylor2 Cos(const Taylor2& a) {
  const double c = std::cos(a.v), s = std::sin(a.v);
  return {c, -s * a.d, -c * a.d * a.d - s * a.dd};
}
Taylor2 Sin(const Taylor2& a) {
  const double c = std::cos(a.v), s = std::sin(a.v);
  return {s, c * a.d, -s * a.d * a.d + c * a.dd};
}

using Vec3T = std::array<Taylor2, 3>;
Vec3T Cross(const Vec3T& a, const Vec3T& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3T Normalized(const Vec3T& a) {
  const Taylor2 inv = Inverse(Sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]));
  return {a[0] * inv, a[1] * inv, a[2] * inv};
}

// Flatness map (thrust vector f = a + g_up, yaw) -> R_W_b, without derivatives.
Eigen::Matrix3d QuadrotorAttitude(const Eigen::Vector3d& f, double yaw) {
  const Eigen::Vector3d z = f.normalized();
  const Eigen::Vector3d x_c(std::cos(yaw), std::sin(yaw), 0.0);
  const Eigen::Vector3d y = z.cross(x_c).normalized();
  Eigen::Matrix3d R;
  R.col(0) = y.cross(z);
  R.col(1) = y;
  R.col(2) = z;
  return R;
}

Eigen::Matrix3d YawRotation(double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

Trajectory::Trajectory(double start_time_s, double knot_interval_s,
                       std::vector<Eigen::Vector4d> control_points, AttitudeMode mode)
    : start_time_(start_time_s),
      knot_interval_(knot_interval_s),
      control_points_(std::move(control_points)),
      mode_(mode) {
  CHECK_GT(knot_interval_, 0.0);
  CHECK_GE(control_points_.size(), 6u);
}

double Trajectory::end_time() const {
  return start_time_ + static_cast<double>(control_points_.size() - 5) * knot_interval_;
}

void Trajectory::Locate(double t, int* segment, double* u) const {
  const int num_segments = static_cast<int>(control_points_.size()) - 5;
  const double s = (t - start_time_) / knot_interval_;
  if (!(s > 0.0)) {
    *segment = 0;
    *u = 0.0;
    return;
  }
  int i = static_cast<int>(std::floor(s));
  if (i >= num_segments) {
    *segment = num_segments - 1;
    *u = 1.0;
    return;
  }
  *segment = i;
  *u = s - i;
}

Eigen::Vector4d Trajectory::Derivative(double t, int k) const {
  CHECK(k >= 0 && k <= 5);
  int seg;
  double u;
  Locate(t, &seg, &u);
  // d^k/du^k of u^p = p!/(p-k)! u^(p-k).
  std::array<double, 6> w{};
  double u_power = 1.0;  // u^(p - k)
  for (int p = k; p <= 5; ++p) {
    double coeff = 1.0;
    for (int q = 0; q < k; ++q) coeff *= (p - q);
    w[p] = coeff * u_power;
    u_power *= u;
  }
  double dt_power = 1.0;
  for (int q = 0; q < k; ++q) dt_power *= knot_interval_;
  const double scale = 1.0 / (120.0 * dt_power);
  Eigen::Vector4d out = Eigen::Vector4d::Zero();
  for (int j = 0; j < 6; ++j) {
    double b = 0.0;
    for (int p = k; p <= 5; ++p) b += w[p] * kBasis[p][j];
    out += b * control_points_[seg + j];
  }
  return out * scale;
}

Eigen::Vector3d Trajectory::PositionAt(double t) const { return Derivative(t, 0).head<3>(); }

Pose Trajectory::PoseAt(double t) const {
  const Eigen::Vector4d x = Derivative(t, 0);
  Pose pose;
  pose.p_b_in_W = x.head<3>();
  if (mode_ == AttitudeMode::kYawOnly) {
    pose.R_W_b = YawRotation(x[3]);
  } else {
    const Eigen::Vector3d f = Derivative(t, 2).head<3>() + Eigen::Vector3d(0, 0, kGravity);
    pose.R_W_b = QuadrotorAttitude(f, x[3]);
  }
  return pose;
}

KinematicState Trajectory::StateAt(double t) const {
  std::array<Eigen::Vector4d, 5> d;
  for (int k = 0; k < 5; ++k) d[k] = Derivative(t, k);
  KinematicState s;
  s.p_b_in_W = d[0].head<3>();
  s.v_b_in_W = d[1].head<3>();
  s.a_b_in_W = d[2].head<3>();
  const Taylor2 yaw{d[0][3], d[1][3], d[2][3]};
  if (mode_ == AttitudeMode::kYawOnly) {
    s.R_W_b = YawRotation(yaw.v);
    s.omega_b = Eigen::Vector3d(0, 0, yaw.d);
    s.alpha_b = Eigen::Vector3d(0, 0, yaw.dd);
    return s;
  }
  // Thrust vector and its first two derivatives (jerk, snap).
  Vec3T f;
  for (int i = 0; i < 3; ++i) {
    f[i] = {d[2][i] + (i == 2 ? kGravity : 0.0), d[3][i], d[4][i]};
  }
  const Vec3T z = Normalized(f);
  const Vec3T x_c = {Cos(yaw), Sin(yaw), Taylor2{}};
  const Vec3T y = Normalized(Cross(z, x_c));
  const Vec3T x = Cross(y, z);
  Eigen::Matrix3d R, R_dot, R_ddot;
  const std::array<const Vec3T*, 3> cols = {&x, &y, &z};
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      R(r, c) = (*cols[c])[r].v;
      R_dot(r, c) = (*cols[c])[r].d;
      R_ddot(r, c) = (*cols[c])[r].dd;
    }
  }
  s.R_W_b = R;
  // R^T R_dot = [omega]x; the skew part of R^T R_ddot = [alpha]x.
  const Eigen::Matrix3d W = R.transpose() * R_dot;
  const Eigen::Matrix3d A = R.transpose() * R_ddot;
  s.omega_b = so3::Vee(0.5 * (W - W.transpose()));
  s.alpha_b = so3::Vee(0.5 * (A - A.transpose()));
  return s;
}

void Trajectory::Extremes(double dt, double* max_speed, double* max_acceleration,
                          double* max_angular_rate) const {
  *max_speed = *max_acceleration = *max_angular_rate = 0.0;
  for (double t = start_time_; t <= end_time(); t += dt) {
    const KinematicState s = StateAt(t);
    *max_speed = std::max(*max_speed, s.v_b_in_W.norm());
    *max_acceleration = std::max(*max_acceleration, s.a_b_in_W.norm());
    *max_angular_rate = std::max(*max_angular_rate, s.omega_b.norm());
  }
}

}  // namespace swarmlio::sim
