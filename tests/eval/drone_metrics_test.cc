#include "swarmlio/eval/drone_metrics.h"

#include <gtest/gtest.h>

#include "tests/eval/eval_test_util.h"

namespace swarmlio::eval {
namespace {

// The estimate in its own frame G_i = the ground truth moved rigidly, plus a
// small wobble so that the errors are not zero.
Trajectory EstimateOf(const Trajectory& reference, double wobble_m) {
  Trajectory estimate = reference;
  const Eigen::Isometry3d T_Gi_W =
      testing::MakePose(Eigen::Vector3d(0, 0, 0.8), Eigen::Vector3d(-3, 1, 0));
  for (size_t i = 0; i < estimate.size(); ++i) {
    Eigen::Isometry3d& T = estimate.T_G_b[i];
    T.translation().z() += wobble_m * ((i % 2 == 0) ? 1.0 : -1.0);
    T = T_Gi_W * T;
  }
  return estimate;
}

TEST(DroneMetrics, DriftIsThePositionDriftPerDistanceInTheWorldFrame) {
  // 101 poses 0.1 m apart along x; the estimate runs 1 % long, sits in its own
  // frame G_i and has its attitude 1 deg off about z. Segments of 2 m of the
  // estimate's path: starts 0-80 take 20 steps (2.02 m, error 0.02 m), 81 and
  // 82 the 19 and 18 left (error 0.019, 0.018 m; within 10 % of 2 m), 83 on
  // none: the drift is 1 % less a little, and neither G_i nor the attitude
  // offset enters it.
  Trajectory reference;
  Trajectory estimate;
  const Eigen::Isometry3d T_Gi_W =
      testing::MakePose(Eigen::Vector3d(0, 0, 0.8), Eigen::Vector3d(-3, 1, 0));
  const Eigen::Isometry3d attitude_offset =
      testing::MakePose(Eigen::Vector3d(0, 0, M_PI / 180.0), Eigen::Vector3d::Zero());
  for (int i = 0; i <= 100; ++i) {
    reference.stamps_s.push_back(0.1 * i);
    estimate.stamps_s.push_back(0.1 * i);
    reference.T_G_b.push_back(
        testing::MakePose(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.1 * i, 0, 0)));
    estimate.T_G_b.push_back(
        T_Gi_W * testing::MakePose(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.101 * i, 0, 0)) *
        attitude_offset);
  }
  DroneMetricsOptions options;
  options.drift_delta_m = 2.0;
  DroneMetrics metrics;
  ASSERT_TRUE(EvaluateDrone("uav0", reference, estimate, options, &metrics).ok());
  ASSERT_TRUE(metrics.has_drift);
  EXPECT_EQ(metrics.drift_translation.count, 83u);
  EXPECT_NEAR(metrics.drift_translation.mean, (81 * 0.02 + 0.019 + 0.018) / 83.0, 1e-9);
  MetricsTable table;
  ASSERT_TRUE(MakeDroneMetricsTable({metrics}, options, {}, &table).ok());
  EXPECT_NE(table.ToCsv().find(",83,0.998"), std::string::npos) << table.ToCsv();
  EXPECT_NE(table.ToMarkdown().find("drift [%] (2 m segments, W, SE(3))"), std::string::npos);

  // Too short for one segment: not an error, the cells are missing; a bad
  // segment length is.
  options.drift_delta_m = 50.0;
  ASSERT_TRUE(EvaluateDrone("uav0", reference, estimate, options, &metrics).ok());
  EXPECT_FALSE(metrics.has_drift);
  EXPECT_FALSE(metrics.drift_note.empty());
  options.drift_delta_m = 0.0;
  EXPECT_EQ(EvaluateDrone("uav0", reference, estimate, options, &metrics).code(),
            Status::Code::kInvalidArgument);
}

TEST(DroneMetrics, EvaluatesAndTabulates) {
  const Trajectory reference = testing::Curve(80);
  DroneMetricsOptions options;
  DroneMetrics uav0;
  ApeResult ape;
  ASSERT_TRUE(
      EvaluateDrone("uav0", reference, EstimateOf(reference, 0.01), options, &uav0, &ape).ok());
  EXPECT_EQ(uav0.ape_translation.count, 80u);
  EXPECT_NEAR(uav0.ape_translation.rmse, 0.01, 1e-3);  // SE(3) alignment removed T_Gi_W
  EXPECT_TRUE(uav0.has_rpe);
  EXPECT_GT(uav0.rpe_translation.count, 3u);
  EXPECT_EQ(ape.errors.size(), 80u);
  uav0.extra = {{"update_ms_mean", 3.5}};

  // Too short for one 1 m RPE pair: not an error, the cells are missing.
  DroneMetrics uav1;
  ASSERT_TRUE(
      EvaluateDrone("uav1", testing::Curve(5), EstimateOf(testing::Curve(5), 0.0), options, &uav1)
          .ok());
  EXPECT_FALSE(uav1.has_rpe);
  EXPECT_FALSE(uav1.rpe_note.empty());

  MetricsTable table;
  ASSERT_TRUE(MakeDroneMetricsTable({uav0, uav1}, options,
                                    {{"update_ms_mean", "update mean [ms]", 2}}, &table)
                  .ok());
  EXPECT_EQ(table.num_rows(), 2u);
  EXPECT_EQ(table.columns().size(), 13u);
  const std::string csv = table.ToCsv();
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "drone,ape_pairs,ape_rmse_m,ape_mean_m,ape_median_m,ape_std_m,ape_max_m,rpe_pairs,"
            "rpe_rmse_m,rpe_mean_m,drift_pairs,drift_percent,update_ms_mean");
  EXPECT_NE(table.ToMarkdown().find("RPE rmse [m] (delta 1 m)"), std::string::npos);
  EXPECT_NE(csv.find("uav1,5,"), std::string::npos) << csv;
  EXPECT_EQ(csv.substr(csv.size() - 9), ",0,,,0,,\n") << csv;  // rpe, drift and extra missing

  // Extra cells may be text (e.g. a metric that does not apply).
  uav1.extra = {{"update_ms_mean", std::string("n/a (frames differ)")}};
  ASSERT_TRUE(MakeDroneMetricsTable({uav1}, options, {{"update_ms_mean", "update [ms]", 2}}, &table)
                  .ok());
  EXPECT_NE(table.ToMarkdown().find("n/a (frames differ)"), std::string::npos)
      << table.ToMarkdown();
  EXPECT_NE(table.ToJson().find("\"n/a (frames differ)\""), std::string::npos) << table.ToJson();

  // An extra value without a column is an error.
  uav1.extra = {{"unknown", 1.0}};
  EXPECT_FALSE(MakeDroneMetricsTable({uav1}, options, {}, &table).ok());
}

TEST(DroneMetrics, NoOverlapIsAnError) {
  Trajectory late = testing::Curve(20, 500.0);
  DroneMetrics metrics;
  const Status status = EvaluateDrone("uav2", testing::Curve(20), late, {}, &metrics);
  EXPECT_FALSE(status.ok());
  EXPECT_EQ(status.message().rfind("uav2: ", 0), 0u) << status.message();
}

}  // namespace
}  // namespace swarmlio::eval
