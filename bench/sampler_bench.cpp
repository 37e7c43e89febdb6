// Cost of the pixel samplers: one camera sample's worth of numbers (start + 1 pixel 2D + 24 more
// dimensions, about what a path of a few bounces consumes).
#include <benchmark/benchmark.h>

#include "candela/sampling/samplers.h"

namespace candela {
namespace {

void BM_Sampler(benchmark::State& state) {
  SamplerDesc desc;
  desc.type = SamplerType(state.range(0));
  Sampler sampler = make_sampler(desc, 64, 7, 512, 512);
  uint64_t i = 0;
  float acc = 0;
  for (auto _ : state) {
    std::visit(
        [&](auto& s) {
          s.start_pixel_sample(int(i % 512), int((i / 512) % 512), i % 64);
          Vec2 p = s.get_pixel_2d();
          acc += p.x;
          for (int d = 0; d < 8; ++d) {
            acc += s.get_1d();
            Vec2 u = s.get_2d();
            acc += u.x + u.y;
          }
        },
        sampler);
    ++i;
  }
  benchmark::DoNotOptimize(acc);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Sampler)->DenseRange(0, 3)->ArgName("independent_stratified_poisson_zsobol");

// The same with each pixel's 64 samples drawn one after another, as a render pass draws them
// (samplers may keep per-pixel state between a pixel's samples).
void BM_SamplerPixelOrder(benchmark::State& state) {
  SamplerDesc desc;
  desc.type = SamplerType(state.range(0));
  Sampler sampler = make_sampler(desc, 64, 7, 512, 512);
  uint64_t i = 0;
  float acc = 0;
  for (auto _ : state) {
    std::visit(
        [&](auto& s) {
          uint64_t pixel = i / 64;
          s.start_pixel_sample(int(pixel % 512), int((pixel / 512) % 512), i % 64);
          Vec2 p = s.get_pixel_2d();
          acc += p.x;
          for (int d = 0; d < 8; ++d) {
            acc += s.get_1d();
            Vec2 u = s.get_2d();
            acc += u.x + u.y;
          }
        },
        sampler);
    ++i;
  }
  benchmark::DoNotOptimize(acc);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SamplerPixelOrder)->Arg(0)->Arg(3)->ArgName("independent_zsobol");

}  // namespace
}  // namespace candela
