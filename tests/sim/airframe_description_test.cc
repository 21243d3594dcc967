// sim::DescribeAirframe: the description each simulated airframe announces,
// checked against rays cast at its body model (the returns' centroid a
// teammate sees), and the ray cast itself on a see-through disc.
#include "swarmlio/sim/airframe_description.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace swarmlio::sim {
namespace {

using teammate::ReflectorShape;
constexpr double kSpacingM = 0.004;

Eigen::Vector3d View(double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * M_PI / 180.0, e = elevation_deg * M_PI / 180.0;
  return Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
}

// Largest distance between the described and the ray-cast centroid over the
// views at elevations -10..10 deg; `flip` mirrors the described one (a sign
// error in the model).
double WorstModelError(const DroneBodyOptions& body, bool flip) {
  const teammate::AirframeDescription a = DescribeAirframe(body);
  const std::vector<Primitive> parts = MakeDroneBody(body);
  double worst = 0.0;
  for (double elevation : {-10.0, 0.0, 10.0}) {
    for (double azimuth = 5.0; azimuth < 360.0; azimuth += 20.0) {
      const Eigen::Vector3d u = View(azimuth, elevation);
      Eigen::Vector3d cast;
      EXPECT_TRUE(RayCastReflectiveCentroid(parts, u, kSpacingM, &cast));
      const Eigen::Vector3d model =
          a.reflector_centre_in_body_m + teammate::VisibleReflectorCentroid(a, flip ? -u : u);
      worst = std::max(worst, (model - cast).norm());
    }
  }
  return worst;
}

TEST(AirframeDescription, TapeBandIsABandTheRayCastAgreesWith) {
  const DroneBodyOptions body = DroneBodyOptions::ForModel(AirframeModel::kTapeBand);
  const teammate::AirframeDescription a = DescribeAirframe(body);
  EXPECT_EQ(a.reflector_shape, ReflectorShape::kBand);
  EXPECT_NEAR(a.reflector_half_extents_m.x(), 0.102, 1e-9);
  EXPECT_NEAR(a.reflector_half_extents_m.y(), 0.072, 1e-9);
  EXPECT_TRUE(a.reflector_centre_in_body_m.isZero(1e-9));
  EXPECT_DOUBLE_EQ(a.min_intensity, 151.0);
  EXPECT_GT(a.size_m, 0.35);
  EXPECT_LT(a.size_m, 0.45);
  // The band model against the rays: 2.2 cm at worst (seen from 10 deg above,
  // the arms in front of the band hide part of it), mostly under 1 cm;
  // mirrored, the model is off by twice the depth.
  EXPECT_LT(WorstModelError(body, false), 0.05);
  EXPECT_GT(WorstModelError(body, true), 0.1);
}

TEST(AirframeDescription, DimTapeAnnouncesItsLowIntensity) {
  const teammate::AirframeDescription a =
      DescribeAirframe(DroneBodyOptions::ForModel(AirframeModel::kDimTape));
  EXPECT_EQ(a.reflector_shape, ReflectorShape::kBand);
  EXPECT_DOUBLE_EQ(a.min_intensity, 100.0);
}

// A disc of radius R seen from the side through a lattice of return
// probability p: the near side returns p of the rays at mean depth pi R / 4,
// the far side p (1 - p) at -pi R / 4.
TEST(AirframeDescription, RayCastWeighsTheFarSideOfASeeThroughShell) {
  const DroneBodyOptions body = DroneBodyOptions::ForModel(AirframeModel::kReflectiveShell);
  const std::vector<Primitive> parts = MakeDroneBody(body);
  const double R = 0.5 * body.shell_diameter_m, p = body.shell_return_probability;
  const double expected = (p - p * (1.0 - p)) / (p + p * (1.0 - p)) * M_PI * R / 4.0;
  Eigen::Vector3d centroid;
  ASSERT_TRUE(RayCastReflectiveCentroid(parts, View(30.0, 0.0), 0.002, &centroid));
  EXPECT_NEAR(centroid.dot(View(30.0, 0.0)), expected, 0.002);
  EXPECT_NEAR(centroid.z(), 0.0, 1e-6);
}

TEST(AirframeDescription, ShellIsRoundAndSparse) {
  const DroneBodyOptions body = DroneBodyOptions::ForModel(AirframeModel::kReflectiveShell);
  const teammate::AirframeDescription a = DescribeAirframe(body);
  EXPECT_EQ(a.reflector_shape, ReflectorShape::kRound);
  EXPECT_GT(a.depth_offset_m, 0.03);
  EXPECT_LT(a.depth_offset_m, 0.06);
  EXPECT_GT(a.centroid_sigma_m, 0.03);  // a few returns scattered over 0.35 m
  EXPECT_LT(a.centroid_sigma_m, 0.12);  // 0.081
  EXPECT_DOUBLE_EQ(a.min_intensity, 236.0);
  EXPECT_LT(WorstModelError(body, false), 0.02);
}

TEST(AirframeDescription, ArmTapeIsRoundAboveTheOriginAndLarge) {
  const DroneBodyOptions body = DroneBodyOptions::ForModel(AirframeModel::kArmTape);
  const teammate::AirframeDescription a = DescribeAirframe(body);
  EXPECT_EQ(a.reflector_shape, ReflectorShape::kRound);
  EXPECT_NEAR(a.reflector_centre_in_body_m.z(), 0.015, 1e-6);
  EXPECT_GT(a.size_m, 0.6);
  EXPECT_DOUBLE_EQ(a.centroid_sigma_m, 0.0);
  // One depth for every view: what the round model leaves of the arm ends'
  // direction-dependent centroid.
  EXPECT_LT(WorstModelError(body, false), 0.08);
}

}  // namespace
}  // namespace swarmlio::sim
