#include "swarmlio/lio/imu_initializer.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <random>

#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/math/so3.h"

namespace swarmlio::lio {
namespace {

using L = ErrorStateLayout;

constexpr double kG = 9.81;
constexpr int64_t kPeriodNs = 5'000'000;  // 200 Hz

// A still IMU with attitude R_W_b (tilted), gyro bias and white noise.
struct StaticImu {
  Eigen::Matrix3d R_W_b = so3::Exp(Eigen::Vector3d(0.2, -0.35, 1.0));
  Eigen::Vector3d gyro_bias{0.01, -0.02, 0.004};  // [rad/s]
  double gyro_noise = 0.005;                      // [rad/s]
  double accel_noise = 0.02;                      // [m/s^2]
  double scale = 1.0;  // reported = scale * specific force (1/9.81 for g, -1 for flipped)
  Eigen::Vector3d SpecificForce() const { return R_W_b.transpose() * Eigen::Vector3d(0, 0, kG); }

  ImuSample Sample(int64_t k, std::mt19937& rng) const {
    std::normal_distribution<double> n(0.0, 1.0);
    ImuSample s;
    s.stamp_ns = 1'000'000'000 + k * kPeriodNs;
    s.angular_velocity_rad_s = gyro_bias + gyro_noise * Eigen::Vector3d(n(rng), n(rng), n(rng));
    s.linear_acceleration =
        scale * (SpecificForce() + accel_noise * Eigen::Vector3d(n(rng), n(rng), n(rng)));
    return s;
  }
};

std::unique_ptr<ImuInitializer> Make(const ImuInitializerOptions& options = {}) {
  std::unique_ptr<ImuInitializer> init;
  const Status s = ImuInitializer::Create(options, &init);
  EXPECT_TRUE(s.ok()) << s.message();
  return init;
}

void Feed(ImuInitializer* init, const StaticImu& imu, int n, std::mt19937& rng, int first = 0) {
  for (int k = first; k < first + n; ++k) ASSERT_TRUE(init->AddSample(imu.Sample(k, rng)).ok());
}

TEST(ImuInitializer, EstimatesGyroBiasAndGravityFromAStaticStart) {
  std::mt19937 rng(1);
  const StaticImu imu;
  auto init = Make();
  Feed(init.get(), imu, 200, rng);
  ASSERT_TRUE(init->WindowFull());
  ImuInitialization r;
  const Status s = init->Initialize(&r);
  ASSERT_TRUE(s.ok()) << s.message();
  const double n = 200;
  EXPECT_EQ(r.num_samples, 200);
  EXPECT_TRUE((r.state.gyro_bias - imu.gyro_bias).cwiseAbs().maxCoeff() <
              4.0 * imu.gyro_noise / std::sqrt(n));
  // G = the initial IMU frame: g_in_G = R_W_b^T g_in_W = -specific force.
  const Eigen::Vector3d g_true = -imu.SpecificForce();
  EXPECT_LT((r.state.g_in_G - g_true).cwiseAbs().maxCoeff(), 4.0 * imu.accel_noise / std::sqrt(n));
  EXPECT_NEAR(r.gravity_magnitude_m_s2, r.state.g_in_G.norm(), 1e-12);
  EXPECT_NEAR(r.gravity_magnitude_m_s2, kG, 0.01);
  EXPECT_TRUE(r.state.q_G_b.isApprox(Eigen::Quaterniond::Identity()));
  EXPECT_EQ(r.state.p_b_in_G, Eigen::Vector3d::Zero());
  EXPECT_EQ(r.state.v_b_in_G, Eigen::Vector3d::Zero());
  EXPECT_EQ(r.state.accel_bias, Eigen::Vector3d::Zero());
  EXPECT_EQ(r.acceleration_unit, AccelerationUnit::kMetersPerSecondSquared);
  EXPECT_TRUE(r.unit_detected);
  EXPECT_EQ(r.acceleration_to_m_s2, 1.0);
  EXPECT_EQ(r.stamp_ns, r.last_sample.stamp_ns);
  EXPECT_NEAR(r.gyro_stddev_rad_s, std::sqrt(3.0) * imu.gyro_noise, 0.2 * imu.gyro_noise);
  EXPECT_NEAR(r.accel_stddev_m_s2, std::sqrt(3.0) * imu.accel_noise, 0.2 * imu.accel_noise);
  EXPECT_NE(r.Summary().find("m_s2 (detected)"), std::string::npos) << r.Summary();

  // Covariance: symmetric positive definite; the errors of gravity and b_a are
  // equal (g_hat - g = b_a_hat - b_a at a static start), so the accelerometer
  // fixes only their difference: Var(dg - db_a) is the noise of the mean and
  // the floor, Var(dg + db_a) carries the b_a prior.
  const auto& P = r.covariance;
  EXPECT_EQ((P - P.transpose()).norm(), 0.0);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P).eigenvalues().minCoeff(), 0.0);
  const double sba2 = std::pow(ImuInitializerOptions().initial_accel_bias_stddev_m_s2, 2);
  EXPECT_EQ(P(L::kGravity.offset, L::kAccelBias.offset), sba2);
  EXPECT_GT(P(L::kGravity.offset, L::kGravity.offset), sba2);
  Eigen::VectorXd difference = Eigen::VectorXd::Zero(P.rows());
  difference(L::kGravity.offset) = 1.0;
  difference(L::kAccelBias.offset) = -1.0;
  const double var_difference = difference.dot(P * difference);
  const double floor2 = std::pow(ImuInitializerOptions().gravity_stddev_floor_m_s2, 2);
  EXPECT_LT(var_difference, floor2 + 10.0 * imu.accel_noise * imu.accel_noise / 200.0);
  Eigen::VectorXd sum = difference;
  sum(L::kAccelBias.offset) = 1.0;
  EXPECT_GT(sum.dot(P * sum), 3.9 * sba2);
}

