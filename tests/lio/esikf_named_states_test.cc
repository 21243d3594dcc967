// EsikfUpdate and named states (StateKey, docs/architecture.md "Named
// states"): the filter holds one ego state, the one at the stamp of the scan
// being updated. A term naming it as EgoAt(that stamp) is the same term as
// Ego() (bit-identical update); a term naming the ego state at any other
// stamp (a loop closure to a past scan) is refused with an error naming the
// key and the stamp the filter holds, and the update returns the prior.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "esikf_test_util.h"
#include "factors/pose_information_factor.h"
#include "factors/relative_pose_factor.h"
#include "swarmlio/lio/esikf_update.h"
#include "swarmlio/lio/state_key.h"

namespace swarmlio::lio {
namespace {

using esikf_test::Sampler;

constexpr int64_t kScanEndNs = 1'700'000'000'123'456'789;

// A model with fixed residual blocks.
class FixedTerms final : public MeasurementModel {
 public:
  const char* name() const override { return "fixed"; }
  Status Linearize(const SwarmState&, std::vector<ResidualTerm>* terms) override {
    for (const ResidualTerm& t : terms_) terms->push_back(t);
    return Status::Ok();
  }
  std::vector<ResidualTerm> terms_;
};

// A pose measurement of the ego state: information 1e4 (1 cm, 0.01 rad)
// about a pose off the prior mean.
struct PoseProblem {
  explicit PoseProblem(unsigned seed) : sampler(seed) {
    x_hat = sampler.State(1);
    P = sampler.Covariance(x_hat.Dim(), 0.1);
    const EgoState measured = x_hat.ego.BoxPlus(sampler.Gaussian(18, 0.05));
    pose.Set(1e4 * Eigen::Matrix<double, 6, 6>::Identity(), Eigen::Matrix<double, 6, 1>::Zero(),
             measured.q_G_b, measured.p_b_in_G);
  }
  EsikfUpdateResult Run(const StateKey& key, std::optional<int64_t> stamp_ns) {
    FixedTerms model;
    model.terms_.push_back({&pose, {key}});
    return EsikfUpdate().Run(x_hat, P, {&model}, nullptr, nullptr, stamp_ns);
  }
  Sampler sampler;
  SwarmState x_hat;
  Eigen::MatrixXd P;
  PoseInformationFactor pose;
};

TEST(EsikfNamedStates, EgoAtTheScanStampIsTheEgoState) {
  PoseProblem pr(1);
  const EsikfUpdateResult ego = pr.Run(StateKey::Ego(), kScanEndNs);
  const EsikfUpdateResult named = pr.Run(StateKey::EgoAt(kScanEndNs), kScanEndNs);
  ASSERT_TRUE(ego.status.ok()) << ego.status.message();
  ASSERT_TRUE(named.status.ok()) << named.status.message();
  EXPECT_EQ(ego.iterations, named.iterations);
  EXPECT_TRUE(ego.state.ego.BoxMinus(named.state.ego).isZero(0.0));
  EXPECT_TRUE(ego.covariance == named.covariance);
  // The term was used: the update moved the state.
  EXPECT_GT(ego.state.ego.BoxMinus(pr.x_hat.ego).norm(), 1e-3);
}

TEST(EsikfNamedStates, EgoAtAnotherStampIsRefusedWithTheKey) {
  PoseProblem pr(2);
  const int64_t past_ns = kScanEndNs - 500'000'000;
  const EsikfUpdateResult result = pr.Run(StateKey::EgoAt(past_ns), kScanEndNs);
  EXPECT_EQ(result.status.code(), Status::Code::kInvalidArgument);
  const std::string& message = result.status.message();
  EXPECT_NE(message.find("EgoAt(" + std::to_string(past_ns) + " ns)"), std::string::npos)
      << message;
  EXPECT_NE(message.find("the filter holds only the state at " + std::to_string(kScanEndNs)),
            std::string::npos)
      << message;
  // A failed update returns the prior.
  EXPECT_TRUE(result.state.ego.BoxMinus(pr.x_hat.ego).isZero(0.0));
  EXPECT_TRUE(result.covariance == pr.P);
}

TEST(EsikfNamedStates, WithoutAStampEveryEgoAtIsRefused) {
  PoseProblem pr(3);
  const EsikfUpdateResult result = pr.Run(StateKey::EgoAt(kScanEndNs), std::nullopt);
  EXPECT_EQ(result.status.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(result.status.message().find("the filter holds only the state at the scan being"),
            std::string::npos)
      << result.status.message();
  EXPECT_TRUE(pr.Run(StateKey::Ego(), std::nullopt).status.ok());
}

// A loop closure to a past scan, as a back end with several states would
// take it: the filter cannot, and says which state it lacks.
TEST(EsikfNamedStates, ARelativePoseToAPastScanIsRefused) {
  PoseProblem pr(4);
  const int64_t past_ns = kScanEndNs - 2'000'000'000;
  const RelativePoseFactor loop(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1.0, 0.0, 0.0),
                                1e2 * RelativePoseFactor::Matrix6::Identity());
  FixedTerms model;
  model.terms_.push_back({&loop, {StateKey::EgoAt(past_ns), StateKey::Ego()}});
  const EsikfUpdateResult result =
      EsikfUpdate().Run(pr.x_hat, pr.P, {&model}, nullptr, nullptr, kScanEndNs);
  EXPECT_EQ(result.status.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(result.status.message().find(StateKey::EgoAt(past_ns).ToString()), std::string::npos)
      << result.status.message();
}

}  // namespace
}  // namespace swarmlio::lio
