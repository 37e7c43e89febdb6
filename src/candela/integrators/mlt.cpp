#include "candela/integrators/mlt.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <limits>

#include "candela/film/filter.h"
#include "candela/integrators/bdpt.h"
#include "candela/integrators/mlt_sampler.h"
#include "candela/render/progress.h"
#include "candela/sampling/distribution1d.h"

namespace candela {
namespace {

struct PathState {
  RGB L;
  Vec2 raster;
  float luminance() const { return L.luminance(); }
};

// The contribution of the path the sampler's current numbers describe, at a given depth: the
// numbers choose the strategy (s, t), the film position, the lens point and the time, then the two
// subpaths are traced with exactly s and t vertices and joined.
class MltPathSampler {
 public:
  MltPathSampler(const Scene& scene, const BdptIntegrator& bdpt) : scene_(scene), bdpt_(bdpt) {}

  PathState sample(MltSampler& sampler, int depth, RayCounts& counts) const {
    thread_local std::vector<BdptVertex> camera_path, light_path;
    camera_path.resize(size_t(depth) + 2);
    light_path.resize(size_t(depth) + 1);
    sampler.start_stream(MltSampler::kCameraStream);
    int s = 0, t = 2, strategies = 1;
    if (depth > 0) {
      strategies = depth + 2;
      s = std::min(int(sampler.get_1d() * float(strategies)), strategies - 1);
      t = strategies - s;
    }
    // Anywhere camera rays reach: the film and the filter's margin around it.
    const PerspectiveCamera& camera = scene_.camera();
    Vec2 margin = camera.margin(), u = sampler.get_2d();
    Vec2 raster{-margin.x + u.x * (float(camera.width()) + 2 * margin.x),
                -margin.y + u.y * (float(camera.height()) + 2 * margin.y)};
    Vec2 lens = sampler.get_2d();
    float time = lerp(sampler.get_1d(), camera.shutter_open(), camera.shutter_close());
    Ray ray = camera.generate_ray(raster, lens, time);
    PathState state{RGB(0.0f), raster};
    if (bdpt_.camera_subpath(ray, sampler, counts, t, camera_path.data()) != t) return state;
    sampler.start_stream(MltSampler::kLightStream);
    if (bdpt_.light_subpath(sampler, counts, s, time, light_path.data()) != s) return state;
    sampler.start_stream(MltSampler::kConnectionStream);
    BdptIntegrator::Connection c = bdpt_.connect(light_path.data(), camera_path.data(), s, t, sampler, counts, time);
    if (t == 1) state.raster = c.raster;
    state.L = c.L * float(strategies);
    if (!state.L.is_finite() || !(state.luminance() > 0)) state.L = RGB(0.0f);
    return state;
  }

 private:
  const Scene& scene_;
  const BdptIntegrator& bdpt_;
};

}  // namespace

RenderStats render_mlt(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  auto start = std::chrono::steady_clock::now();
  RenderStats stats;
  film.enable_splats();
  if (scene.lights().empty()) {
    film.set_splat_scale(0);
    return stats;
  }
  // Russian roulette would end subpaths short of the lengths the state asks for: off.
  RenderSettings bdpt_settings = settings;
  bdpt_settings.rr_start_depth = std::numeric_limits<int>::max();
  const BdptIntegrator bdpt(scene, bdpt_settings);
  const MltPathSampler paths(scene, bdpt);
  const Filter filter(settings.filter);
  const int depths = settings.max_depth + 1;
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  tbb::enumerable_thread_specific<RayCounts> ray_counts;
  auto cancelled = [&] { return options.cancel && options.cancel->load(std::memory_order_relaxed); };

  const uint64_t pixels = uint64_t(film.width()) * uint64_t(film.height());
  const uint64_t total_mutations = uint64_t(settings.spp) * pixels;
  const uint64_t bootstrap_count = uint64_t(settings.mlt_bootstrap) * uint64_t(depths);
  ProgressBar progress(bootstrap_count + total_mutations, options.progress);

  // Bootstrap: the luminance of independent states, depth by depth in turn.
  std::vector<float> weights(bootstrap_count);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, bootstrap_count, 1024), [&](const auto& range) {
      RayCounts& counts = ray_counts.local();
      for (uint64_t i = range.begin(); i < range.end(); ++i) {
        MltSampler sampler(settings.seed, i, settings.mlt_sigma, settings.mlt_large_step);
        weights[i] = paths.sample(sampler, int(i % uint64_t(depths)), counts).luminance();
      }
      progress.advance(range.size());
    });
  });
  double sum = 0;
  for (float w : weights) sum += w;
  const double b = sum / double(std::max<uint64_t>(bootstrap_count, 1)) * double(depths);
  if (!(b > 0)) {
    progress.finish();
    film.set_splat_scale(0);
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return stats;
  }
  const Distribution1D bootstrap(weights);

  // The chains.
  const uint64_t chains = std::max<uint64_t>(1, std::min<uint64_t>(uint64_t(settings.mlt_chains), total_mutations));
  std::atomic<uint64_t> done{0};
  std::atomic<uint64_t> non_finite{0};
  std::atomic<bool> out_of_time{false};
  arena.execute([&] {
    tbb::parallel_for(uint64_t(0), chains, [&](uint64_t chain) {
      RayCounts& counts = ray_counts.local();
      uint64_t first = chain * total_mutations / chains, last = (chain + 1) * total_mutations / chains;
      Rng rng(chain, hash_values(settings.seed, 0x636861696e));
      size_t index = bootstrap.sample(rng.next_float());
      int depth = int(index % size_t(depths));
      MltSampler sampler(settings.seed, index, settings.mlt_sigma, settings.mlt_large_step);
      PathState current = paths.sample(sampler, depth, counts);
      uint64_t since_report = 0;
      for (uint64_t m = first; m < last; ++m) {
        if ((m - first) % 256 == 0 && (cancelled() || out_of_time.load(std::memory_order_relaxed))) break;
        sampler.start_iteration();
        PathState proposed = paths.sample(sampler, depth, counts);
        float y_current = current.luminance(), y_proposed = proposed.luminance();
        float accept = y_current > 0 ? std::min(1.0f, y_proposed / y_current) : 1.0f;
        // Deposit both states, weighted by the probability that the chain moves or stays.
        if (accept > 0 && !film.splats().add(proposed.raster, proposed.L * (accept / y_proposed), filter))
          non_finite.fetch_add(1, std::memory_order_relaxed);
        if (accept < 1 && y_current > 0 &&
            !film.splats().add(current.raster, current.L * ((1 - accept) / y_current), filter))
          non_finite.fetch_add(1, std::memory_order_relaxed);
        if (rng.next_float() < accept) {
          current = proposed;
          sampler.accept();
        } else {
          sampler.reject();
        }
        done.fetch_add(1, std::memory_order_relaxed);
        if (++since_report == 4096) {
          progress.advance(since_report);
          since_report = 0;
          if (options.time_limit_seconds > 0 &&
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >=
                  options.time_limit_seconds)
            out_of_time.store(true);
        }
      }
      progress.advance(since_report);
    });
  });
  progress.finish();

  // Each deposit is a unit of luminance: mutations / b of them make one unit of image per film area.
  const uint64_t mutations = done.load();
  film.set_splat_scale(mutations > 0 ? b * double(scene.camera().importance_film_pixels()) / double(mutations) : 0);
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.samples = mutations;
  stats.non_finite_samples = non_finite.load();
  stats.cancelled = cancelled();
  stats.time_limited = out_of_time.load() && mutations < total_mutations;
  for (const auto& c : ray_counts) stats.rays += c;
  return stats;
}

}  // namespace candela
