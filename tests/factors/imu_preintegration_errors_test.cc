// ImuPreintegration / ImuPreintegrationFactor options and input errors
// (fixture: imu_preintegration_test_fixture.h): invalid options, the sample
// handling shared with the propagator, unusable measurements.
#include "imu_preintegration_test_fixture.h"

namespace swarmlio {
namespace {

using namespace imu_preintegration_test;  // NOLINT(build/namespaces): the fixture

// --- options and input errors ----------------------------------------------

TEST(ImuPreintegration, RejectsInvalidOptions) {
  std::unique_ptr<lio::ImuPreintegration> pre;
  EXPECT_TRUE(lio::ImuPreintegration::Create(DefaultOptions(), &pre).ok());
  lio::ImuPreintegrationOptions options;
  options.process_noise.gyro_bias_cov_rad2_s4 = 0.0;  // valid for the filter, singular here
  Status status = lio::ImuPreintegration::Create(options, &pre);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(status.message().find("process_noise.gyro_bias_cov_rad2_s4"), std::string::npos)
      << status.message();
  options = lio::ImuPreintegrationOptions();
  options.gravity_stddev_floor_m_s2 = 0.0;
  status = lio::ImuPreintegration::Create(options, &pre);
  EXPECT_NE(status.message().find("gravity_stddev_floor_m_s2"), std::string::npos)
      << status.message();
  options = lio::ImuPreintegrationOptions();
  options.max_gap_s = -1.0;
  EXPECT_FALSE(lio::ImuPreintegration::Create(options, &pre).ok());
}

TEST(ImuPreintegration, HandlesSamplesLikeThePropagator) {
  Sampler s(13);
  const Motion m(&s);
  std::unique_ptr<lio::ImuPreintegration> pre;
  ASSERT_TRUE(lio::ImuPreintegration::Create(DefaultOptions(), &pre).ok());
  // The last sample must not be after the start.
  EXPECT_EQ(pre->Reset(kImuPeriodNs - 1, m.Sample(kImuPeriodNs), 1.0, m.b_g, m.b_a).code(),
            Status::Code::kInvalidArgument);
  ImuSample bad = m.Sample(0);
  bad.angular_velocity_rad_s.x() = std::nan("");
  EXPECT_EQ(pre->Reset(0, bad, 1.0, m.b_g, m.b_a).code(), Status::Code::kInvalidArgument);
  ASSERT_TRUE(pre->Reset(0, m.Sample(0), 1.0, m.b_g, m.b_a).ok());
  // Duplicate of the start sample, a non-finite sample, a gap.
  EXPECT_TRUE(pre->AddImu(m.Sample(0)).ok());
  EXPECT_EQ(pre->num_skipped_duplicate(), 1);
  bad.stamp_ns = kImuPeriodNs;
  EXPECT_EQ(pre->AddImu(bad).code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(pre->num_rejected_non_finite(), 1);
  EXPECT_EQ(pre->AddImu(m.Sample(30 * kImuPeriodNs)).code(), Status::Code::kOutOfRange);
  EXPECT_EQ(pre->num_gaps(), 1);
  EXPECT_EQ(pre->num_intervals(), 0);
  ASSERT_TRUE(pre->AddImu(m.Sample(kImuPeriodNs)).ok());
  ASSERT_TRUE(pre->AddImu(m.Sample(2 * kImuPeriodNs)).ok());
  // Out of order, back in time, next sample before the target.
  EXPECT_TRUE(pre->AddImu(m.Sample(kImuPeriodNs / 2)).ok());
  EXPECT_EQ(pre->num_skipped_out_of_order(), 1);
  EXPECT_EQ(pre->IntegrateTo(kImuPeriodNs).code(), Status::Code::kOutOfRange);
  const ImuSample early = m.Sample(2 * kImuPeriodNs + 100);
  EXPECT_EQ(pre->IntegrateTo(2 * kImuPeriodNs + 200, &early).code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(pre->num_intervals(), 2);
  // A sample at a reached target becomes the input without a step.
  const ImuSample at_target = m.Sample(3 * kImuPeriodNs);
  ASSERT_TRUE(pre->IntegrateTo(3 * kImuPeriodNs, &at_target).ok());
  ASSERT_TRUE(pre->AddImu(at_target).ok());
  EXPECT_EQ(pre->num_intervals(), 3);
  EXPECT_EQ(pre->num_skipped_out_of_order(), 1);
  EXPECT_EQ(pre->preintegrated().dt_s, ToSeconds(3 * kImuPeriodNs));
}

TEST(ImuPreintegrationFactor, CreateRejectsUnusableMeasurements) {
  Sampler s(14);
  const Motion m(&s);
  std::unique_ptr<ImuPreintegrationFactor> factor;
  // One IMU interval: dp and dv are collinear, the covariance is singular.
  Window one;
  one.t_k_ns = 5 * kImuPeriodNs;
  one.t_k1_ns = 6 * kImuPeriodNs;
  const auto pre = Preintegrate(m, one, m.b_g, m.b_a);
  ASSERT_EQ(pre->num_intervals(), 1);
  EXPECT_EQ(ImuPreintegrationFactor::Create(pre->preintegrated(), &factor).code(),
            Status::Code::kInvalidArgument);
  // Two intervals are enough.
  Window two = one;
  two.t_k1_ns = 6 * kImuPeriodNs + 1'000'000;
  EXPECT_TRUE(
      ImuPreintegrationFactor::Create(Preintegrate(m, two, m.b_g, m.b_a)->preintegrated(), &factor)
          .ok());
  PreintegratedImu zero_length;
  EXPECT_EQ(ImuPreintegrationFactor::Create(zero_length, &factor).code(),
            Status::Code::kInvalidArgument);
  PreintegratedImu non_finite = Preintegrate(m, Window(), m.b_g, m.b_a)->preintegrated();
  non_finite.delta_v.x() = std::nan("");
  EXPECT_EQ(ImuPreintegrationFactor::Create(non_finite, &factor).code(),
            Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace swarmlio
