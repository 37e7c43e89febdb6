// Cost of the pixel samplers: one camera sample's worth of numbers (start + 1 pixel 2D + 24 more
// dimensions, about what a path of a few bounces consumes).
#include <benchmark/benchmark.h>

#include "candela/sampling/samplers.h"

namespace candela {
namespace {

// range(0): the sampler type; range(1): how many of a pixel's samples are drawn in a row (1: a
// new pixel every sample; 64: a pixel's whole set, as a render pass draws them, so samplers may
// reuse per-pixel work).
void BM_Sampler(benchmark::State& state) {
  SamplerDesc desc;
  desc.type = SamplerType(state.range(0));
  const uint64_t in_a_row = uint64_t(state.range(1));
  Sampler sampler = make_sampler(desc, 64, 7, 512, 512);
  uint64_t i = 0;
  float acc = 0;
  for (auto _ : state) {
    std::visit(
        [&](auto& s) {
          uint64_t pixel = i / in_a_row;
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
BENCHMARK(BM_Sampler)
    ->ArgsProduct({{0, 1, 2, 3}, {1}})
    ->Args({0, 64})
    ->Args({3, 64})
    ->ArgNames({"independent_stratified_poisson_zsobol", "in_a_row"});

}  // namespace
}  // namespace candela
