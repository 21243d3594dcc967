// Ray-casting throughput of the static-scene BVH (rays per second, 1 core).
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "swarmlio/math/so3.h"
#include "swarmlio/sim/scene.h"

namespace swarmlio::sim {
namespace {

// An indoor-like scene: closed 20 x 16 x 4 m room plus `clutter` random boxes,
// cylinders and rectangles.
void BuildScene(int clutter, Scene* scene) {
  const Material wall = Material::Diffuse(60.0);
  AddRoom(Eigen::Vector3d::Zero(), Eigen::Vector3d(20, 16, 4), 0.5, wall, /*ceiling=*/true, scene);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> x(-9.0, 9.0), y(-7.0, 7.0), s(0.1, 0.8), a(-3.2, 3.2);
  for (int i = 0; i < clutter; ++i) {
    const Eigen::Vector3d c(x(rng), y(rng), s(rng) * 3.0);
    switch (i % 3) {
      case 0:
        scene->Add(Primitive::OrientedBox(c, so3::Exp(Eigen::Vector3d(0, 0, a(rng))),
                                          Eigen::Vector3d(s(rng), s(rng), s(rng)), wall));
        break;
      case 1:
        scene->Add(Primitive::VerticalCylinder(Eigen::Vector3d(c.x(), c.y(), 0.0), 0.5 * s(rng),
                                               4.0 * s(rng), wall));
        break;
      default:
        scene->Add(Primitive::Rectangle(c, so3::Exp(Eigen::Vector3d(a(rng), 0, 0)), s(rng),
                                        s(rng), wall));
    }
  }
  scene->Build();
}

void BM_SceneRaycast(benchmark::State& state) {
  Scene scene;
  BuildScene(static_cast<int>(state.range(0)), &scene);
  std::mt19937_64 rng(2);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> x(-8.0, 8.0), y(-6.0, 6.0), z(0.5, 3.5);
  std::vector<Ray> rays(4096);
  for (Ray& r : rays) {
    r.origin = Eigen::Vector3d(x(rng), y(rng), z(rng));
    r.direction = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  }
  size_t i = 0;
  int64_t hits = 0;
  for (auto _ : state) {
    RayHit hit;
    hits += scene.Intersect(rays[i], 0.0, 100.0, &hit);
    benchmark::DoNotOptimize(hit);
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["hit_fraction"] = static_cast<double>(hits) / state.iterations();
  state.counters["primitives"] = static_cast<double>(scene.primitives().size());
}
BENCHMARK(BM_SceneRaycast)->Arg(0)->Arg(50)->Arg(500)->Arg(5000);

void BM_BruteForceRaycast(benchmark::State& state) {
  Scene scene;
  BuildScene(static_cast<int>(state.range(0)), &scene);
  std::mt19937_64 rng(2);
  std::normal_distribution<double> g;
  Ray ray{Eigen::Vector3d(0.3, 0.2, 1.5), Eigen::Vector3d::UnitX()};
  for (auto _ : state) {
    ray.direction = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    RayHit hit;
    IntersectBruteForce(scene.primitives(), ray, 0.0, 100.0, &hit);
    benchmark::DoNotOptimize(hit);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_BruteForceRaycast)->Arg(50)->Arg(500);

}  // namespace
}  // namespace swarmlio::sim

BENCHMARK_MAIN();
