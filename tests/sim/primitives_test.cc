#include "swarmlio/sim/primitives.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "swarmlio/math/so3.h"
#include "swarmlio/sim/bvh.h"
#include "swarmlio/sim/scene.h"

namespace swarmlio::sim {
namespace {

constexpr double kTol = 1e-9;
const Material kGrey = Material::Diffuse(50.0);

Ray MakeRay(const Eigen::Vector3d& o, const Eigen::Vector3d& d) { return {o, d.normalized()}; }

TEST(Primitives, AxisAlignedBoxExactDistanceAndNormal) {
  const Primitive box = Primitive::AxisAlignedBox({1, -1, -1}, {3, 1, 1}, kGrey);
  double t;
  Eigen::Vector3d n;
  ASSERT_TRUE(box.Intersect(MakeRay({0, 0, 0}, {1, 0, 0}), 0, 100, &t, &n));
  EXPECT_NEAR(t, 1.0, kTol);
  EXPECT_TRUE(n.isApprox(Eigen::Vector3d(-1, 0, 0)));
  // Diagonal ray into the corner region: enters through the x = 1 face at y = 0.5.
  const Eigen::Vector3d d = Eigen::Vector3d(2, 1, 0).normalized();
  ASSERT_TRUE(box.Intersect({Eigen::Vector3d(-1, 0, 0), d}, 0, 100, &t, &n));
  EXPECT_NEAR(t, std::sqrt(5.0), kTol);
  // From inside: the exit face.
  ASSERT_TRUE(box.Intersect(MakeRay({2, 0, 0}, {0, 0, 1}), 0, 100, &t, &n));
  EXPECT_NEAR(t, 1.0, kTol);
  EXPECT_TRUE(n.isApprox(Eigen::Vector3d(0, 0, 1)));
  // Misses: beside, behind, beyond t_max.
  EXPECT_FALSE(box.Intersect(MakeRay({0, 2, 0}, {1, 0, 0}), 0, 100, &t, &n));
  EXPECT_FALSE(box.Intersect(MakeRay({0, 0, 0}, {-1, 0, 0}), 0, 100, &t, &n));
  EXPECT_FALSE(box.Intersect(MakeRay({0, 0, 0}, {1, 0, 0}), 0, 0.5, &t, &n));
}

TEST(Primitives, OrientedBoxExactDistance) {
  // Unit cube rotated 45 deg about z at the origin: the edge is at sqrt(2)/2.
  const Eigen::Matrix3d R = so3::Exp(Eigen::Vector3d(0, 0, M_PI / 4));
  const Primitive box = Primitive::OrientedBox({5, 0, 0}, R, {0.5, 0.5, 0.5}, kGrey);
  double t;
  Eigen::Vector3d n;
  // Ray along x, offset in y by 0.2: hits a face at 45 deg. The face x'+... :
  // in world the face is the line x - 5 = -(sqrt(2)/2 - |y|).
  ASSERT_TRUE(box.Intersect(MakeRay({0, 0.2, 0}, {1, 0, 0}), 0, 100, &t, &n));
  EXPECT_NEAR(t, 5.0 - (std::sqrt(0.5) - 0.2), kTol);
  EXPECT_NEAR(std::abs(n.x()), std::sqrt(0.5), kTol);
  EXPECT_NEAR(n.z(), 0.0, kTol);
  // Bounds are the rotated box's AABB.
  EXPECT_NEAR(box.bounds().max.x(), 5.0 + std::sqrt(0.5), kTol);
  EXPECT_NEAR(box.bounds().max.z(), 0.5, kTol);
}

TEST(Primitives, RectangleIsTwoSidedAndFinite) {
  // Rectangle in the plane x = 4 (its normal is world x).
  const Eigen::Matrix3d R = so3::Exp(Eigen::Vector3d(0, M_PI / 2, 0));  // local z -> world -x
  const Primitive rect = Primitive::Rectangle({4, 0, 0}, R, 1.0, 2.0, kGrey);
  double t;
  Eigen::Vector3d n;
  const Eigen::Vector3d d = Eigen::Vector3d(4, 1.5, 0.5).normalized();
  ASSERT_TRUE(rect.Intersect({Eigen::Vector3d::Zero(), d}, 0, 100, &t, &n));
  EXPECT_NEAR(t, Eigen::Vector3d(4, 1.5, 0.5).norm(), kTol);
  EXPECT_NEAR(std::abs(n.x()), 1.0, kTol);
  ASSERT_TRUE(rect.Intersect(MakeRay({8, 0, 0}, {-1, 0, 0}), 0, 100, &t, &n));
  EXPECT_NEAR(t, 4.0, kTol);
  // Local x is world z (half 1), local y is world y (half 2).
  EXPECT_FALSE(rect.Intersect(MakeRay({0, 0, 1.2}, {1, 0, 0}), 0, 100, &t, &n));
  EXPECT_TRUE(rect.Intersect(MakeRay({0, 1.9, 0}, {1, 0, 0}), 0, 100, &t, &n));
  EXPECT_FALSE(rect.Intersect(MakeRay({0, 0, 0}, {0, 1, 0}), 0, 100, &t, &n));
}

TEST(Primitives, VerticalCylinderSideAndCaps) {
  const Primitive cyl = Primitive::VerticalCylinder({3, 0, 0}, 0.5, 2.0, kGrey);
  double t;
  Eigen::Vector3d n;
  ASSERT_TRUE(cyl.Intersect(MakeRay({0, 0, 1}, {1, 0, 0}), 0, 100, &t, &n));
  EXPECT_NEAR(t, 2.5, kTol);
  EXPECT_TRUE(n.isApprox(Eigen::Vector3d(-1, 0, 0)));
  // Off-axis chord: x = 3 - sqrt(r^2 - y^2).
  ASSERT_TRUE(cyl.Intersect(MakeRay({0, 0.3, 1}, {1, 0, 0}), 0, 100, &t, &n));
  EXPECT_NEAR(t, 3.0 - std::sqrt(0.25 - 0.09), kTol);
  // Top cap from above.
  ASSERT_TRUE(cyl.Intersect(MakeRay({3.1, 0.1, 5}, {0, 0, -1}), 0, 100, &t, &n));
  EXPECT_NEAR(t, 3.0, kTol);
  EXPECT_TRUE(n.isApprox(Eigen::Vector3d(0, 0, 1)));
  // Slanted ray through the top cap: from (0,0,4) towards (3,0,2) -> hits cap z=2 at x=3.
  const Eigen::Vector3d d = Eigen::Vector3d(3, 0, -2).normalized();
  ASSERT_TRUE(cyl.Intersect({Eigen::Vector3d(0, 0, 4), d}, 0, 100, &t, &n));
  // Side x = 2.5 is at z = 4 - 2 * 2.5 / 3 = 2.333 > 2: above the side, so the cap.
  EXPECT_NEAR(t, Eigen::Vector3d(3, 0, -2).norm(), kTol);
  // Above the top: miss.
  EXPECT_FALSE(cyl.Intersect(MakeRay({0, 0, 2.1}, {1, 0, 0}), 0, 100, &t, &n));
  // From inside: hits the wall.
  ASSERT_TRUE(cyl.Intersect(MakeRay({3, 0, 1}, {0, 1, 0}), 0, 100, &t, &n));
  EXPECT_NEAR(t, 0.5, kTol);
}

TEST(Primitives, TriangleInsideAndOutside) {
  const Primitive tri = Primitive::Triangle({2, 0, 0}, {2, 1, 0}, {2, 0, 1}, kGrey);
  double t;
  Eigen::Vector3d n;
  const Eigen::Vector3d d = Eigen::Vector3d(2, 0.25, 0.25).normalized();
  ASSERT_TRUE(tri.Intersect({Eigen::Vector3d::Zero(), d}, 0, 100, &t, &n));
  EXPECT_NEAR(t, Eigen::Vector3d(2, 0.25, 0.25).norm(), kTol);
  EXPECT_NEAR(std::abs(n.x()), 1.0, kTol);
  EXPECT_FALSE(tri.Intersect(MakeRay({0, 0.6, 0.6}, {1, 0, 0}), 0, 100, &t, &n));
  ASSERT_TRUE(tri.Intersect(MakeRay({4, 0.1, 0.1}, {-1, 0, 0}), 0, 100, &t, &n));  // back side
  EXPECT_NEAR(t, 2.0, kTol);
}

TEST(Primitives, ContainsIsTheInteriorOfClosedShapes) {
  const Primitive box = Primitive::AxisAlignedBox({0, 0, 0}, {2, 1, 3}, kGrey);
  EXPECT_TRUE(box.Contains({1.0, 0.5, 2.9}));
  EXPECT_FALSE(box.Contains({1.0, 0.5, 3.1}));
  EXPECT_FALSE(box.Contains({2.0, 0.5, 1.0}));  // on a face: not inside
  // Rotated 45 deg about z: a corner of its bounding box is outside.
  const Primitive turned = Primitive::OrientedBox(
      {0, 0, 0}, so3::Exp(Eigen::Vector3d(0, 0, M_PI / 4)), {1, 1, 1}, kGrey);
  EXPECT_TRUE(turned.Contains({1.3, 0.0, 0.5}));
  EXPECT_FALSE(turned.Contains({1.0, 1.0, 0.0}));
  EXPECT_TRUE(turned.bounds().min.x() < 1.0 && turned.bounds().max.y() > 1.0);
  const Primitive pole = Primitive::VerticalCylinder({5, 5, 1}, 0.5, 2.0, kGrey);
  EXPECT_TRUE(pole.Contains({5.3, 5.3, 2.0}));
  EXPECT_FALSE(pole.Contains({5.4, 5.4, 2.0}));  // 0.57 m from the axis
  EXPECT_FALSE(pole.Contains({5.0, 5.0, 0.9}));  // below the base
  EXPECT_FALSE(pole.Contains({5.0, 5.0, 3.1}));  // above the top
  EXPECT_FALSE(Primitive::Rectangle({0, 0, 0}, Eigen::Matrix3d::Identity(), 1, 1, kGrey)
                   .Contains({0, 0, 0}));
  EXPECT_FALSE(Primitive::Triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, kGrey).Contains({0.2, 0.2, 0}));
}

TEST(Primitives, TransformedMovesTheShape) {
  const Primitive box = Primitive::AxisAlignedBox({-1, -1, -1}, {1, 1, 1}, kGrey);
  const Primitive moved = box.Transformed(so3::Exp(Eigen::Vector3d(0, 0, 0.3)), {10, 0, 0});
  double t;
  Eigen::Vector3d n;
  ASSERT_TRUE(moved.Intersect(MakeRay({10, 0, 5}, {0, 0, -1}), 0, 100, &t, &n));
  EXPECT_NEAR(t, 4.0, kTol);
}

// Random scene of all primitive kinds in a 40 m cube.
std::vector<Primitive> RandomScene(int n, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> pos(-20.0, 20.0);
  std::uniform_real_distribution<double> size(0.05, 3.0);
  std::normal_distribution<double> gauss;
  std::vector<Primitive> out;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d c(pos(*rng), pos(*rng), pos(*rng));
    const Eigen::Matrix3d R = so3::Exp(Eigen::Vector3d(gauss(*rng), gauss(*rng), gauss(*rng)));
    const Eigen::Vector3d h(size(*rng), size(*rng), size(*rng));
    switch (i % 5) {
      case 0:
        out.push_back(Primitive::AxisAlignedBox(c - h, c + h, kGrey));
        break;
      case 1:
        out.push_back(Primitive::OrientedBox(c, R, h, kGrey));
        break;
      case 2:
        out.push_back(Primitive::Rectangle(c, R, h.x(), h.y(), kGrey));
        break;
      case 3:
        out.push_back(Primitive::VerticalCylinder(c, h.x(), h.z(), kGrey));
        break;
      default:
        out.push_back(Primitive::Triangle(c, c + R.col(0) * h.x(), c + R.col(1) * h.y(), kGrey));
    }
  }
  return out;
}

