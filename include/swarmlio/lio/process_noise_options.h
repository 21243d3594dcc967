// ProcessNoiseOptions: the covariance Q of the process noise w of the
// discrete IMU model (paper Sec. III-D, eq. (2)-(3); docs/imu.md).
//
// Convention (the same numbers mean the same thing as FAST-LIO's acc_cov,
// gyr_cov, b_acc_cov, b_gyr_cov): every entry is the VARIANCE of a white
// noise that enters the rate f(x, u, w) and is held constant over one IMU
// interval dt. With G = d x_{k+1} / d w (which carries the factor dt),
//
//   P_{k+1} = F P_k F^T + G Q G^T,   Q = diag(gyro_cov I3, accel_cov I3,
//                                             gyro_bias_cov I3, accel_bias_cov I3,
//                                             [teammate_rotation_cov I3,
//                                              teammate_translation_cov I3] per teammate)
//
// so one step adds ~ dt^2 * cov to the corresponding error (e.g. dt^2 *
// gyro_cov rad^2 to the attitude). The covariance therefore grows like
// cov * dt * T over a time T, i.e. these variances are rate dependent: the
// equivalent continuous-time density is sigma_c^2 = cov * dt (0.1 (rad/s)^2
// at 200 Hz = 5e-4 rad^2/s, sigma_c = 0.022 rad/s/sqrt(Hz)). Retune when the
// IMU rate changes. Defaults: FAST-LIO / Swarm-LIO2 mapping/{gyr,acc,b_gyr,
// b_acc}_cov. The teammate densities are this project's choice (the paper
// gives only their existence, n_R and n_p).
#pragma once

#include <string>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::lio {

struct ProcessNoiseOptions {
  double gyro_cov_rad2_s2 = 0.1;                 // n_g variance [(rad/s)^2] (FAST-LIO gyr_cov)
  double accel_cov_m2_s4 = 0.1;                  // n_a variance [(m/s^2)^2] (FAST-LIO acc_cov)
  double gyro_bias_cov_rad2_s4 = 1e-4;           // n_bg variance [(rad/s^2)^2] (FAST-LIO b_gyr_cov)
  double accel_bias_cov_m2_s6 = 1e-4;            // n_ba variance [(m/s^3)^2] (FAST-LIO b_acc_cov)
  double teammate_rotation_cov_rad2_s2 = 1e-6;   // n_R variance [(rad/s)^2]
  double teammate_translation_cov_m2_s2 = 1e-4;  // n_p variance [(m/s)^2]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("gyro_cov_rad2_s2", gyro_cov_rad2_s2,
      FieldSpec::InRange(0.0, 100.0, "(rad/s)^2", "gyro noise variance per IMU interval"));
    v("accel_cov_m2_s4", accel_cov_m2_s4,
      FieldSpec::InRange(0.0, 100.0, "(m/s^2)^2", "accelerometer noise variance per IMU interval"));
    v("gyro_bias_cov_rad2_s4", gyro_bias_cov_rad2_s4,
      FieldSpec::InRange(0.0, 1.0, "(rad/s^2)^2", "gyro bias random-walk variance"));
    v("accel_bias_cov_m2_s6", accel_bias_cov_m2_s6,
      FieldSpec::InRange(0.0, 1.0, "(m/s^3)^2", "accelerometer bias random-walk variance"));
    config::VisitExperimental(v, [&](auto& x) {
      x("teammate_rotation_cov_rad2_s2", teammate_rotation_cov_rad2_s2,
        FieldSpec::InRange(0.0, 1.0, "(rad/s)^2", "global-extrinsic rotation random walk (n_R)"));
      x("teammate_translation_cov_m2_s2", teammate_translation_cov_m2_s2,
        FieldSpec::InRange(0.0, 100.0, "(m/s)^2", "global-extrinsic translation random walk (n_p)"));
    });
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const { return config::ValidateFields(*this); }
};

}  // namespace swarmlio::lio
