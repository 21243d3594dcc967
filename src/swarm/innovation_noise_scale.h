// Observation noise that a wrong default cannot starve (docs/swarm.md
// "Observation noise from the innovations"): per teammate, a scale s of the
// active observation covariance R, estimated online from the normalized
// innovation squared (covariance matching). With e = h(x) - z, its full
// covariance S = J P J^T + R_j + s R (J: the Jacobian over the ego and
// extrinsic blocks, P their prediction covariance, R_j the teammate's pose
// term) and NIS = e^T S^-1 e (3 on average when s R is right), each
// observation moves s by
//     s <- clamp(s (1 + rate (min(NIS, cap) / 3 - 1)), min_scale, max_scale),
// so s settles where the NIS averages 3: an airframe whose returns scatter
// more than the default model says is not rejected by the gate, and one that
// scatters less is not under-used. The cap (the gate's square) keeps one
// outlier from moving it far. Internal to src/swarm.
#pragma once

#include <Eigen/Core>

#include "factors/active_observation_factor.h"
#include "swarmlio/state/swarm_state.h"
#include "swarmlio/swarm/swarm_options.h"

namespace swarmlio::swarm::internal {

/// NIS of innovation `e` of `factor` (built with the covariance
/// `factor_R` for the observation part, `true_R` the part that is the
/// observation's own noise; they differ by the information share) for
/// teammate `id`, with the prediction covariance `P` of `x`.
double ActiveObservationNis(const ActiveObservationFactor& factor,
                            const SwarmState& x,
                            const Eigen::MatrixXd& P,
                            int id,
                            const Eigen::Vector3d& e,
                            const Eigen::Matrix3d& factor_R,
                            const Eigen::Matrix3d& true_R);

/// The scale after one more observation with `nis` (the file comment).
double UpdatedNoiseScale(double scale, double nis, const SwarmOptions& options);

}  // namespace swarmlio::swarm::internal
