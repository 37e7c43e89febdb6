#include "candela/render/renderer.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <algorithm>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <tuple>

#include "candela/film/filter.h"
#include "candela/integrators/mlt.h"
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

// The non-finite samples to report: the `limit` smallest by (sample, y, x), so the list does not
// depend on thread timing.
class NonFiniteLog {
 public:
  explicit NonFiniteLog(int limit) : limit_(size_t(std::max(limit, 0))) {}
  void add(int x, int y, uint64_t s) {
    std::lock_guard lock(mutex_);
    NonFiniteSample n{x, y, s};
    auto less = [](const NonFiniteSample& a, const NonFiniteSample& b) {
      return std::tie(a.sample, a.y, a.x) < std::tie(b.sample, b.y, b.x);
    };
    if (samples_.size() == limit_ && (limit_ == 0 || !less(n, samples_.back()))) return;
    samples_.insert(std::upper_bound(samples_.begin(), samples_.end(), n, less), n);
    if (samples_.size() > limit_) samples_.pop_back();
  }
  std::vector<NonFiniteSample> samples() const { return samples_; }

 private:
  size_t limit_;
  std::mutex mutex_;
  std::vector<NonFiniteSample> samples_;
};

// Everything one pass needs, shared by all tiles.
struct PassContext {
  const Scene& scene;
  const PathIntegrator* path;  // one of the two
  const BdptIntegrator* bdpt;
  BdptTarget bdpt_target;
  const Filter& filter;
  const Sampler& prototype;  // copied per tile: samplers carry per-sample state
  Film& film;
  tbb::enumerable_thread_specific<RayCounts>& ray_counts;
  std::atomic<uint64_t>& non_finite;
  NonFiniteLog& non_finite_log;
  float clamp;
  const std::atomic<bool>* cancel;
};

bool cancelled(const PassContext& pc) { return pc.cancel && pc.cancel->load(std::memory_order_relaxed); }

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
    RGB L = pc.bdpt ? pc.bdpt->radiance(ray, sampler, counts, pc.bdpt_target, x, y, fs.weight)
                    : pc.path->radiance(ray, sampler, counts);
    if (!L.is_finite()) {
      // Never reaches the film: counted, the first few logged, and the sample counts as black.
      pc.non_finite.fetch_add(1, std::memory_order_relaxed);
      pc.non_finite_log.add(x, y, s);
      L = RGB(0.0f);
    } else if (pc.clamp > 0) {
      float m = L.max_component();
      if (m > pc.clamp) L *= pc.clamp / m;
    }
    pc.film.add_sample(x, y, L, fs.weight);
  }
}

// Which samples a pixel gets in a pass: [first, first + count); count <= 0 skips the pixel.
struct SampleRange {
  int64_t first;
  int count;
};

// One pass over the tiles: pixel (x, y) gets the samples range(x, y) names. Tiles not yet started
// when the cancel flag is set are skipped.
template <typename Range>
void run_pass(const PassContext& pc, const std::vector<Tile>& tiles, tbb::task_arena& arena, Range range,
              ProgressBar& progress) {
  arena.execute([&] {
    tbb::parallel_for(size_t(0), tiles.size(), [&](size_t t) {
      if (cancelled(pc)) return;
      const Tile& tile = tiles[t];
      RayCounts& counts = pc.ray_counts.local();
      uint64_t done = 0;
      std::visit(
          [&](const auto& prototype) {
            auto sampler = prototype;
            for (int y = tile.y0; y < tile.y1; ++y)
              for (int x = tile.x0; x < tile.x1; ++x) {
                SampleRange r = range(x, y);
                if (r.count <= 0) continue;
                render_pixel(pc, sampler, x, y, uint64_t(r.first), r.count, counts);
                done += uint64_t(r.count);
              }
          },
          pc.prototype);
      progress.advance(done);
    });
  });
}

}  // namespace

bool is_known_integrator(const std::string& name) { return name == "path" || name == "bdpt" || name == "mlt"; }

std::string known_integrators() { return "path, bdpt, mlt"; }

float relative_error(const PixelSums& pixel) {
  RGB mean = pixel.mean(), se = pixel.standard_error();
  float worst = 0;
  for (int c = 0; c < 3; ++c) worst = std::max(worst, se[c] / std::sqrt(mean[c] * mean[c] + 0.01f));
  return worst;
}

