#include "candela/render/renderer.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <stdexcept>

#include "candela/film/filter.h"
#include "candela/render/progress.h"
#include "candela/sampling/samplers.h"

namespace candela {
namespace {

constexpr int kTileSize = 16;
constexpr int kPassSpp = 4;  // samples per pixel per pass in plain renders: a responsive progress bar

struct Tile {
  int x0, y0, x1, y1;
};

std::vector<Tile> make_tiles(int width, int height) {
  std::vector<Tile> tiles;
  for (int y = 0; y < height; y += kTileSize)
    for (int x = 0; x < width; x += kTileSize)
      tiles.push_back({x, y, std::min(x + kTileSize, width), std::min(y + kTileSize, height)});
  return tiles;
}

// Everything one pass needs, shared by all tiles.
struct PassContext {
  const Scene& scene;
  const PathIntegrator& integrator;
  const Filter& filter;
  const Sampler& prototype;  // copied per tile: samplers carry per-sample state
  Film& film;
  tbb::enumerable_thread_specific<RayCounts>& ray_counts;
  std::atomic<uint64_t>& non_finite;
};

// Renders samples [first, first + count) of pixel (x, y).
template <typename S>
void render_pixel(const PassContext& pc, S& sampler, int x, int y, uint64_t first, int count, RayCounts& counts) {
  const PerspectiveCamera& camera = pc.scene.camera();
  for (uint64_t s = first; s < first + uint64_t(count); ++s) {
    sampler.start_pixel_sample(x, y, s);
    // Place the sample in the pixel by importance-sampling the reconstruction filter (eq. 9 with a
    // filter); the sample counts for this pixel only, with the filter's weight.
    Filter::Sample fs = pc.filter.sample(sampler.get_pixel_2d());
    Vec2 lens = sampler.get_2d();
    // Pick the path's time in the shutter interval (sec. 4.2); every object is seen at it.
    float time = lerp(sampler.get_1d(), camera.shutter_open(), camera.shutter_close());
    Ray ray = camera.generate_ray({float(x) + 0.5f + fs.offset.x, float(y) + 0.5f + fs.offset.y}, lens, time);
    RGB L = pc.integrator.radiance(ray, sampler, counts);
    if (!L.is_finite()) {
      pc.non_finite.fetch_add(1, std::memory_order_relaxed);
      L = RGB(0.0f);
    }
    pc.film.add_sample(x, y, L, fs.weight);
  }
}

// One pass over the tiles: pixel (x, y) gets `count` samples starting at first_sample(x, y), or is
// skipped when that returns a negative number.
template <typename FirstSample>
void run_pass(const PassContext& pc, const std::vector<Tile>& tiles, tbb::task_arena& arena, int count,
              FirstSample first_sample, ProgressBar& progress) {
  arena.execute([&] {
    tbb::parallel_for(size_t(0), tiles.size(), [&](size_t t) {
      const Tile& tile = tiles[t];
      RayCounts& counts = pc.ray_counts.local();
      uint64_t done = 0;
      std::visit(
          [&](const auto& prototype) {
            auto sampler = prototype;
            for (int y = tile.y0; y < tile.y1; ++y)
              for (int x = tile.x0; x < tile.x1; ++x) {
                int64_t first = first_sample(x, y);
                if (first < 0) continue;
                render_pixel(pc, sampler, x, y, uint64_t(first), count, counts);
                done += uint64_t(count);
              }
          },
          pc.prototype);
      progress.advance(done);
    });
  });
}

}  // namespace

bool is_known_integrator(const std::string& name) { return name == "path"; }

float relative_error(const PixelSums& pixel) {
  RGB mean = pixel.mean(), se = pixel.standard_error();
  float worst = 0;
  for (int c = 0; c < 3; ++c) worst = std::max(worst, se[c] / std::sqrt(mean[c] * mean[c] + 0.01f));
  return worst;
}

RenderStats render(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  if (!is_known_integrator(settings.integrator))
    throw std::invalid_argument("unknown integrator '" + settings.integrator + "' (known: path)");
  auto start = std::chrono::steady_clock::now();
  const bool adaptive = settings.adaptive_threshold > 0;
  const int batch = adaptive ? settings.adaptive_batch : settings.spp;
  const int max_spp = adaptive ? std::max(settings.adaptive_max_spp, batch) : settings.spp;

  const PathIntegrator integrator(scene, settings);
  const Filter filter(settings.filter);
  const Sampler prototype = make_sampler(settings.sampler, adaptive ? batch : settings.spp, settings.seed,
                                         film.width(), film.height());
  std::vector<Tile> tiles = make_tiles(film.width(), film.height());
  tbb::enumerable_thread_specific<RayCounts> ray_counts;
  std::atomic<uint64_t> non_finite{0};
  PassContext pc{scene, integrator, filter, prototype, film, ray_counts, non_finite};
  ProgressBar progress(uint64_t(film.width()) * film.height() * uint64_t(max_spp), options.progress);
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);

  if (!adaptive) {
    // A Poisson-disc set is built per pixel: render it in one pass rather than rebuilding it per pass.
    const int pass_spp = settings.sampler.type == SamplerType::Poisson ? settings.spp : kPassSpp;
    for (int pass = 0; pass < settings.spp; pass += pass_spp)
      run_pass(pc, tiles, arena, std::min(pass_spp, settings.spp - pass), [&](int, int) { return int64_t(pass); },
               progress);
  } else {
    // Batches of F samples. Between batches, every pixel's relative error is estimated from its own
    // samples and smoothed over its 3x3 neighbourhood (one pixel's variance from a few samples is
    // itself very noisy); pixels still above the threshold get the next batch. The decision is made
    // while no pass runs, from the film alone, so it does not depend on threads.
    const int w = film.width(), h = film.height();
    std::vector<uint8_t> active(size_t(w) * h, 1);
    std::vector<float> error(size_t(w) * h);
    for (int rendered = 0; rendered < max_spp; rendered += batch) {
      run_pass(pc, tiles, arena, batch,
               [&](int x, int y) -> int64_t { return active[size_t(y) * w + x] ? int64_t(rendered) : -1; },
               progress);
      if (rendered + batch >= max_spp) break;
      arena.execute([&] {
        tbb::parallel_for(0, h, [&](int y) {
          for (int x = 0; x < w; ++x) error[size_t(y) * w + x] = relative_error(film.pixel(x, y));
        });
      });
      bool any = false;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          uint8_t& a = active[size_t(y) * w + x];
          if (!a) continue;
          double sum_sq = 0;
          int n = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              int nx = x + dx, ny = y + dy;
              if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
              float e = error[size_t(ny) * w + nx];
              sum_sq += double(e) * e;
              ++n;
            }
          a = std::sqrt(sum_sq / n) > settings.adaptive_threshold;
          any = any || a;
        }
      if (!any) break;
    }
  }
  progress.finish();

  RenderStats stats;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.samples = film.total_samples();
  stats.non_finite_samples = non_finite.load();
  for (const auto& c : ray_counts) stats.rays += c;
  return stats;
}

}  // namespace candela
