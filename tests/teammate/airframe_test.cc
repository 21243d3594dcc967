// teammate/airframe.h: where the returns' centroid lies for each reflector
// shape, an observation placed by a teammate's announced airframe, and the
// detector gates an announcement widens.
#include "swarmlio/teammate/airframe.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "swarmlio/teammate/observation.h"
#include "swarmlio/teammate/teammate_detector.h"

namespace swarmlio::teammate {
namespace {

AirframeDescription Band(double a, double b) {
  AirframeDescription airframe;
  airframe.reflector_shape = ReflectorShape::kBand;
  airframe.reflector_half_extents_m = Eigen::Vector3d(a, b, 0.025);
  return airframe;
}

TEST(Airframe, BandIsTheTapeCentroidOfTheObservationModel) {
  const AirframeDescription band = Band(0.10, 0.07);
  for (double azimuth = 0.05; azimuth < 2 * M_PI; azimuth += 0.3) {
    const Eigen::Vector3d u(std::cos(azimuth) * 0.97, std::sin(azimuth) * 0.97, 0.243);
    EXPECT_TRUE(VisibleReflectorCentroid(band, u.normalized())
                    .isApprox(TapeCentroidInBody(u.normalized(), 0.10, 0.07), 1e-12));
  }
  // Head-on to a face: that face's centre; from straight above: no side face.
  EXPECT_TRUE(VisibleReflectorCentroid(band, Eigen::Vector3d::UnitY())
                  .isApprox(Eigen::Vector3d(0, 0.07, 0)));
  EXPECT_TRUE(VisibleReflectorCentroid(band, Eigen::Vector3d::UnitZ()).isZero());
}

TEST(Airframe, BoxCentroidLiesTowardsTheObserverOnEveryFace) {
  AirframeDescription box;
  box.reflector_shape = ReflectorShape::kBox;
  box.reflector_half_extents_m = Eigen::Vector3d(0.2, 0.1, 0.05);
  EXPECT_TRUE(VisibleReflectorCentroid(box, -Eigen::Vector3d::UnitZ())
                  .isApprox(Eigen::Vector3d(0, 0, -0.05)));
  // Two faces equally foreshortened (x = +a, y = +b at 45 deg): the mean of
  // their centres weighted by their areas b c and a c.
  const Eigen::Vector3d u = Eigen::Vector3d(1, 1, 0).normalized();
  const double a = 0.2, b = 0.1;
  EXPECT_TRUE(
      VisibleReflectorCentroid(box, u).isApprox(Eigen::Vector3d(a * b, b * a, 0) / (b + a), 1e-12));
  for (double azimuth = 0.1; azimuth < 2 * M_PI; azimuth += 0.5) {
    const Eigen::Vector3d v(std::cos(azimuth), std::sin(azimuth), -0.3);
    EXPECT_GT(VisibleReflectorCentroid(box, v.normalized()).dot(v), 0.0);
  }
}

TEST(Airframe, RoundLiesItsDepthOffsetOnTheLineOfSight) {
  AirframeDescription round;
  round.reflector_shape = ReflectorShape::kRound;
  round.depth_offset_m = 0.046;
  const Eigen::Vector3d u = Eigen::Vector3d(0.3, -0.9, 0.1).normalized();
  EXPECT_TRUE(VisibleReflectorCentroid(round, u).isApprox(0.046 * u));
}

// The teammate 5 m ahead, turned by 90 deg (its y axis faces the observer),
// announced with its band 1 cm above and 2 cm behind its body origin: the
// returns lie on the face y = +b of the band, and the observation puts the
// body origin back where it is.
TEST(Airframe, ObservationPlacesTheBodyOriginBehindTheAnnouncedReflector) {
  AirframeDescription band = Band(0.10, 0.07);
  band.reflector_centre_in_body_m = Eigen::Vector3d(-0.02, 0.0, 0.01);
  band.centroid_sigma_m = 0.05;
  const Eigen::Matrix3d R_bi_bj =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d p_bj_in_bi(5, 0, 0);
  const Eigen::Vector3d face_in_bj = band.reflector_centre_in_body_m + Eigen::Vector3d(0, 0.07, 0);
  PointCluster cluster;
  cluster.num_points = 20;
  cluster.num_reflective_points = 20;
  cluster.reflective_centroid_in_b = p_bj_in_bi + R_bi_bj * face_in_bj;
  cluster.centroid_in_b = cluster.reflective_centroid_in_b;
  ObservationOptions options;
  const TeammateObservation with =
      MakeObservation(1, 0, cluster, Eigen::Vector3d::Zero(), options, &R_bi_bj, &band);
  // The view direction is the returns' centroid's, not the body origin's:
  // 0.35 mm here.
  EXPECT_LT((with.p_bj_in_bi - p_bj_in_bi).norm(), 0.001);
  const TeammateObservation without =
      MakeObservation(1, 0, cluster, Eigen::Vector3d::Zero(), options, &R_bi_bj);
  EXPECT_GT((without.p_bj_in_bi - p_bj_in_bi).norm(), 0.02);  // the constant offset
  // The announced scatter adds to every direction of the covariance.
  const Eigen::Matrix3d added =
      with.covariance_m2 - ObservationCovariance(with.p_bj_in_bi, options);
  EXPECT_TRUE(added.isApprox(0.05 * 0.05 * Eigen::Matrix3d::Identity(), 1e-9));
}

TEST(Airframe, AnnouncementsWidenTheDetectorGatesNeverNarrowThem) {
  TeammateDetectorOptions options;
  options.clustering.min_reflectivity = 200.0;
  options.clustering.max_object_size_m = 0.6;
  TeammateDetector detector(0, options);
  AirframeDescription dim = Band(0.10, 0.07);
  dim.min_intensity = 100.0;
  dim.size_m = 0.4;
  EXPECT_FALSE(detector.SetTeammateAirframe(0, dim));  // its own
  EXPECT_DOUBLE_EQ(detector.min_reflectivity(), 200.0);
  EXPECT_TRUE(detector.SetTeammateAirframe(2, dim));
  EXPECT_DOUBLE_EQ(detector.min_reflectivity(), 100.0);
  AirframeDescription large = Band(0.3, 0.3);
  large.min_intensity = 236.0;
  large.size_m = 0.9;
  EXPECT_TRUE(detector.SetTeammateAirframe(3, large));
  EXPECT_DOUBLE_EQ(detector.min_reflectivity(), 100.0);  // the lowest announced
  AirframeDescription invalid = large;
  invalid.size_m = std::nan("");
  EXPECT_FALSE(detector.SetTeammateAirframe(4, invalid));
  // Drone 2 now announces a bright tape: the gate follows (200 is the floor).
  dim.min_intensity = 240.0;
  EXPECT_TRUE(detector.SetTeammateAirframe(2, dim));
  EXPECT_DOUBLE_EQ(detector.min_reflectivity(), 200.0);
}

}  // namespace
}  // namespace swarmlio::teammate
