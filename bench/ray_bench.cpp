// Ray-casting throughput of the scene layer (Embree plus hit reconstruction) on the Cornell box:
// camera rays, and random rays between surface points (incoherent, like bounce rays).
#include <benchmark/benchmark.h>

#include "candela/io/scene_reader.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/scene/scene.h"

namespace candela {
namespace {

const Scene& cornell_box() {
  static Scene scene(read_json_scene(builtin_scene_json(), "cornell-box.json", "."));
  return scene;
}

void BM_CameraRays(benchmark::State& state) {
  const Scene& scene = cornell_box();
  Rng rng(1, 2);
  int64_t hits = 0;
  for (auto _ : state) {
    Ray ray = scene.camera().generate_ray({rng.next_float() * 512, rng.next_float() * 512}, {0.5f, 0.5f}, 0);
    SurfaceHit hit;
    hits += scene.intersect(ray, hit);
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CameraRays);

void BM_IncoherentRays(benchmark::State& state) {
  const Scene& scene = cornell_box();
  Rng rng(3, 4);
  Point3 center = scene.bounds().center();
  int64_t hits = 0;
  for (auto _ : state) {
    Vec3 d = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
    Point3 o = center + Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f) * 400;
    SurfaceHit hit;
    hits += scene.intersect(Ray{o, d}, hit);
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_IncoherentRays);

void BM_ShadowRays(benchmark::State& state) {
  const Scene& scene = cornell_box();
  Rng rng(5, 6);
  Point3 center = scene.bounds().center();
  int64_t blocked = 0;
  for (auto _ : state) {
    Point3 a = center + Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f) * 500;
    Point3 b = center + Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f) * 500;
    blocked += scene.occluded(Ray{a, b - a, 1});
  }
  benchmark::DoNotOptimize(blocked);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ShadowRays);

}  // namespace
}  // namespace candela
