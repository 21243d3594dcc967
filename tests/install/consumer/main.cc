// A downstream program: uses the installed headers and libraries.
#include <cstdio>

#include "factors/ego_state_manifold.h"
#include "swarmlio/io/bag_options.h"
#include "swarmlio/state/swarm_state.h"

int main() {
  swarmlio::SwarmState x;
  x.AddTeammate(2, swarmlio::GlobalExtrinsic());
  swarmlio::EgoStateManifold manifold;
  swarmlio::io::BagReaderOptions options;
  const bool ok = x.Dim() == 24 && manifold.TangentSize() == 18 && options.Validate().empty();
  std::printf("swarmlio consumer: state dim %d, %s\n", x.Dim(), ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
