#include "swarmlio/lio/imu_initializer.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "swarmlio/math/so3.h"

namespace swarmlio::lio {
namespace {

using L = ErrorStateLayout;

bool IsFinite(const ImuSample& s) {
  return s.angular_velocity_rad_s.allFinite() && s.linear_acceleration.allFinite();
}

// |mean a_m| ranges (raw units) that auto-detection accepts, as ratios of 1 g.
constexpr double kAutoMinRatio = 0.5;
constexpr double kAutoMaxRatio = 1.5;

struct WindowStatistics {
  Eigen::Vector3d mean_gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_accel = Eigen::Vector3d::Zero();  // raw units
  Eigen::Matrix3d cov_gyro = Eigen::Matrix3d::Zero();    // sample covariance
  Eigen::Matrix3d cov_accel = Eigen::Matrix3d::Zero();   // raw units^2
};

// Two-pass mean and sample covariance (the window is small).
WindowStatistics ComputeStatistics(const std::deque<ImuSample>& window) {
  WindowStatistics s;
  const double n = static_cast<double>(window.size());
  for (const ImuSample& x : window) {
    s.mean_gyro += x.angular_velocity_rad_s;
    s.mean_accel += x.linear_acceleration;
  }
  s.mean_gyro /= n;
  s.mean_accel /= n;
  for (const ImuSample& x : window) {
    const Eigen::Vector3d dg = x.angular_velocity_rad_s - s.mean_gyro;
    const Eigen::Vector3d da = x.linear_acceleration - s.mean_accel;
    s.cov_gyro += dg * dg.transpose();
    s.cov_accel += da * da.transpose();
  }
  s.cov_gyro /= (n - 1.0);
  s.cov_accel /= (n - 1.0);
  return s;
}

// The acceleration unit: configured, or (kAuto, *detected) from |mean a_m|
// = raw_norm: ~1 -> g, ~g0 -> m/s^2, else FailedPrecondition.
Status ResolveAccelerationUnit(AccelerationUnitSetting setting,
                               double raw_norm,
                               double g0,
                               AccelerationUnit* unit,
                               bool* detected) {
  switch (setting) {
    case AccelerationUnitSetting::kMetersPerSecondSquared:
      *unit = AccelerationUnit::kMetersPerSecondSquared;
      break;
    case AccelerationUnitSetting::kStandardGravity:
      *unit = AccelerationUnit::kStandardGravity;
      break;
    case AccelerationUnitSetting::kAuto:
      *detected = true;
      if (raw_norm >= kAutoMinRatio && raw_norm <= kAutoMaxRatio) {
        *unit = AccelerationUnit::kStandardGravity;
      } else if (raw_norm >= kAutoMinRatio * g0 && raw_norm <= kAutoMaxRatio * g0) {
        *unit = AccelerationUnit::kMetersPerSecondSquared;
      } else {
        std::ostringstream os;
        os << "imu initializer: cannot detect the acceleration unit: |mean acc| = " << raw_norm
           << " is neither ~1 (g, accepted [" << kAutoMinRatio << ", " << kAutoMaxRatio
           << "]) nor ~" << g0 << " (m/s^2, accepted [" << kAutoMinRatio * g0 << ", "
           << kAutoMaxRatio * g0 << "])";
        return Status::FailedPrecondition(os.str());
      }
      break;
  }
  return Status::Ok();
}

// Where the reported mean acceleration (raw, norm raw_norm) points relative
// to up_axis: up, down (within max_up_axis_angle_deg) or undetermined, and
// its angle from up_axis [deg] (0 without an up_axis).
void ReportedDirection(const ImuInitializerOptions& options,
                       const Eigen::Vector3d& mean_accel,
                       double raw_norm,
                       SpecificForceDirection* direction,
                       double* angle_deg) {
  const Eigen::Vector3d up = UpAxisVector(options.up_axis);
  if (options.up_axis != ImuUpAxis::kNone && raw_norm > 0.0) {
    const double c = std::clamp(mean_accel.dot(up) / raw_norm, -1.0, 1.0);
    *angle_deg = std::acos(c) * 180.0 / M_PI;
    if (*angle_deg <= options.max_up_axis_angle_deg) {
      *direction = SpecificForceDirection::kUp;
    } else if (*angle_deg >= 180.0 - options.max_up_axis_angle_deg) {
      *direction = SpecificForceDirection::kDown;
    }
  }
}

// The accelerometer sign: *sign is the configured one (0 = auto: detected
// from the direction, +1 when undetermined); *sign_warning explains an
// undetermined auto sign or a direction that contradicts the configured one.
void ResolveSign(const ImuInitializerOptions& options,
                 SpecificForceDirection direction,
                 double angle_deg,
                 int* sign,
                 std::string* sign_warning) {
  const bool sign_detected = *sign == 0;
  std::ostringstream os;
  os << "the mean acceleration at rest points " << config::EnumToString(direction) << " ("
     << angle_deg << " deg from up_axis " << config::EnumToString(options.up_axis) << ")";
  const std::string seen = os.str();
  if (sign_detected) {
    if (direction == SpecificForceDirection::kUndetermined) {
      *sign = 1;
      *sign_warning = seen + ": cannot tell the accelerometer sign, assumed +1; set "
                             "imu_init.acceleration_sign (+1 or -1) or imu_init.up_axis";
    } else {
      *sign = direction == SpecificForceDirection::kDown ? -1 : 1;
    }
  } else if (direction == SpecificForceDirection::kDown && *sign == 1) {
    *sign_warning = seen + ", gravity comes out opposite to the configured sign: the driver "
                           "reports -(specific force) (or the IMU is mounted with up_axis "
                           "down); set odometry.experimental.imu_init.acceleration_sign: -1 "
                           "(or 0 = auto; replay manifest: odometry: {experimental: "
                           "{imu_init: {acceleration_sign: 0}}}), or imu_init.up_axis to the "
                           "IMU's up axis";
  } else if (direction == SpecificForceDirection::kUp && *sign == -1) {
    *sign_warning = seen + ", gravity comes out opposite to the configured sign -1: the driver "
                           "reports the specific force; set "
                           "odometry.experimental.imu_init.acceleration_sign: 1 (or "
                           "0 = auto), or imu_init.up_axis to the IMU's up axis";
  }
}

}  // namespace

Eigen::Vector3d UpAxisVector(ImuUpAxis axis) {
  switch (axis) {
    case ImuUpAxis::kPlusX:
      return Eigen::Vector3d::UnitX();
    case ImuUpAxis::kMinusX:
      return -Eigen::Vector3d::UnitX();
    case ImuUpAxis::kPlusY:
      return Eigen::Vector3d::UnitY();
    case ImuUpAxis::kMinusY:
      return -Eigen::Vector3d::UnitY();
    case ImuUpAxis::kPlusZ:
      return Eigen::Vector3d::UnitZ();
    case ImuUpAxis::kMinusZ:
      return -Eigen::Vector3d::UnitZ();
    case ImuUpAxis::kNone:
      break;
  }
  return Eigen::Vector3d::Zero();
}

std::string ImuInitializerOptions::Validate() const {
  std::string error = config::ValidateFields(*this);
  if (!error.empty()) return error;
  if (acceleration_sign != 1 && acceleration_sign != -1 && acceleration_sign != 0) {
    return "acceleration_sign: must be +1, -1 or 0 (auto) (got " +
           std::to_string(acceleration_sign) + ")";
  }
  return {};
}

std::string ImuInitialization::Summary() const {
  std::ostringstream os;
  os << "IMU initialized from " << num_samples << " samples: acceleration unit "
     << config::EnumToString(acceleration_unit) << (unit_detected ? " (detected)" : " (configured)")
     << ", factor " << acceleration_to_m_s2 << ", |g| = " << gravity_magnitude_m_s2
     << " m/s^2, g_in_G = [" << state.g_in_G.transpose() << "], gyro bias = ["
     << state.gyro_bias.transpose() << "] rad/s, std gyro " << gyro_stddev_rad_s
     << " rad/s, std acc " << accel_stddev_m_s2 << " m/s^2; accelerometer sign "
     << (acceleration_sign > 0 ? "+1" : "-1") << (sign_detected ? " (detected)" : " (configured)")
     << ": acceleration at rest points ";
  switch (reported_direction) {
    case SpecificForceDirection::kUp:
      os << "up (normal)";
      break;
    case SpecificForceDirection::kDown:
      os << "down (sign-flipped driver)";
      break;
    case SpecificForceDirection::kUndetermined:
      os << "neither up nor down (undetermined)";
      break;
  }
  os << ", " << angle_to_up_axis_deg << " deg from up_axis";
  if (in_flight) {
    os << "; in flight: v_b_in_G = [" << state.v_b_in_G.transpose() << "] m/s from "
       << alignment_passes << " LiDAR passes (" << alignment_num_poses << " scan positions, rms "
       << alignment_rms_m << " m)";
  }
  if (!sign_warning.empty()) os << "; WARNING: " << sign_warning;
  return os.str();
}

Status ImuInitializer::Create(const ImuInitializerOptions& options,
                              std::unique_ptr<ImuInitializer>* initializer) {
  const std::string error = options.Validate();
  if (!error.empty()) return Status::InvalidArgument("imu initializer options: " + error);
  initializer->reset(new ImuInitializer(options));
  return Status::Ok();
}

int64_t ImuInitializer::DurationNs() const {
  return static_cast<int64_t>(std::llround(options_.window_duration_s * 1e9));
}

Status ImuInitializer::AddSample(const ImuSample& sample) {
  if (!IsFinite(sample)) {
    ++num_rejected_non_finite_;
    return Status::InvalidArgument("imu initializer: non-finite IMU sample at stamp " +
                                   std::to_string(sample.stamp_ns) + " ns rejected");
  }
  if (!window_.empty() && sample.stamp_ns <= window_.back().stamp_ns) {
    ++num_skipped_out_of_order_;
    return Status::Ok();
  }
  window_.push_back(sample);
  if (options_.window_duration_s > 0.0) {
    // Keep the shortest suffix that still spans the duration.
    const int64_t span_ns = DurationNs();
    while (window_.size() > 2 && window_.back().stamp_ns - window_[1].stamp_ns >= span_ns) {
      window_.pop_front();
    }
  } else {
    while (static_cast<int>(window_.size()) > options_.window_num_samples) window_.pop_front();
  }
  return Status::Ok();
}

bool ImuInitializer::WindowFull() const {
  if (window_.size() < 2) return false;
  if (options_.window_duration_s > 0.0) {
    return window_.back().stamp_ns - window_.front().stamp_ns >= DurationNs();
  }
  return static_cast<int>(window_.size()) >= options_.window_num_samples;
}

struct ImuInitializer::UnitAndSign {
  AccelerationUnit unit = AccelerationUnit::kMetersPerSecondSquared;
  bool detected = false;
  double unit_factor = 1.0;
  SpecificForceDirection direction = SpecificForceDirection::kUndetermined;
  double angle_deg = 0.0;
  int sign = 1;
  bool sign_detected = false;
  std::string sign_warning;
};

Status ImuInitializer::DetermineUnitAndSign(const Eigen::Vector3d& mean_accel,
                                            UnitAndSign* out) const {
  const double g0 = options_.nominal_gravity_m_s2;
  const double raw_norm = mean_accel.norm();

  // 1. Unit: configured, or detected from |mean a_m| (~1 -> g, ~9.8 -> m/s^2).
  AccelerationUnit unit = AccelerationUnit::kMetersPerSecondSquared;
  bool detected = false;
  SWARMLIO_RETURN_IF_ERROR(
      ResolveAccelerationUnit(options_.acceleration_unit, raw_norm, g0, &unit, &detected));
  const double unit_factor = unit == AccelerationUnit::kStandardGravity ? g0 : 1.0;

  // 1b. Sign: the direction of the reported mean acceleration relative to
  // up_axis (a normal accelerometer at rest reports the specific force, up).
  SpecificForceDirection direction = SpecificForceDirection::kUndetermined;
  double angle_deg = 0.0;
  ReportedDirection(options_, mean_accel, raw_norm, &direction, &angle_deg);
  int sign = options_.acceleration_sign;
  const bool sign_detected = sign == 0;
  std::string sign_warning;
  ResolveSign(options_, direction, angle_deg, &sign, &sign_warning);
  out->unit = unit;
  out->detected = detected;
  out->unit_factor = unit_factor;
  out->direction = direction;
  out->angle_deg = angle_deg;
  out->sign = sign;
  out->sign_detected = sign_detected;
  out->sign_warning = sign_warning;
  return Status::Ok();
}

void ImuInitializer::StartResult(const UnitAndSign& us, double g_norm,
                                 ImuInitialization* r) const {
  *r = ImuInitialization();
  r->stamp_ns = window_.back().stamp_ns;
  r->started_ns = r->stamp_ns;
  r->last_sample = window_.back();
  r->state = EgoState();
  r->acceleration_unit = us.unit;
  r->unit_detected = us.detected;
  r->acceleration_to_m_s2 = us.sign * us.unit_factor;
  r->gravity_magnitude_m_s2 = g_norm;
  r->num_samples = static_cast<int>(window_.size());
  r->reported_direction = us.direction;
  r->angle_to_up_axis_deg = us.angle_deg;
  r->acceleration_sign = us.sign;
  r->sign_detected = us.sign_detected;
  r->sign_warning = us.sign_warning;
}

void ImuInitializer::SetInitialCovariance(double velocity_sigma, const Eigen::Matrix3d& P_gyro_bias,
                                          const Eigen::Matrix3d& P_gravity_measured,
                                          double gravity_sigma_floor,
                                          Eigen::Matrix<double, ErrorStateLayout::kEgoDim,
                                                        ErrorStateLayout::kEgoDim>* P) const {
  // Pose and velocity priors; the gravity error equals the accelerometer-bias
  // error (only g - b_a enters the specific force, docs/imu.md), so
  // Cov(g, b_a) = Cov(b_a), plus what the mean measured and a floor.
  P->setZero();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double sr = options_.initial_rotation_stddev_rad;
  const double sp = options_.initial_position_stddev_m;
  const double sba = options_.initial_accel_bias_stddev_m_s2;
  const double sg = gravity_sigma_floor;
  P->block<3, 3>(L::kRotation.offset, L::kRotation.offset) = sr * sr * I;
  P->block<3, 3>(L::kPosition.offset, L::kPosition.offset) = sp * sp * I;
  P->block<3, 3>(L::kVelocity.offset, L::kVelocity.offset) = velocity_sigma * velocity_sigma * I;
  P->block<3, 3>(L::kGyroBias.offset, L::kGyroBias.offset) = P_gyro_bias;
  P->block<3, 3>(L::kAccelBias.offset, L::kAccelBias.offset) = sba * sba * I;
  P->block<3, 3>(L::kGravity.offset, L::kGravity.offset) =
      sba * sba * I + P_gravity_measured + sg * sg * I;
  P->block<3, 3>(L::kGravity.offset, L::kAccelBias.offset) = sba * sba * I;
  P->block<3, 3>(L::kAccelBias.offset, L::kGravity.offset) = sba * sba * I;
}

Status ImuInitializer::Initialize(ImuInitialization* result) const {
  if (!WindowFull()) {
    std::ostringstream os;
    os << "imu initializer: window not full (" << window_.size() << " samples";
    if (options_.window_duration_s > 0.0) {
      os << ", need " << options_.window_duration_s << " s";
    } else {
      os << ", need " << options_.window_num_samples;
    }
    os << ")";
    return Status::FailedPrecondition(os.str());
  }
  const WindowStatistics stats = ComputeStatistics(window_);
  const double g0 = options_.nominal_gravity_m_s2;
  const double raw_norm = stats.mean_accel.norm();
  UnitAndSign us;
  SWARMLIO_RETURN_IF_ERROR(DetermineUnitAndSign(stats.mean_accel, &us));
  const AccelerationUnit unit = us.unit;
  const double unit_factor = us.unit_factor;
  const double factor = us.sign * unit_factor;

  // 2. Static test on the window (standard deviations in SI units).
  const double gyro_std = std::sqrt(stats.cov_gyro.trace());
  const double accel_std = unit_factor * std::sqrt(stats.cov_accel.trace());
  const double gyro_mean_norm = stats.mean_gyro.norm();
  if (!(gyro_std <= options_.max_gyro_stddev_rad_s) ||
      !(accel_std <= options_.max_accel_stddev_m_s2) ||
      !(gyro_mean_norm <= options_.max_gyro_bias_rad_s)) {
    std::ostringstream os;
    os << "imu initializer: the start is not static enough over " << window_.size()
       << " samples: gyro std " << gyro_std << " rad/s (max " << options_.max_gyro_stddev_rad_s
       << "), acc std " << accel_std << " m/s^2 (max " << options_.max_accel_stddev_m_s2
       << "), |mean gyro| " << gyro_mean_norm << " rad/s (max " << options_.max_gyro_bias_rad_s
       << "); keep the IMU still during initialization";
    return Status::FailedPrecondition(os.str());
  }

  // 3. Gravity magnitude must match the unit (catches a wrong unit setting).
  const double g_norm = unit_factor * raw_norm;
  if (!(std::abs(g_norm / g0 - 1.0) <= options_.max_gravity_error_ratio)) {
    std::ostringstream os;
    os << "imu initializer: measured |g| = " << g_norm << " m/s^2 with acceleration unit "
       << config::EnumToString(unit) << " is not within " << options_.max_gravity_error_ratio * 100
       << " % of " << g0 << " m/s^2 (raw |mean acc| = " << raw_norm
       << "); check acceleration_unit (m_s2, g or auto)";
    return Status::FailedPrecondition(os.str());
  }

  // 4. State. G := the IMU frame at the last window sample.
  const double n = static_cast<double>(window_.size());
  ImuInitialization& r = *result;
  StartResult(us, g_norm, &r);
  r.state.gyro_bias = stats.mean_gyro;
  r.state.g_in_G = -factor * stats.mean_accel;
  r.gyro_stddev_rad_s = gyro_std;
  r.accel_stddev_m_s2 = accel_std;

  // 5. Covariance (docs/imu.md): pose/velocity floors, standard error of the
  // gyro mean, the b_a prior, and the gravity error. At rest (R = I)
  // a_m = -g + b_a, so g_hat = -mean(a_m) with b_a_hat = 0 has the error
  // g_hat - g = -b_a = b_a_hat - b_a: the errors of g and b_a are EQUAL (up to
  // the noise of the mean), hence Cov(g, b_a) = +Cov(b_a) and only their
  // difference, which the accelerometer measured, is known tightly.
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double sbg = options_.gyro_bias_stddev_floor_rad_s;
  SetInitialCovariance(options_.initial_velocity_stddev_m_s, stats.cov_gyro / n + sbg * sbg * I,
                       unit_factor * unit_factor * stats.cov_accel / n,
                       options_.gravity_stddev_floor_m_s2, &r.covariance);
  return Status::Ok();
}

Status ImuInitializer::InitializeInFlight(const InFlightCoarseSigmas& coarse,
                                         ImuInitialization* result) const {
  if (!WindowFull()) {
    return Status::FailedPrecondition("imu initializer: window not full (" +
                                      std::to_string(window_.size()) + " samples)");
  }
  // The mean specific force in G (the IMU frame at the window's end): each
  // sample rotated by the gyro integrated back from the end (bias unknown,
  // taken as 0; the error is a second-order effect on a coarse guess).
  const int n = static_cast<int>(window_.size());
  std::vector<Eigen::Matrix3d> R_G_bk(n, Eigen::Matrix3d::Identity());
  for (int k = n - 2; k >= 0; --k) {
    const double dt = static_cast<double>(window_[k + 1].stamp_ns - window_[k].stamp_ns) * 1e-9;
    const Eigen::Vector3d w =
        0.5 * (window_[k].angular_velocity_rad_s + window_[k + 1].angular_velocity_rad_s);
    R_G_bk[k] = R_G_bk[k + 1] * so3::Exp(-dt * w);
  }
  Eigen::Vector3d mean_in_G = Eigen::Vector3d::Zero();
  for (int k = 0; k < n; ++k) {
    mean_in_G += R_G_bk[k] * window_[k].linear_acceleration;
  }
  mean_in_G /= n;
  // Unit and sign as at rest: in flight the mean specific force is still
  // gravity plus the (smaller) mean acceleration of the flight.
  UnitAndSign us;
  SWARMLIO_RETURN_IF_ERROR(DetermineUnitAndSign(mean_in_G, &us));
  const double factor = us.sign * us.unit_factor;
  const double g0 = options_.nominal_gravity_m_s2;
  const double g_norm = us.unit_factor * mean_in_G.norm();
  constexpr double kMaxInFlightRatio = 0.5;
  if (!(std::abs(g_norm / g0 - 1.0) <= kMaxInFlightRatio)) {
    std::ostringstream os;
    os << "imu initializer (in flight): mean specific force " << g_norm << " m/s^2 with unit "
       << config::EnumToString(us.unit) << " is not within " << kMaxInFlightRatio * 100
       << " % of " << g0 << " m/s^2; check acceleration_unit";
    return Status::FailedPrecondition(os.str());
  }
  ImuInitialization& r = *result;
  StartResult(us, g_norm, &r);
  r.state.g_in_G = -factor * mean_in_G;
  r.in_flight = true;

  const double sbg = coarse.gyro_bias_rad_s;
  SetInitialCovariance(coarse.velocity_m_s, sbg * sbg * Eigen::Matrix3d::Identity(),
                       Eigen::Matrix3d::Zero(), coarse.gravity_m_s2, &r.covariance);
  return Status::Ok();
}

}  // namespace swarmlio::lio
