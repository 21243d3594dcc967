// ObservationShare (src/swarm/observation_terms.h): which share of a mutual
// observation's information a drone takes, by its own and the teammate's
// degeneracy flags (docs/swarm.md "Information sharing").
#include "src/swarm/observation_terms.h"

#include <gtest/gtest.h>

namespace swarmlio::swarm::internal {
namespace {

TEST(ObservationShare, FullInformationOnlyWhereTheTeammateSkipsTheObservation) {
  SwarmOptions options;
  options.observation_information_share = 0.5;
  // Both well localized: each use takes its share.
  EXPECT_EQ(ObservationShare(options, false, false), 0.5);
  // This drone degenerate, the teammate well localized: the teammate skips
  // observations involving this drone, so this use is the only one.
  EXPECT_EQ(ObservationShare(options, true, false), 1.0);
  // The teammate degenerate: this drone (well localized) takes its share.
  EXPECT_EQ(ObservationShare(options, false, true), 0.5);
  // Both degenerate: both may fuse it, so neither takes it whole (at 1.0 on
  // both sides exploration seed 304 drifted 2.6 m in swarm mode, docs/swarm.md).
  EXPECT_EQ(ObservationShare(options, true, true), 0.5);
  // Without the skip rule nobody skips: always the share.
  options.skip_degenerate_teammates = false;
  EXPECT_EQ(ObservationShare(options, true, false), 0.5);
}

}  // namespace
}  // namespace swarmlio::swarm::internal
