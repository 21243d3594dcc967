// The description a simulated drone gives of its own airframe
// (teammate::AirframeDescription, YAML `airframe:` of the replay manifest),
// as its owner would measure it: the reflector's shape and extents from the
// body model, and for the shapes without a closed form (round: arm tape,
// see-through shell) the depth offset and the centroid scatter from rays
// cast at the body model. docs/simulator.md "Airframes".
#pragma once

#include <Eigen/Core>
#include <vector>

#include "swarmlio/sim/drone_body.h"
#include "swarmlio/sim/primitives.h"
#include "swarmlio/teammate/airframe.h"

namespace swarmlio::sim {

/// Centroid of the returns on the reflective parts of `parts_b` (body
/// frame) seen from far away along the unit direction `u_in_b` (body ->
/// observer), with parallel rays on a grid of `spacing_m`: each ray returns
/// from the first reflective surface it meets, a sparse surface (return
/// probability p < 1) with weight p and lets 1 - p through, a diffuse part
/// stops it. `spread_m` (optional): the weighted RMS distance of the returns
/// from that centroid. False when no ray returns.
bool RayCastReflectiveCentroid(const std::vector<Primitive>& parts_b,
                               const Eigen::Vector3d& u_in_b,
                               double spacing_m,
                               Eigen::Vector3d* centroid_in_b,
                               double* spread_m = nullptr);

/// The airframe description of a simulated body (the header comment).
teammate::AirframeDescription DescribeAirframe(const DroneBodyOptions& body);

}  // namespace swarmlio::sim
