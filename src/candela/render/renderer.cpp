#include "candela/render/renderer.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <stdexcept>

#include "candela/render/progress.h"

namespace candela {
namespace {

constexpr int kTileSize = 16;
constexpr int kPassSpp = 4;  // samples per pixel per pass: small enough for a responsive progress bar

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

}  // namespace

bool is_known_integrator(const std::string& name) { return name == "path"; }

RenderStats render(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  if (!is_known_integrator(settings.integrator))
    throw std::invalid_argument("unknown integrator '" + settings.integrator + "' (known: path)");
  auto start = std::chrono::steady_clock::now();
  const PathIntegrator integrator(scene, settings);
  const PerspectiveCamera& camera = scene.camera();
  std::vector<Tile> tiles = make_tiles(film.width(), film.height());
  tbb::enumerable_thread_specific<RayCounts> ray_counts;
  ProgressBar progress(uint64_t(film.width()) * film.height() * uint64_t(settings.spp), options.progress);

  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  for (int pass_begin = 0; pass_begin < settings.spp; pass_begin += kPassSpp) {
    int pass_end = std::min(settings.spp, pass_begin + kPassSpp);
    arena.execute([&] {
      tbb::parallel_for(size_t(0), tiles.size(), [&](size_t t) {
        const Tile& tile = tiles[t];
        RayCounts& counts = ray_counts.local();
        IndependentSampler sampler(settings.seed);
        for (int y = tile.y0; y < tile.y1; ++y)
          for (int x = tile.x0; x < tile.x1; ++x)
            for (int s = pass_begin; s < pass_end; ++s) {
              // Jitter the camera ray uniformly over the pixel (the paper's eq. 9).
              sampler.start_pixel_sample(x, y, uint64_t(s));
              Vec2 jitter = sampler.get_pixel_2d();
              Vec2 lens = sampler.get_2d();
              // Pick the path's time in the shutter interval (sec. 4.2); every object is seen at it.
              float time = lerp(sampler.get_1d(), camera.shutter_open(), camera.shutter_close());
              Ray ray = camera.generate_ray({float(x) + jitter.x, float(y) + jitter.y}, lens, time);
              RGB L = integrator.radiance(ray, sampler, counts);
              film.add_sample(x, y, L);
            }
        progress.advance(uint64_t(tile.x1 - tile.x0) * (tile.y1 - tile.y0) * uint64_t(pass_end - pass_begin));
      });
    });
  }
  progress.finish();

  RenderStats stats;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.samples = uint64_t(film.width()) * film.height() * uint64_t(settings.spp);
  for (const auto& c : ray_counts) stats.rays += c;
  return stats;
}

}  // namespace candela
