#include "swarmlio/lio/in_flight_alignment.h"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "swarmlio/math/so3.h"

namespace swarmlio::lio {
namespace {

double Seconds(int64_t ns) { return static_cast<double>(ns) * 1e-9; }

// Rotation, velocity-like and position-like integrals from t0.
struct Integrals {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

// One step of dt with the midpoint input (w, f): the force rotated at the
// step's middle attitude.
void Step(const Eigen::Vector3d& w, const Eigen::Vector3d& f, double dt, Integrals* s) {
  const Eigen::Matrix3d R_mid = s->R * so3::Exp(0.5 * dt * w);
  const Eigen::Vector3d a = R_mid * f;
  s->p += s->v * dt + 0.5 * dt * dt * a;
  s->v += dt * a;
  s->R = s->R * so3::Exp(dt * w);
}

}  // namespace

Status DoubleIntegrateSpecificForce(const ImuSample& start,
                                    const std::vector<ImuSample>& samples,
                                    double acceleration_to_m_s2,
                                    const Eigen::Vector3d& gyro_bias_rad_s,
                                    const std::vector<StampedPose>& poses,
                                    std::vector<Eigen::Vector3d>* double_integrals) {
  double_integrals->clear();
  std::vector<int64_t> stamps_ns;
  for (const StampedPose& p : poses) stamps_ns.push_back(p.stamp_ns);
  if (stamps_ns.empty()) return Status::Ok();
  if (samples.empty() || stamps_ns.front() <= start.stamp_ns ||
      stamps_ns.back() > samples.back().stamp_ns) {
    return Status::InvalidArgument("in-flight alignment: pose stamps outside the IMU samples");
  }
  Integrals s;
  size_t next = 0;  // next stamp to report
  ImuSample a = start;
  int64_t t = start.stamp_ns;  // integrated up to here
  for (const ImuSample& b : samples) {
    if (b.stamp_ns <= a.stamp_ns) continue;
    const double span = Seconds(b.stamp_ns - a.stamp_ns);
    // Sub-steps of [a, b] ending at the pose stamps inside it, then at b.
    while (t < b.stamp_ns) {
      int64_t end = b.stamp_ns;
      if (next < stamps_ns.size() && stamps_ns[next] < end) end = stamps_ns[next];
      const double mid = 0.5 * Seconds((t - a.stamp_ns) + (end - a.stamp_ns)) / span;
      const Eigen::Vector3d w =
          (1.0 - mid) * a.angular_velocity_rad_s + mid * b.angular_velocity_rad_s - gyro_bias_rad_s;
      const Eigen::Vector3d f = acceleration_to_m_s2 *
                                ((1.0 - mid) * a.linear_acceleration + mid * b.linear_acceleration);
      Step(w, f, Seconds(end - t), &s);
      t = end;
      while (next < stamps_ns.size() && stamps_ns[next] == t) {
        double_integrals->push_back(s.p);
        s.R = poses[next].q_G_b.normalized().toRotationMatrix();
        ++next;
      }
    }
    a = b;
    if (next == stamps_ns.size()) break;
  }
  if (next != stamps_ns.size()) {
    return Status::InvalidArgument("in-flight alignment: pose stamps not increasing");
  }
  return Status::Ok();
}

Status AlignVelocityAndGravity(const ImuSample& start,
                               const std::vector<ImuSample>& samples,
                               double acceleration_to_m_s2,
                               const Eigen::Vector3d& gyro_bias_rad_s,
                               const std::vector<StampedPose>& positions,
                               double position_stddev_floor_m,
                               VelocityGravityAlignment* result) {
  const int n = static_cast<int>(positions.size());
  if (n < 3) {
    return Status::FailedPrecondition("in-flight alignment: " + std::to_string(n) +
                                      " scan positions, need 3");
  }
  const double span_s = Seconds(positions.back().stamp_ns - start.stamp_ns);
  if (span_s < 0.2) {
    std::ostringstream os;
    os << "in-flight alignment: the scan positions span " << span_s
       << " s, need 0.2 s to tell gravity from velocity";
    return Status::FailedPrecondition(os.str());
  }
  std::vector<Eigen::Vector3d> D;
  SWARMLIO_RETURN_IF_ERROR(DoubleIntegrateSpecificForce(start, samples, acceleration_to_m_s2,
                                                        gyro_bias_rad_s, positions, &D));
  Eigen::MatrixXd A(3 * n, 6);
  Eigen::VectorXd b(3 * n);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (int k = 0; k < n; ++k) {
    const double tau = Seconds(positions[k].stamp_ns - start.stamp_ns);
    A.block<3, 3>(3 * k, 0) = tau * I;
    A.block<3, 3>(3 * k, 3) = 0.5 * tau * tau * I;
    b.segment<3>(3 * k) = positions[k].p_b_in_G - D[k];
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < 6) {
    return Status::FailedPrecondition("in-flight alignment: rank-deficient system");
  }
  const Eigen::VectorXd x = qr.solve(b);
  const Eigen::VectorXd r = A * x - b;
  VelocityGravityAlignment& out = *result;
  out.v_b_in_G = x.head<3>();
  out.g_in_G = x.tail<3>();
  out.num_positions = n;
  const int dof = std::max(1, 3 * n - 6);
  out.rms_residual_m = std::sqrt(r.squaredNorm() / dof);
  const double sigma = std::max(out.rms_residual_m, position_stddev_floor_m);
  const Eigen::Matrix<double, 6, 6> AtA = A.transpose() * A;
  out.covariance = sigma * sigma * AtA.inverse();
  return Status::Ok();
}

}  // namespace swarmlio::lio