TEST(ImuInitializer, DetectsGUnits) {
  std::mt19937 rng(2);
  StaticImu imu;
  imu.scale = 1.0 / kG;
  auto init = Make();
  Feed(init.get(), imu, 200, rng);
  ImuInitialization r;
  ASSERT_TRUE(init->Initialize(&r).ok());
  EXPECT_EQ(r.acceleration_unit, AccelerationUnit::kStandardGravity);
  EXPECT_TRUE(r.unit_detected);
  EXPECT_DOUBLE_EQ(r.acceleration_to_m_s2, kG);
  EXPECT_LT((r.state.g_in_G + imu.SpecificForce()).norm(), 0.02);
  EXPECT_NEAR(r.accel_stddev_m_s2, std::sqrt(3.0) * imu.accel_noise, 0.2 * imu.accel_noise);
}

TEST(ImuInitializer, ConfiguredUnitThatDoesNotMatchIsAnError) {
  std::mt19937 rng(3);
  StaticImu imu;
  imu.scale = 1.0 / kG;  // data in g
  ImuInitializerOptions options;
  options.acceleration_unit = AccelerationUnitSetting::kMetersPerSecondSquared;
  auto init = Make(options);
  Feed(init.get(), imu, 200, rng);
  ImuInitialization r;
  const Status s = init->Initialize(&r);
  EXPECT_EQ(s.code(), Status::Code::kFailedPrecondition);
  EXPECT_NE(s.message().find("acceleration_unit"), std::string::npos) << s.message();

  options.acceleration_unit = AccelerationUnitSetting::kStandardGravity;
  init = Make(options);
  Feed(init.get(), imu, 200, rng);
  ASSERT_TRUE(init->Initialize(&r).ok());
  EXPECT_FALSE(r.unit_detected);
  EXPECT_EQ(r.acceleration_unit, AccelerationUnit::kStandardGravity);
}

TEST(ImuInitializer, AutoRejectsImplausibleMagnitude) {
  std::mt19937 rng(4);
  StaticImu imu;
  imu.scale = 0.3;
  auto init = Make();
  Feed(init.get(), imu, 200, rng);
  ImuInitialization r;
  const Status s = init->Initialize(&r);
  EXPECT_EQ(s.code(), Status::Code::kFailedPrecondition);
  EXPECT_NE(s.message().find("cannot detect"), std::string::npos) << s.message();
}

