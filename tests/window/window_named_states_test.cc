// The fixed-lag window and named states (lio::StateKey, docs/architecture.md
// "Named states", docs/window.md "The window"): a relative-pose term between
// two window states, named lio::StateKey::EgoAt(stamp), handed to the window with
// the newest scan like the component's observations.
//
// The seam is WindowSmoother itself (internal to swarmlio_lio, driven here
// as lio::Odometry drives it): a drone at rest 1 m above a floor, so the
// point-to-plane terms hold height, roll and pitch and the IMU factors say
// "constant velocity"; x, y and yaw are held by the first state's prior and
// whatever else the window holds. The loop closure says that the state at t2
// is 5 cm ahead (x of body t0) of the state at t0, 1 mm / 1 mrad: the
// window must move the t2 state there, with the t1 state half way (constant
// velocity 0.25 m/s), residual ~0; when the t0 state leaves, the term's
// information moves into the marginalization prior; a key naming a state
// the window does not hold is refused with the key in the error.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "factors/relative_pose_factor.h"
#include "src/window/window_smoother.h"
#include "swarmlio/lio/state_key.h"

namespace swarmlio::window {
namespace {

constexpr int64_t kT0Ns = 1'000'000'000;
constexpr int64_t kScanPeriodNs = 100'000'000;  // 10 Hz scans
constexpr int64_t kImuPeriodNs = 5'000'000;     // 200 Hz IMU
constexpr double kGravity = 9.81;

int64_t ScanEnd(int k) { return kT0Ns + k * kScanPeriodNs; }

// A model whose terms the window takes over (as the component's mutual
// observations); the window never linearizes it.
class KeptTerms final : public lio::MeasurementModel {
 public:
  const char* name() const override { return "loop_closure"; }
  Status Linearize(const SwarmState&, std::vector<lio::ResidualTerm>*) override {
    return Status::FailedPrecondition("a window-only model");
  }
  bool ReleaseTerms(std::vector<lio::OwnedResidualTerm>* terms) override {
    for (lio::OwnedResidualTerm& t : terms_) terms->push_back(std::move(t));
    terms_.clear();
    return true;
  }
  std::vector<lio::OwnedResidualTerm> terms_;
};

// The measured pose of the body at t2 in the body at t0: 5 cm along x.
std::unique_ptr<RelativePoseFactor> LoopClosure() {
  RelativePoseFactor::Matrix6 L = RelativePoseFactor::Matrix6::Identity();
  L.topLeftCorner<3, 3>() *= 1e3;      // 1 mrad
  L.bottomRightCorner<3, 3>() *= 1e3;  // 1 mm
  return std::make_unique<RelativePoseFactor>(Eigen::Quaterniond::Identity(),
                                              Eigen::Vector3d(0.05, 0.0, 0.0), L);
}

EgoState AtRest(double x_m, double v_x_m_s) {
  EgoState ego;
  ego.p_b_in_G = Eigen::Vector3d(x_m, 0.0, 1.0);
  ego.v_b_in_G = Eigen::Vector3d(v_x_m_s, 0.0, 0.0);
  ego.g_in_G = Eigen::Vector3d(0.0, 0.0, -kGravity);
  return ego;
}

ImuSample Sample(int64_t stamp_ns) {
  ImuSample s;
  s.stamp_ns = stamp_ns;
  s.linear_acceleration = Eigen::Vector3d(0.0, 0.0, kGravity);  // level, no acceleration
  return s;
}

class FloorWindow {
 public:
  explicit FloorWindow(int size) : map_(lio::LocalMapOptions()) {
    std::vector<Eigen::Vector3d> floor_in_G;
    for (double x = -8.0; x <= 8.0; x += 0.25) {
      for (double y = -8.0; y <= 8.0; y += 0.25) floor_in_G.emplace_back(x, y, 0.0);
    }
    map_.Insert(floor_in_G);
    for (double x = -5.0; x <= 5.0; x += 0.5) {
      for (double y = -5.0; y <= 5.0; y += 0.5) floor_in_b_.emplace_back(x, y, -1.0);
    }
    lio::WindowOptions options;
    options.size = size;
    lio::ScanAssociationOptions association;
    association.max_normal_stddev_rad = 0.0;  // a floor: no noisy-plane handling
    association.tilt_projection_sigma = 0.0;
    status_ = WindowSmoother::Create(options, lio::ImuPropagatorOptions(), association,
                                     lio::EsikfUpdateOptions(), &map_, &window_);
  }