TEST(Bvh, MatchesBruteForceOnRandomRaysInRandomScenes) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pos(-25.0, 25.0);
  std::normal_distribution<double> gauss;
  int num_hits = 0;
  for (int scene_size : {1, 2, 7, 60, 500}) {
    const std::vector<Primitive> prims = RandomScene(scene_size, &rng);
    Bvh bvh;
    bvh.Build(&prims);
    for (int i = 0; i < 4000; ++i) {
      Ray ray{Eigen::Vector3d(pos(rng), pos(rng), pos(rng)),
              Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized()};
      if (i % 10 == 0) ray.direction = Eigen::Vector3d::UnitZ();  // axis-parallel rays
      RayHit expected;
      RayHit actual;
      const bool e = IntersectBruteForce(prims, ray, 0.0, 60.0, &expected);
      const bool a = bvh.Intersect(ray, 0.0, 60.0, &actual);
      ASSERT_EQ(e, a) << "scene " << scene_size << " ray " << i;
      if (!e) continue;
      ++num_hits;
      EXPECT_EQ(expected.t, actual.t);
      EXPECT_EQ(expected.primitive, actual.primitive);
      EXPECT_EQ(bvh.Occluded(ray, 0.0, 60.0), true);
    }
  }
  EXPECT_GT(num_hits, 1500);
}

TEST(Scene, BuildsAndIntersectsAfterMove) {
  Scene scene;
  scene.Add(Primitive::AxisAlignedBox({5, -1, -1}, {6, 1, 1}, kGrey));
  scene.Add(Primitive::AxisAlignedBox({3, -1, -1}, {4, 1, 1}, Material::RetroReflective()));
  scene.Build();
  Scene moved = std::move(scene);
  RayHit hit;
  ASSERT_TRUE(moved.Intersect(MakeRay({0, 0, 0}, {1, 0, 0}), 0, 100, &hit));
  EXPECT_NEAR(hit.t, 3.0, kTol);
  EXPECT_EQ(hit.primitive, 1);
  EXPECT_EQ(moved.primitives()[hit.primitive].material().type, SurfaceType::kRetroReflective);
}

}  // namespace
}  // namespace swarmlio::sim