// A sign-flipped IMU initializes with either sign: only acceleration_sign
// makes gravity point the right way (it is not detectable at rest).
TEST(ImuInitializer, NegativeSignConventionNeedsTheOption) {
  std::mt19937 rng(5);
  StaticImu imu;
  imu.scale = -1.0;
  ImuInitializerOptions options;
  options.acceleration_sign = -1;
  auto init = Make(options);
  Feed(init.get(), imu, 200, rng);
  ImuInitialization r;
  ASSERT_TRUE(init->Initialize(&r).ok());
  EXPECT_EQ(r.acceleration_to_m_s2, -1.0);
  EXPECT_LT((r.state.g_in_G + imu.SpecificForce()).norm(), 0.02);

  auto wrong = Make();  // default +1: also "succeeds", with gravity reversed
  Feed(wrong.get(), imu, 200, rng);
  ASSERT_TRUE(wrong->Initialize(&r).ok());
  EXPECT_LT((r.state.g_in_G - imu.SpecificForce()).norm(), 0.02);
}

// The sign at rest relative to up_axis (+z; the test IMU is tilted ~23 deg):
// always reported; a contradiction is a warning naming the option; auto (0)
// picks the sign from the data.
TEST(ImuInitializer, DetectsTheAccelerometerSignFromTheStaticStart) {
  std::mt19937 rng(15);
  StaticImu normal;
  StaticImu flipped;
  flipped.scale = -1.0;
  ImuInitialization r;

  auto init = Make();  // +1 configured, normal data: up, no warning
  Feed(init.get(), normal, 200, rng);
  ASSERT_TRUE(init->Initialize(&r).ok());
  EXPECT_EQ(r.reported_direction, SpecificForceDirection::kUp);
  EXPECT_LT(r.angle_to_up_axis_deg, 40.0);
  EXPECT_EQ(r.acceleration_sign, 1);
  EXPECT_FALSE(r.sign_detected);
  EXPECT_TRUE(r.sign_warning.empty()) << r.sign_warning;
  EXPECT_NE(r.Summary().find("points up (normal)"), std::string::npos) << r.Summary();

  init = Make();  // +1 configured, flipped data: down, warning naming the option
  Feed(init.get(), flipped, 200, rng);
  ASSERT_TRUE(init->Initialize(&r).ok());
  EXPECT_EQ(r.reported_direction, SpecificForceDirection::kDown);
  EXPECT_GT(r.angle_to_up_axis_deg, 140.0);
  EXPECT_EQ(r.acceleration_sign, 1);
  EXPECT_NE(r.sign_warning.find("acceleration_sign: -1"), std::string::npos) << r.sign_warning;
  EXPECT_NE(r.sign_warning.find("opposite"), std::string::npos) << r.sign_warning;
  EXPECT_NE(r.Summary().find("WARNING"), std::string::npos) << r.Summary();
  EXPECT_NE(r.Summary().find("down (sign-flipped driver)"), std::string::npos) << r.Summary();

  ImuInitializerOptions options;
  options.acceleration_sign = -1;  // -1 configured, normal data: warning the other way
  init = Make(options);
  Feed(init.get(), normal, 200, rng);
  ASSERT_TRUE(init->Initialize(&r).ok());
  EXPECT_NE(r.sign_warning.find("acceleration_sign: 1"), std::string::npos) << r.sign_warning;

  options.acceleration_sign = 0;  // auto: flipped data get -1, gravity points down again
  init = Make(options);
  Feed(init.get(), flipped, 200, rng);
  ASSERT_TRUE(init->Initialize(&r).ok());
  EXPECT_TRUE(r.sign_detected);
  EXPECT_EQ(r.acceleration_sign, -1);
  EXPECT_EQ(r.acceleration_to_m_s2, -1.0);
  EXPECT_TRUE(r.sign_warning.empty()) << r.sign_warning;
  EXPECT_LT((r.state.g_in_G + flipped.SpecificForce() * 1.0).norm(), 0.02);
  EXPECT_NE(r.Summary().find("-1 (detected)"), std::string::npos) << r.Summary();

  init = Make(options);  // auto, normal data: +1
  Feed(init.get(), normal, 200, rng);
  ASSERT_TRUE(init->Initialize(&r).ok());
  EXPECT_EQ(r.acceleration_sign, 1);
  EXPECT_LT((r.state.g_in_G + normal.SpecificForce()).norm(), 0.02);

  // A sideways mount (up_axis +x, gravity along z): auto cannot tell, assumes
  // +1 and says which option to set.
  options.up_axis = ImuUpAxis::kPlusX;
  init = Make(options);
  Feed(init.get(), normal, 200, rng);
  ASSERT_TRUE(init->Initialize(&r).ok());
  EXPECT_EQ(r.reported_direction, SpecificForceDirection::kUndetermined);
  EXPECT_EQ(r.acceleration_sign, 1);
  EXPECT_NE(r.sign_warning.find("imu_init.acceleration_sign"), std::string::npos)
      << r.sign_warning;
}

