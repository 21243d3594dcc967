// ImuSampleStepper: what each sample or target time means for the integral
// (the sample handling the propagator and the preintegration share).
#include "swarmlio/lio/imu_sample_stepper.h"

#include <gtest/gtest.h>

#include <limits>

namespace swarmlio::lio {
namespace {

using Action = ImuSampleStepper::Action;
constexpr int64_t kMs = 1000000;

ImuSample Sample(int64_t stamp_ns, double w, double a) {
  ImuSample s;
  s.stamp_ns = stamp_ns;
  s.angular_velocity_rad_s = Eigen::Vector3d(w, 0.0, 0.0);
  s.linear_acceleration = Eigen::Vector3d(0.0, 0.0, a);
  return s;
}

class ImuSampleStepperTest : public ::testing::Test {
 protected:
  ImuSampleStepperTest() : stepper_("test owner", /*max_gap_s=*/0.1, "note") {
    // Unit factor 2 (e.g. g-units at g = 2) so conversions are visible.
    stepper_.Reset(0, Sample(0, 1.0, 1.0), 2.0);
  }
  ImuSampleStepper stepper_;
};

TEST_F(ImuSampleStepperTest, ASampleAfterTheCurrentTimeIsAMidpointStep) {
  Action action;
  ImuStep step;
  ASSERT_TRUE(stepper_.Accept(Sample(10 * kMs, 3.0, 5.0), &action, &step).ok());
  ASSERT_EQ(action, Action::kStep);
  EXPECT_EQ(step.end_ns, 10 * kMs);
  EXPECT_DOUBLE_EQ(step.dt_s, 0.01);
  // The plain mean of the two samples (the integration stands on the last).
  EXPECT_DOUBLE_EQ(step.input.angular_velocity_rad_s.x(), 2.0);
  EXPECT_DOUBLE_EQ(step.input.specific_force_m_s2.z(), 2.0 * 3.0);
  EXPECT_EQ(stepper_.stamp_ns(), 0) << "Accept changes nothing";
  stepper_.Advance(step);
  stepper_.Hold(Sample(10 * kMs, 3.0, 5.0));
  EXPECT_EQ(stepper_.stamp_ns(), 10 * kMs);
  EXPECT_DOUBLE_EQ(stepper_.last_input().specific_force_m_s2.z(), 10.0);
}

TEST_F(ImuSampleStepperTest, DuplicatesAndEarlierStampsAreSkippedAndCounted) {
  Action action = Action::kStep;
  ImuStep step;
  ASSERT_TRUE(stepper_.Accept(Sample(0, 9.0, 9.0), &action, &step).ok());
  EXPECT_EQ(action, Action::kSkip);
  EXPECT_EQ(stepper_.num_skipped_duplicate(), 1);
  ASSERT_TRUE(stepper_.Accept(Sample(-kMs, 9.0, 9.0), &action, &step).ok());
  EXPECT_EQ(action, Action::kSkip);
  EXPECT_EQ(stepper_.num_skipped_out_of_order(), 1);
}

TEST_F(ImuSampleStepperTest, NonFiniteSamplesAndGapsAreRefusedAndCounted) {
  Action action;
  ImuStep step;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Status bad = stepper_.Accept(Sample(kMs, nan, 1.0), &action, &step);
  EXPECT_EQ(bad.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(bad.message().find("test owner"), std::string::npos) << bad.message();
  EXPECT_EQ(stepper_.num_rejected_non_finite(), 1);
  const Status gap = stepper_.Accept(Sample(200 * kMs, 1.0, 1.0), &action, &step);
  EXPECT_EQ(gap.code(), Status::Code::kOutOfRange);
  EXPECT_NE(gap.message().find("note"), std::string::npos) << gap.message();
  EXPECT_EQ(stepper_.num_gaps(), 1);
  EXPECT_EQ(stepper_.stamp_ns(), 0);
}

TEST_F(ImuSampleStepperTest, StepToHoldsOrInterpolatesAndThenTheSampleOnlyBecomesTheInput) {
  ImuStep step;
  bool needed = false;
  // Zero-order hold of the last input.
  ASSERT_TRUE(stepper_.StepTo(4 * kMs, nullptr, &step, &needed).ok());
  ASSERT_TRUE(needed);
  EXPECT_DOUBLE_EQ(step.input.angular_velocity_rad_s.x(), 1.0);
  // Towards the next sample at 10 ms: the input at the midpoint 2 ms.
  const ImuSample next = Sample(10 * kMs, 6.0, 1.0);
  ASSERT_TRUE(stepper_.StepTo(4 * kMs, &next, &step, &needed).ok());
  EXPECT_DOUBLE_EQ(step.input.angular_velocity_rad_s.x(), 1.0 + 0.2 * 5.0);
  stepper_.Advance(step);
  ASSERT_TRUE(stepper_.StepTo(4 * kMs, nullptr, &step, &needed).ok());
  EXPECT_FALSE(needed) << "already there";
  EXPECT_EQ(stepper_.StepTo(3 * kMs, nullptr, &step, &needed).code(), Status::Code::kOutOfRange);
  // A sample exactly at the reached time is only the new input.
  Action action;
  ASSERT_TRUE(stepper_.Accept(Sample(4 * kMs, 7.0, 1.0), &action, &step).ok());
  EXPECT_EQ(action, Action::kInputOnly);
  const ImuSample early = Sample(3 * kMs, 1.0, 1.0);
  EXPECT_EQ(stepper_.StepTo(5 * kMs, &early, &step, &needed).code(),
            Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace swarmlio::lio