RenderStats render(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  if (!is_known_integrator(settings.integrator))
    throw std::invalid_argument("unknown integrator '" + settings.integrator + "' (known: " + known_integrators() + ")");
  if (options.only_x >= film.width() || options.only_y >= film.height() || (options.only_x >= 0) != (options.only_y >= 0))
    throw std::invalid_argument("pixel to render is outside the image");
  if (settings.integrator == "mlt") {
    if (settings.adaptive_threshold > 0) throw std::invalid_argument("adaptive sampling does not apply to the mlt integrator");
    if (options.only_x >= 0) throw std::invalid_argument("the mlt integrator cannot render a single pixel");
    if (film.total_samples() > 0 || (film.has_splats() && film.splats().sums() != std::vector<int64_t>(film.splats().sums().size(), 0)))
      throw std::invalid_argument("the mlt integrator cannot continue a partly rendered film");
    return render_mlt(scene, settings, film, options);
  }
  const bool bidirectional = settings.integrator == "bdpt";
  if (bidirectional && !film.has_splats()) film.enable_splats();
  auto start = std::chrono::steady_clock::now();
  const bool adaptive = settings.adaptive_threshold > 0;
  const int batch = adaptive ? settings.adaptive_batch : settings.spp;
  const int max_spp = adaptive ? std::max(settings.adaptive_max_spp, batch) : settings.spp;

  const Filter filter(settings.filter);
  std::optional<PathIntegrator> path;
  std::optional<BdptIntegrator> bdpt;
  if (bidirectional) bdpt.emplace(scene, settings);
  else path.emplace(scene, settings);
  BdptTarget bdpt_target{&film, &filter, options.bdpt_strategies, options.bdpt_unweighted};
  const Sampler prototype = make_sampler(settings.sampler, adaptive ? batch : settings.spp, settings.seed,
                                         film.width(), film.height());
  std::vector<Tile> tiles = options.only_x >= 0 ? std::vector<Tile>{{options.only_x, options.only_y,
                                                                     options.only_x + 1, options.only_y + 1}}
                                                : make_tiles(film.width(), film.height());
  const uint64_t pixel_count = options.only_x >= 0 ? 1 : uint64_t(film.width()) * film.height();
  tbb::enumerable_thread_specific<RayCounts> ray_counts;
  std::atomic<uint64_t> non_finite{0};
  NonFiniteLog non_finite_log(options.max_reported_non_finite);
  PassContext pc{scene,      path ? &*path : nullptr, bdpt ? &*bdpt : nullptr, bdpt_target, filter, prototype, film,
                 ray_counts, non_finite,            non_finite_log,          options.clamp, options.cancel};
  const uint64_t samples_before = film.total_samples();
  ProgressBar progress(pixel_count * uint64_t(max_spp), options.progress);
  progress.advance(options.only_x >= 0 ? 0 : samples_before);
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  RenderStats stats;
  // After a whole pass: true when the render must stop (cancelled, or out of time).
  auto stop_after_pass = [&](bool more_to_do) {
    if (cancelled(pc)) {
      stats.cancelled = true;
      return true;
    }
    if (more_to_do && options.time_limit_seconds > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= options.time_limit_seconds) {
      stats.time_limited = true;
      return true;
    }
    return false;
  };

  if (!adaptive) {
    // A Poisson-disc set is built per pixel: render it in one pass rather than rebuilding it per pass.
    // Every pixel continues from its own count, so a film resumed from a checkpoint (or one whose
    // last pass was cut short) gets exactly the samples an uninterrupted render would add, in order.
    const int pass_spp = settings.sampler.type == SamplerType::Poisson ? settings.spp : kPassSpp;
    uint64_t least = options.only_x >= 0 ? film.pixel(options.only_x, options.only_y).count : film.min_samples();
    const int first_pass = int(std::min<uint64_t>(least, uint64_t(settings.spp)) / uint64_t(pass_spp)) * pass_spp;
    for (int pass = first_pass; pass < settings.spp; pass += pass_spp) {
      const int end = std::min(pass + pass_spp, settings.spp);
      run_pass(pc, tiles, arena,
               [&](int x, int y) {
                 int64_t have = int64_t(film.pixel(x, y).count);
                 return SampleRange{have, int(std::max<int64_t>(0, end - have))};
               },
               progress);
      if (options.after_pass && !cancelled(pc)) options.after_pass(film, non_finite.load());
      if (stop_after_pass(end < settings.spp)) break;
    }
  } else {
    if (samples_before > 0) throw std::invalid_argument("adaptive sampling cannot continue a partly rendered film");
    // Batches of F samples. Between batches, every pixel's relative error is estimated from its own
    // samples and smoothed over its 3x3 neighbourhood (one pixel's variance from a few samples is
    // itself very noisy); pixels still above the threshold get the next batch. The decision is made
    // while no pass runs, from the film alone, so it does not depend on threads.
    const int w = film.width(), h = film.height();
    std::vector<uint8_t> active(size_t(w) * h, 1);
    if (options.only_x >= 0) {
      std::fill(active.begin(), active.end(), 0);
      active[size_t(options.only_y) * w + options.only_x] = 1;
    }
    std::vector<float> error(size_t(w) * h);
    for (int rendered = 0; rendered < max_spp; rendered += batch) {
      run_pass(pc, tiles, arena,
               [&](int x, int y) {
                 return active[size_t(y) * w + x] ? SampleRange{rendered, batch} : SampleRange{0, 0};
               },
               progress);
      if (stop_after_pass(rendered + batch < max_spp)) break;
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

  // One light path was traced per camera sample: the light image is the splats times the
  // importance film's area over their number.
  if (bidirectional) {
    uint64_t light_paths = film.total_samples();
    film.set_splat_scale(light_paths > 0 ? double(scene.camera().importance_film_pixels()) / double(light_paths) : 0);
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.samples = film.total_samples() - samples_before;
  stats.non_finite_samples = non_finite.load();
  stats.first_non_finite = non_finite_log.samples();
  if (cancelled(pc)) stats.cancelled = true;
  for (const auto& c : ray_counts) stats.rays += c;
  return stats;
}

}  // namespace candela