  // Adds the state at scan end k (IMU at rest since the previous state,
  // whose estimate is `previous`) at the prediction `x_pred`.
  Status Add(int k,
             const EgoState& previous,
             const EgoState& x_pred,
             std::vector<lio::MeasurementModel*> models,
             std::string* model_error) {
    if (k > 0) {
      window_->StartInterval(ScanEnd(k - 1), Sample(ScanEnd(k - 1)), 1.0, previous);
      for (int64_t t = ScanEnd(k - 1) + kImuPeriodNs; t <= ScanEnd(k); t += kImuPeriodNs) {
        window_->AddImu(Sample(t));
      }
      window_->IntegrateTo(ScanEnd(k), nullptr);
    }
    WindowStateInput input;
    input.stamp_ns = ScanEnd(k);
    input.x_pred.ego = x_pred;
    Eigen::VectorXd sigma(18);
    sigma << 0.01, 0.01, 0.01, 0.01, 0.01, 0.01,  // rotation [rad], position [m]
        1.0, 1.0, 1.0,                            // velocity [m/s]
        1e-3, 1e-3, 1e-3, 0.01, 0.01, 0.01,       // biases
        1e-3, 1e-3, 1e-3;                         // gravity [m/s^2]
    input.P_pred = sigma.cwiseAbs2().asDiagonal();
    input.points_in_b = floor_in_b_;
    input.use_planes = true;
    input.models = std::move(models);
    double marginalize_s = 0.0;
    return window_->AddState(std::move(input), &leaving_, &marginalize_s, model_error);
  }

  WindowSmoother& window() { return *window_; }
  const Status& status() const { return status_; }
  const std::vector<LeavingScan>& leaving() const { return leaving_; }