TEST(ImuInitializer, RefusesAMovingStartWithTheMeasuredSpread) {
  std::mt19937 rng(6);
  StaticImu imu;
  imu.gyro_noise = 0.2;
  auto init = Make();
  Feed(init.get(), imu, 200, rng);
  ImuInitialization r;
  Status s = init->Initialize(&r);
  EXPECT_EQ(s.code(), Status::Code::kFailedPrecondition);
  EXPECT_NE(s.message().find("not static"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("gyro std"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("(max 0.05)"), std::string::npos) << s.message();

  imu.gyro_noise = 0.005;
  imu.accel_noise = 1.0;  // shaking
  init = Make();
  Feed(init.get(), imu, 200, rng);
  s = init->Initialize(&r);
  EXPECT_EQ(s.code(), Status::Code::kFailedPrecondition);
  EXPECT_NE(s.message().find("acc std"), std::string::npos) << s.message();

  // The window slides: once the motion stops, 200 still samples initialize.
  imu.accel_noise = 0.02;
  Feed(init.get(), imu, 200, rng, 200);
  EXPECT_EQ(init->num_samples_in_window(), 200);
  s = init->Initialize(&r);
  EXPECT_TRUE(s.ok()) << s.message();
}

TEST(ImuInitializer, RejectsNonFiniteAndSkipsOutOfOrderSamples) {
  std::mt19937 rng(7);
  const StaticImu imu;
  auto init = Make();
  ImuSample bad = imu.Sample(0, rng);
  bad.angular_velocity_rad_s.y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(init->AddSample(bad).code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(init->num_rejected_non_finite(), 1);
  EXPECT_EQ(init->num_samples_in_window(), 0);
  ASSERT_TRUE(init->AddSample(imu.Sample(5, rng)).ok());
  ASSERT_TRUE(init->AddSample(imu.Sample(5, rng)).ok());
  ASSERT_TRUE(init->AddSample(imu.Sample(3, rng)).ok());
  EXPECT_EQ(init->num_skipped_out_of_order(), 2);
  EXPECT_EQ(init->num_samples_in_window(), 1);
  ImuInitialization r;
  EXPECT_EQ(init->Initialize(&r).code(), Status::Code::kFailedPrecondition);
}

TEST(ImuInitializer, DurationWindow) {
  std::mt19937 rng(8);
  const StaticImu imu;
  ImuInitializerOptions options;
  options.window_duration_s = 0.5;
  auto init = Make(options);
  Feed(init.get(), imu, 100, rng);  // spans 0.495 s
  EXPECT_FALSE(init->WindowFull());
  ASSERT_TRUE(init->AddSample(imu.Sample(100, rng)).ok());
  EXPECT_TRUE(init->WindowFull());
  EXPECT_EQ(init->num_samples_in_window(), 101);
  for (int k = 101; k < 300; ++k) ASSERT_TRUE(init->AddSample(imu.Sample(k, rng)).ok());
  EXPECT_EQ(init->num_samples_in_window(), 101);
  ImuInitialization r;
  EXPECT_TRUE(init->Initialize(&r).ok());
}

TEST(ImuInitializer, OptionsAreValidated) {
  std::unique_ptr<ImuInitializer> init;
  ImuInitializerOptions options;
  options.acceleration_sign = 2;  // 0 is auto
  Status s = ImuInitializer::Create(options, &init);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(s.message().find("acceleration_sign"), std::string::npos) << s.message();
  options = ImuInitializerOptions();
  options.window_num_samples = 1;
  EXPECT_FALSE(ImuInitializer::Create(options, &init).ok());
  EXPECT_EQ(ImuInitializerOptions().Validate(), "");
}

// Unit and sign chain end to end: raw g-unit, sign-flipped, noise-free data
// at rest stays at rest after 1 s of propagation.
TEST(ImuInitializer, PropagatorStartedFromTheResultStaysAtRest) {
  std::mt19937 rng(9);
  StaticImu imu;
  imu.gyro_noise = 0.0;
  imu.accel_noise = 0.0;
  imu.scale = -1.0 / kG;
  ImuInitializerOptions options;
  options.acceleration_sign = -1;
  auto init = Make(options);
  Feed(init.get(), imu, 200, rng);
  ImuInitialization r;
  ASSERT_TRUE(init->Initialize(&r).ok());
  std::unique_ptr<ImuPropagator> prop;
  ASSERT_TRUE(ImuPropagator::Create(ImuPropagatorOptions(), &prop).ok());
  ASSERT_TRUE(prop->Reset(r).ok());
  for (int k = 200; k < 400; ++k) ASSERT_TRUE(prop->AddImu(imu.Sample(k, rng)).ok());
  EXPECT_LT(prop->state().ego.p_b_in_G.norm(), 1e-9);
  EXPECT_LT(prop->state().ego.v_b_in_G.norm(), 1e-9);
  EXPECT_LT(so3::Log(prop->state().ego.q_G_b).norm(), 1e-12);
}

// In flight: a tilted IMU turning at 1 rad/s about the vertical at constant
// velocity fails the static test (its mean gyro is the turn), but the
// in-flight start accepts it; the specific force rotated back into G by the
// gyro gives g_in_G, the raw mean would be smeared by the turn. Unit and sign
// are detected as at rest.
TEST(ImuInitializer, InFlightStartRotatesTheSpecificForceIntoG) {
  const Eigen::Matrix3d R_tilt = so3::Exp(Eigen::Vector3d(0.15, -0.1, 0.0));
  const double yaw_rate = 1.0;  // [rad/s]
  const auto R_W_b = [&](double t) -> Eigen::Matrix3d {
    return so3::Exp(Eigen::Vector3d(0, 0, yaw_rate * t)) * R_tilt;
  };
  for (const double scale : {1.0, 1.0 / kG, -1.0}) {
    ImuInitializerOptions options;
    options.acceleration_unit = AccelerationUnitSetting::kAuto;
    options.acceleration_sign = 0;
    auto init = Make(options);
    for (int k = 0; k < 200; ++k) {
      const double t = k * 1e-9 * kPeriodNs;
      ImuSample s;
      s.stamp_ns = 1'000'000'000 + k * kPeriodNs;
      s.angular_velocity_rad_s = R_tilt.transpose() * Eigen::Vector3d(0, 0, yaw_rate);
      s.linear_acceleration = scale * R_W_b(t).transpose() * Eigen::Vector3d(0, 0, kG);
      ASSERT_TRUE(init->AddSample(s).ok());
    }
    ImuInitialization r;
    EXPECT_EQ(init->Initialize(&r).code(), Status::Code::kFailedPrecondition);
    const Status s = init->InitializeInFlight(ImuInitializer::InFlightCoarseSigmas(), &r);
    ASSERT_TRUE(s.ok()) << s.message();
    const double t_end = 199 * 1e-9 * kPeriodNs;
    const Eigen::Vector3d g_true = R_W_b(t_end).transpose() * Eigen::Vector3d(0, 0, -kG);
    EXPECT_LT((r.state.g_in_G - g_true).norm(), 0.01)
        << scale << ": " << r.state.g_in_G.transpose();
    EXPECT_TRUE(r.in_flight);
    EXPECT_EQ(r.acceleration_sign, scale < 0 ? -1 : 1);
    const AccelerationUnit unit = std::abs(scale) < 0.5 ? AccelerationUnit::kStandardGravity
                                                        : AccelerationUnit::kMetersPerSecondSquared;
    EXPECT_EQ(r.acceleration_unit, unit);
    EXPECT_EQ(r.state.v_b_in_G, Eigen::Vector3d::Zero());
    EXPECT_EQ(r.state.gyro_bias, Eigen::Vector3d::Zero());
    // The coarse sigmas, and the g - b_a correlation of a static start.
    const ImuInitializer::InFlightCoarseSigmas coarse;
    EXPECT_NEAR(r.covariance(L::kVelocity.offset, L::kVelocity.offset),
                coarse.velocity_m_s * coarse.velocity_m_s, 1e-12);
    EXPECT_NEAR(r.covariance(L::kGravity.offset, L::kAccelBias.offset),
                r.covariance(L::kAccelBias.offset, L::kAccelBias.offset), 1e-12);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(r.covariance));
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  }
}

}  // namespace
}  // namespace swarmlio::lio
