// Reproduces every figure of /work/shared/data/evo/EXPECTED.md (evo 1.36.5 on
// the public TUM trajectories copied to tests/eval/data): pair counts exactly,
// statistics and Sim(3) scales to 1e-6 relative.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>
#include <string>

#include "swarmlio/eval/ape.h"
#include "swarmlio/eval/rpe.h"
#include "swarmlio/eval/trajectory_io.h"
#include "tests/eval/eval_test_util.h"

namespace swarmlio::eval {
namespace {

constexpr double kRelativeTolerance = 1e-6;
constexpr double kNoScale = std::numeric_limits<double>::quiet_NaN();

const char* const kFr1Reference = "freiburg1_xyz-groundtruth.txt";
const char* const kFr1Estimate = "freiburg1_xyz-rgbdslam.txt";
const char* const kFr2Reference = "fr2_desk_groundtruth.txt";
const char* const kFr2Estimate = "fr2_desk_ORB.txt";

enum class Metric { kApe, kRpe };

struct EvoCase {
  const char* name;
  const char* reference;
  const char* estimate;
  Metric metric;
  PoseRelation relation;
  Alignment alignment;
  double delta;
  DeltaUnit delta_unit;
  size_t pairs;
  double rmse, mean, median, std, min, max;
  double scale;  // kNoScale: not reported
};

// The rows of EXPECTED.md, in its order.
const EvoCase kCases[] = {
    {"fr1 APE trans, no alignment", kFr1Reference, kFr1Estimate, Metric::kApe,
     PoseRelation::kTranslation, Alignment::kNone, 1, DeltaUnit::kFrames, 785, 0.0200794184,
     0.0180625184, 0.0165177562, 0.00877088766, 0.0012561023, 0.0432894339, kNoScale},
    {"fr1 APE trans, SE(3)", kFr1Reference, kFr1Estimate, Metric::kApe, PoseRelation::kTranslation,
     Alignment::kSe3, 1, DeltaUnit::kFrames, 785, 0.0134700888, 0.0120244987, 0.0111831868,
     0.00607080921, 0.000955046181, 0.0347595459, 1.0},
    {"fr1 APE trans, Sim(3)", kFr1Reference, kFr1Estimate, Metric::kApe, PoseRelation::kTranslation,
     Alignment::kSim3, 1, DeltaUnit::kFrames, 785, 0.0133893849, 0.0119868896, 0.0111338991,
     0.00596574432, 0.000732706705, 0.0348461449, 1.0080013899},
    {"fr1 APE angle_deg, SE(3)", kFr1Reference, kFr1Estimate, Metric::kApe,
     PoseRelation::kRotationAngleDeg, Alignment::kSe3, 1, DeltaUnit::kFrames, 785, 2.0576996,
     2.02469548, 2.00084109, 0.367063833, 0.741958398, 3.63959083, 1.0},
    {"fr1 RPE trans, 1 frame", kFr1Reference, kFr1Estimate, Metric::kRpe,
     PoseRelation::kTranslation, Alignment::kNone, 1, DeltaUnit::kFrames, 784, 0.00576437085,
     0.00481560947, 0.0041388578, 0.00316826083, 0.000171061153, 0.0208658145, kNoScale},
    {"fr1 RPE angle_deg, 1 frame", kFr1Reference, kFr1Estimate, Metric::kRpe,
     PoseRelation::kRotationAngleDeg, Alignment::kNone, 1, DeltaUnit::kFrames, 784, 0.353613161,
     0.300306581, 0.262139, 0.186703575, 0.0169371435, 1.63329606, kNoScale},
    {"fr1 RPE trans, 10 frames", kFr1Reference, kFr1Estimate, Metric::kRpe,
     PoseRelation::kTranslation, Alignment::kNone, 10, DeltaUnit::kFrames, 78, 0.014610132,
     0.012477077, 0.0119812341, 0.00760121754, 0.0010349715, 0.0431538617, kNoScale},
    {"fr1 RPE trans, 0.1 m", kFr1Reference, kFr1Estimate, Metric::kRpe, PoseRelation::kTranslation,
     Alignment::kNone, 0.1, DeltaUnit::kMeters, 79, 0.0143844511, 0.0126441129, 0.0116302056,
     0.00685848703, 0.00154130558, 0.038654181, kNoScale},
    {"fr2 APE trans, SE(3)", kFr2Reference, kFr2Estimate, Metric::kApe, PoseRelation::kTranslation,
     Alignment::kSe3, 1, DeltaUnit::kFrames, 2174, 0.00811897756, 0.00749177687, 0.00741462983,
     0.00312906951, 0.000349636198, 0.0242995937, 1.0},
    {"fr2 APE trans, Sim(3)", kFr2Reference, kFr2Estimate, Metric::kApe, PoseRelation::kTranslation,
     Alignment::kSim3, 1, DeltaUnit::kFrames, 2174, 0.00612316303, 0.00558619732, 0.00530522508,
     0.00250749377, 0.00018979581, 0.0214767856, 0.9969698308},
    {"fr2 RPE trans, 1 frame", kFr2Reference, kFr2Estimate, Metric::kRpe,
     PoseRelation::kTranslation, Alignment::kNone, 1, DeltaUnit::kFrames, 2173, 0.00349032137,
     0.00303808742, 0.00275028839, 0.00171824566, 0.000131969006, 0.0194846789, kNoScale},
};

// Readable test names in ctest and failure messages.
void PrintTo(const EvoCase& c, std::ostream* os) { *os << c.name; }

Trajectory Load(const std::string& name) {
  // The public fr2_desk ground truth repeats one stamp (line 10863); evo
  // keeps such poses, and so does this option.
  TrajectoryReadOptions options;
  options.allow_duplicate_stamps = true;
  Trajectory trajectory;
  const Status status = ReadTumTrajectory(testing::DataFile(name), options, &trajectory);
  EXPECT_TRUE(status.ok()) << status.message();
  return trajectory;
}

double RelativeDifference(double actual, double expected) {
  return std::abs(actual - expected) / std::abs(expected);
}

class EvoReference : public ::testing::TestWithParam<EvoCase> {};

TEST_P(EvoReference, ReproducesEvo) {
  const EvoCase& c = GetParam();
  const Trajectory reference = Load(c.reference);
  const Trajectory estimate = Load(c.estimate);
  ErrorStatistics s;
  double scale = kNoScale;
  if (c.metric == Metric::kApe) {
    ApeOptions options;
    options.relation = c.relation;
    options.alignment = c.alignment;
    ApeResult result;
    const Status status = ComputeApe(reference, estimate, options, &result);
    ASSERT_TRUE(status.ok()) << status.message();
    s = result.statistics;
    scale = result.alignment_transform.scale;
  } else {
    RpeOptions options;
    options.relation = c.relation;
    options.alignment = c.alignment;
    options.delta = c.delta;
    options.delta_unit = c.delta_unit;
    RpeResult result;
    const Status status = ComputeRpe(reference, estimate, options, &result);
    ASSERT_TRUE(status.ok()) << status.message();
    s = result.statistics;
  }
  EXPECT_EQ(s.count, c.pairs);
  const std::pair<const char*, std::pair<double, double>> figures[] = {
      {"rmse", {s.rmse, c.rmse}},  {"mean", {s.mean, c.mean}}, {"median", {s.median, c.median}},
      {"std", {s.std, c.std}},     {"min", {s.min, c.min}},    {"max", {s.max, c.max}},
      {"scale", {scale, c.scale}},
  };
  double worst = 0.0;
  for (const auto& [name, values] : figures) {
    if (std::isnan(values.second)) continue;
    const double relative = RelativeDifference(values.first, values.second);
    worst = std::max(worst, relative);
    EXPECT_LE(relative, kRelativeTolerance)
        << c.name << " " << name << ": " << values.first << " vs evo " << values.second;
  }
  // The report table in the hand-over quotes these lines.
  std::printf("[evo] %-30s pairs %zu  max relative difference %.2e\n", c.name, s.count, worst);
}

INSTANTIATE_TEST_SUITE_P(Expected,
                         EvoReference,
                         ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<EvoCase>& param_info) {
                           std::string name = param_info.param.name;
                           for (char& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace swarmlio::eval