 private:
  lio::LocalMap map_;
  std::vector<Eigen::Vector3d> floor_in_b_;
  std::unique_ptr<WindowSmoother> window_;
  std::vector<LeavingScan> leaving_;
  Status status_;
};

// States t0, t1, t2 at rest (K = 3), the loop closure t0 -> t2 given with
// the t2 scan when `with_term`; the three estimates after the t2 solve.
std::vector<EgoState> SolveThreeStates(bool with_term, const RelativePoseFactor** factor) {
  FloorWindow w(3);
  EXPECT_TRUE(w.status().ok()) << w.status().message();
  std::string model_error;
  EgoState newest = AtRest(0.0, 0.0);
  for (int k = 0; k < 3; ++k) {
    KeptTerms loop;
    if (k == 2 && with_term) {
      std::unique_ptr<RelativePoseFactor> cost = LoopClosure();
      *factor = cost.get();
      loop.terms_.push_back(
          {std::move(cost), {lio::StateKey::EgoAt(ScanEnd(0)), lio::StateKey::Ego()}});
    }
    EXPECT_TRUE(w.Add(k, newest, AtRest(0.0, 0.0), {&loop}, &model_error).ok());
    EXPECT_EQ(model_error, "");
    const WindowSolveResult result = w.window().Solve();
    EXPECT_TRUE(result.status.ok()) << result.status.message();
    EXPECT_TRUE(result.updated);
    newest = result.state.ego;
  }
  std::vector<LeavingScan> scans;
  w.window().TakeScansForMap(&scans);
  std::vector<EgoState> states;
  for (const LeavingScan& s : scans) states.push_back(s.state);
  return states;
}

TEST(WindowNamedStates, ARelativePoseTermBetweenWindowStatesPullsThemToTheMeasurement) {
  const RelativePoseFactor* factor = nullptr;
  const std::vector<EgoState> control = SolveThreeStates(false, &factor);
  ASSERT_EQ(control.size(), 3u);
  for (const EgoState& s : control) {
    EXPECT_LT((s.p_b_in_G - Eigen::Vector3d(0.0, 0.0, 1.0)).norm(), 1e-4);
    EXPECT_LT(s.v_b_in_G.norm(), 1e-3);
  }

  const std::vector<EgoState> states = SolveThreeStates(true, &factor);
  ASSERT_EQ(states.size(), 3u);
  ASSERT_NE(factor, nullptr);
  // At the solution the term is satisfied to well within its 1 mm / 1 mrad.
  // Evaluated with an identical factor of the test's own: the window owned
  // the one it solved with and may have freed it (ASan caught a read of it).
  const Eigen::Matrix<double, 6, 1> r = LoopClosure()->Residual(states[0], states[2]);
  EXPECT_LT(r.norm(), 0.05) << r.transpose();
  const Eigen::Vector3d p_2_in_0 =
      states[0].R_G_b().transpose() * (states[2].p_b_in_G - states[0].p_b_in_G);
  EXPECT_NEAR(p_2_in_0.x(), 0.05, 1e-4);
  // The prior holds the t0 state; the IMU factors (constant velocity) put
  // the t1 state half way and give every state the velocity 0.05 m / 0.2 s.
  EXPECT_LT((states[0].p_b_in_G - Eigen::Vector3d(0.0, 0.0, 1.0)).norm(), 1e-3);
  EXPECT_NEAR(states[1].p_b_in_G.x(), 0.5 * (states[0].p_b_in_G.x() + states[2].p_b_in_G.x()),
              1e-4);
  for (const EgoState& s : states) {
    EXPECT_NEAR(s.v_b_in_G.x(), 0.25, 5e-3);
    EXPECT_NEAR(s.p_b_in_G.z(), 1.0, 1e-4);  // the floor
  }
}

TEST(WindowNamedStates, TheTermMovesIntoThePriorWhenItsFirstStateLeaves) {
  FloorWindow w(3);
  ASSERT_TRUE(w.status().ok()) << w.status().message();
  std::string model_error;
  EgoState newest = AtRest(0.0, 0.0);
  for (int k = 0; k < 5; ++k) {
    KeptTerms loop;
    if (k == 2) {
      loop.terms_.push_back(
          {LoopClosure(), {lio::StateKey::EgoAt(ScanEnd(0)), lio::StateKey::Ego()}});
    }
    // The prediction of a constant-velocity propagation from the newest estimate.
    const EgoState x_pred =
        k == 0 ? newest
               : AtRest(newest.p_b_in_G.x() + 0.1 * newest.v_b_in_G.x(), newest.v_b_in_G.x());
    ASSERT_TRUE(w.Add(k, newest, x_pred, {&loop}, &model_error).ok());
    EXPECT_EQ(model_error, "");
    const WindowSolveResult result = w.window().Solve();
    ASSERT_TRUE(result.status.ok()) << result.status.message();
    newest = result.state.ego;
    if (k >= 2) {
      // The term (k = 2) and then the prior it went into (k = 3: t0 left
      // with it; k = 4: t1 too) keep the velocity and the positions.
      SCOPED_TRACE(k);
      EXPECT_NEAR(newest.v_b_in_G.x(), 0.25, 5e-3);
      EXPECT_NEAR(newest.p_b_in_G.x(), 0.025 * k, 1e-3);
    }
  }
  EXPECT_EQ(w.window().counters().marginalizations, 2);
  ASSERT_EQ(w.leaving().size(), 2u);
  EXPECT_NEAR(w.leaving()[0].state.p_b_in_G.x(), 0.0, 1e-3);    // t0
  EXPECT_NEAR(w.leaving()[1].state.p_b_in_G.x(), 0.025, 1e-3);  // t1
}

TEST(WindowNamedStates, AKeyNamingAStateNotInTheWindowIsRefused) {
  FloorWindow w(2);
  ASSERT_TRUE(w.status().ok()) << w.status().message();
  std::string model_error;
  EgoState newest = AtRest(0.0, 0.0);
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(w.Add(k, newest, AtRest(0.0, 0.0), {}, &model_error).ok());
    newest = w.window().Solve().state.ego;
  }
  // The window holds t1, t2; t0 was marginalized, t0 + 50 ms was never a state.
  const int64_t marginalized_ns = ScanEnd(0);
  const int64_t never_ns = ScanEnd(0) + kScanPeriodNs / 2;
  for (int64_t stamp_ns : {marginalized_ns, never_ns}) {
    SCOPED_TRACE(stamp_ns);
    KeptTerms loop;
    loop.terms_.push_back({LoopClosure(), {lio::StateKey::EgoAt(stamp_ns), lio::StateKey::Ego()}});
    const int k = stamp_ns == marginalized_ns ? 3 : 4;
    EXPECT_TRUE(w.Add(k, newest, AtRest(0.0, 0.0), {&loop}, &model_error).ok());
    EXPECT_NE(model_error.find("loop_closure names " + lio::StateKey::EgoAt(stamp_ns).ToString() +
                               ", which the window does not hold"),
              std::string::npos)
        << model_error;
    // The window goes on without the term.
    const WindowSolveResult result = w.window().Solve();
    EXPECT_TRUE(result.status.ok()) << result.status.message();
    EXPECT_LT(result.state.ego.v_b_in_G.norm(), 1e-3);
    newest = result.state.ego;
  }
  // A state in the window is accepted (t4: the window holds t3, t4, t5 while
  // it takes t5's terms, then marginalizes t3).
  KeptTerms loop;
  loop.terms_.push_back({LoopClosure(), {lio::StateKey::EgoAt(ScanEnd(4)), lio::StateKey::Ego()}});
  EXPECT_TRUE(w.Add(5, newest, AtRest(0.0, 0.0), {&loop}, &model_error).ok());
  EXPECT_EQ(model_error, "");
}

}  // namespace
}  // namespace swarmlio::window
