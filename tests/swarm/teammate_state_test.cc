// The extrinsic composition of identification through teammates
// (src/swarm/teammate_state.h): T_Gi_Gk = T_Gi_Gj T_Gj_Gk and its error
// Jacobians, checked against numeric differentiation on the manifold at
// random, near-identity and near-pi rotations; a flipped block is caught.
// And the rules for which teammate may relay (CanRelay) and which loops are
// refused (ChainPassesThrough).
#include "src/swarm/teammate_state.h"

#include <gtest/gtest.h>

#include <random>

#include "swarmlio/math/so3.h"

namespace swarmlio::swarm::internal {
namespace {

GlobalExtrinsic RandomExtrinsic(std::mt19937* rng, double angle) {
  std::normal_distribution<double> n;
  const Eigen::Vector3d axis = Eigen::Vector3d(n(*rng), n(*rng), n(*rng)).normalized();
  GlobalExtrinsic T;
  T.q_Ga_Gb = so3::ExpQuaternion(axis * angle);
  T.p_Gb_in_Ga = 5.0 * Eigen::Vector3d(n(*rng), n(*rng), n(*rng));
  return T;
}

// d(T_ik)/d(dx) by central differences, dx applied to T_ij (first) or T_jk.
Eigen::Matrix<double, 6, 6> Numeric(const GlobalExtrinsic& T_ij, const GlobalExtrinsic& T_jk,
                                    bool first) {
  GlobalExtrinsic T_ik;
  Eigen::Matrix<double, 6, 6> J1, J2;
  ComposeExtrinsic(T_ij, T_jk, &T_ik, &J1, &J2);
  Eigen::Matrix<double, 6, 6> J;
  const double h = 1e-6;
  for (int c = 0; c < 6; ++c) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d[c] = h;
    GlobalExtrinsic plus, minus;
    ComposeExtrinsic(first ? T_ij.BoxPlus(d) : T_ij, first ? T_jk : T_jk.BoxPlus(d), &plus, &J1, &J2);
    ComposeExtrinsic(first ? T_ij.BoxPlus(-d) : T_ij, first ? T_jk : T_jk.BoxPlus(-d), &minus, &J1,
                     &J2);
    J.col(c) = (plus.BoxMinus(T_ik) - minus.BoxMinus(T_ik)) / (2.0 * h);
  }
  return J;
}

TEST(ComposeExtrinsic, ComposesAndItsJacobiansMatchNumericDifferentiation) {
  std::mt19937 rng(3);
  for (const double angle : {0.7, 2.5, 1e-9, M_PI - 1e-4}) {
    SCOPED_TRACE(angle);
    for (int trial = 0; trial < 5; ++trial) {
      const GlobalExtrinsic T_ij = RandomExtrinsic(&rng, angle);
      const GlobalExtrinsic T_jk = RandomExtrinsic(&rng, 1.3);
      GlobalExtrinsic T_ik;
      Eigen::Matrix<double, 6, 6> J_ij, J_jk;
      ComposeExtrinsic(T_ij, T_jk, &T_ik, &J_ij, &J_jk);
      // The composition itself: a point of G_k mapped to G_i both ways.
      const Eigen::Vector3d x_in_Gk(0.3, -1.2, 2.0);
      EXPECT_LT((T_ik.T_Ga_Gb() * x_in_Gk - T_ij.T_Ga_Gb() * (T_jk.T_Ga_Gb() * x_in_Gk)).norm(),
                1e-12);
      EXPECT_LT((J_ij - Numeric(T_ij, T_jk, true)).norm(), 1e-6);
      EXPECT_LT((J_jk - Numeric(T_ij, T_jk, false)).norm(), 1e-6);
    }
  }
}

TEST(ComposeExtrinsic, AFlippedBlockIsCaught) {
  std::mt19937 rng(4);
  const GlobalExtrinsic T_ij = RandomExtrinsic(&rng, 0.9);
  const GlobalExtrinsic T_jk = RandomExtrinsic(&rng, 1.1);
  GlobalExtrinsic T_ik;
  Eigen::Matrix<double, 6, 6> J_ij, J_jk;
  ComposeExtrinsic(T_ij, T_jk, &T_ik, &J_ij, &J_jk);
  const Eigen::Matrix<double, 6, 6> numeric = Numeric(T_ij, T_jk, true);
  Eigen::Matrix<double, 6, 6> flipped = J_ij;
  flipped.bottomLeftCorner<3, 3>() *= -1.0;  // the lever-arm term's sign
  EXPECT_GT((flipped - numeric).norm(), 1e-2);
  flipped = J_ij;
  flipped.topLeftCorner<3, 3>() *= -1.0;
  EXPECT_GT((flipped - numeric).norm(), 1e-2);
}

// i knows j first-hand and k only through j (session 1 of j). A derived k
// may not relay while j is in the state in that session, may once j left or
// restarted, or once enough own observations of k were fused; never when the
// option is off.
TEST(CanRelay, ADerivedTeammateRelaysOnceItNoLongerLeansOnItsIntermediary) {
  const int j = 1, k = 2;
  SwarmState x;
  x.AddTeammate(j, GlobalExtrinsic());
  x.AddTeammate(k, GlobalExtrinsic());
  Teammates teammates;
  teammates[j].session_start_ns = 100;
  teammates[k].session_start_ns = 200;
  SetProvenance(false, false, {}, &teammates[j]);
  SetProvenance(true, true, {{j, 100}}, &teammates[k]);
  SwarmOptions options;
  options.graph_derived_min_observations = 20;
  EXPECT_TRUE(CanRelay(teammates[j], x, teammates, options));  // first-hand
  EXPECT_FALSE(CanRelay(teammates[k], x, teammates, options));
  // Own observations of k make its block first-hand-like.
  teammates[k].observations_fused = 20;
  EXPECT_TRUE(CanRelay(teammates[k], x, teammates, options));
  teammates[k].observations_fused = 19;
  EXPECT_FALSE(CanRelay(teammates[k], x, teammates, options));
  // j restarted (a new session, its block not yet removed) or left.
  teammates[j].session_start_ns = 101;
  EXPECT_TRUE(CanRelay(teammates[k], x, teammates, options));
  teammates[j].session_start_ns = 100;
  x.RemoveTeammate(j);
  EXPECT_TRUE(CanRelay(teammates[k], x, teammates, options));
  options.graph_through_derived = false;
  EXPECT_FALSE(CanRelay(teammates[k], x, teammates, options));
}

// The inverse of k's own derived entry (k does not say through whom): its
// chain is taken as every other teammate heard, in their current sessions.
TEST(HeardTeammates, StandsInForAnUnnamedChain) {
  const int j = 1, k = 2, m = 3, silent = 4;
  Teammates teammates;
  teammates[j].session_start_ns = 100;
  teammates[j].last_heard_ns = 5;
  teammates[k].session_start_ns = 200;
  teammates[k].last_heard_ns = 6;
  teammates[m].session_start_ns = 300;
  teammates[m].last_heard_ns = 7;
  teammates[silent].last_seen_ns = 8;  // seen, never heard
  const std::map<int, int64_t> chain = HeardTeammates(teammates, k);
  EXPECT_EQ(chain, (std::map<int, int64_t>{{j, 100}, {m, 300}}));
  SetProvenance(true, true, chain, &teammates[k]);
  SwarmState x;
  x.AddTeammate(j, GlobalExtrinsic());
  x.AddTeammate(k, GlobalExtrinsic());
  SwarmOptions options;
  EXPECT_FALSE(CanRelay(teammates[k], x, teammates, options));  // j is still there
  teammates[j].session_start_ns = 101;                           // j restarted
  EXPECT_TRUE(CanRelay(teammates[k], x, teammates, options));
  EXPECT_FALSE(ChainPassesThrough(teammates[k], j, teammates));
  EXPECT_TRUE(ChainPassesThrough(teammates[k], m, teammates));
}

// k's block came through j: composing j through k is a loop while j is in
// the same session (here it left the state, e.g. timed out), not once j
// restarted (its new frame is not in k's chain).
TEST(ChainPassesThrough, RefusesALoopThroughTheSameSessionOnly) {
  const int j = 1, k = 2, m = 3;
  Teammates teammates;
  teammates[j].session_start_ns = 100;
  SetProvenance(true, true, {{j, 100}}, &teammates[k]);
  EXPECT_TRUE(ChainPassesThrough(teammates[k], j, teammates));
  EXPECT_FALSE(ChainPassesThrough(teammates[k], m, teammates));
  teammates[j].session_start_ns = 101;
  EXPECT_FALSE(ChainPassesThrough(teammates[k], j, teammates));
}

}  // namespace
}  // namespace swarmlio::swarm::internal
