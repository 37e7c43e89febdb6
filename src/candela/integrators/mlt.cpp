#include "candela/integrators/mlt.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <chrono>
#include <limits>

#include "candela/film/filter.h"
#include "candela/integrators/bdpt.h"
#include "candela/integrators/mlt_sampler.h"
#include "candela/render/progress.h"
#include "candela/sampling/distribution1d.h"
#include "candela/sampling/sampler.h"

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

// The luminance of the whole image function, averaged over the film (margin included): every
// bidirectional strategy of every depth for camera rays through a jittered grid over the film, plus
// the luminance of what their light paths splat. Stratifying the film position matters: the
// bootstrap's uniform film positions estimate the share of small bright regions (a visible light)
// with a relative error of 10% and more at 10^5 samples.
struct Normalization {
  std::vector<double> per_depth;  // the mean luminance of each depth's paths
  double value = 0, relative_error = 0;
};

Normalization estimate_normalization(const Scene& scene, const BdptIntegrator& bdpt, const RenderSettings& settings,
                                     tbb::task_arena& arena, tbb::enumerable_thread_specific<RayCounts>& ray_counts,
                                     uint64_t samples) {
  const PerspectiveCamera& camera = scene.camera();
  const Vec2 margin = camera.margin();
  const float width = float(camera.width()) + 2 * margin.x, height = float(camera.height()) + 2 * margin.y;
  const int gx = std::max(1, int(std::lround(std::sqrt(double(samples) * width / height))));
  const int gy = std::max(1, int((samples + uint64_t(gx) - 1) / uint64_t(gx)));
  const uint64_t n = uint64_t(gx) * uint64_t(gy);
  const int max_depth = settings.max_depth;
  const size_t depths = size_t(max_depth) + 1;
  std::vector<double> luminance(n * depths);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, n, 256), [&](const auto& range) {
      thread_local std::vector<BdptVertex> camera_path, light_path;
      thread_local std::vector<RGB> crossed;
      camera_path.resize(size_t(max_depth) + 2);
      light_path.resize(size_t(max_depth) + 1);
      RayCounts& counts = ray_counts.local();
      IndependentSampler sampler(hash_values(settings.seed, 0x6e6f726d));
      for (uint64_t i = range.begin(); i < range.end(); ++i) {
        int cx = int(i % uint64_t(gx)), cy = int(i / uint64_t(gx));
        sampler.start_pixel_sample(cx, cy, 0);
        Vec2 u = sampler.get_2d();
        Vec2 raster{-margin.x + (float(cx) + u.x) / float(gx) * width, -margin.y + (float(cy) + u.y) / float(gy) * height};
        Vec2 lens = sampler.get_2d();
        float time = lerp(sampler.get_1d(), camera.shutter_open(), camera.shutter_close());
        Ray ray = camera.generate_ray(raster, lens, time);
        crossed.assign(size_t(max_depth) + 3, RGB(0.0f));
        int nc = bdpt.camera_subpath(ray, sampler, counts, max_depth + 2, camera_path.data(), crossed.data());
        int nl = bdpt.light_subpath(sampler, counts, max_depth + 1, time, light_path.data());
        double* by_depth = &luminance[i * depths];
        for (int t = 1; t <= nc; ++t)
          for (int s = 0; s <= nl; ++s) {
            int depth = s + t - 2;
            if ((s == 1 && t == 1) || depth < 0 || depth > max_depth) continue;
            RGB L = bdpt.connect(light_path.data(), camera_path.data(), s, t, sampler, counts, time).L;
            if (L.is_finite()) by_depth[depth] += L.luminance();
          }
        for (size_t t = 2; t < crossed.size(); ++t)
          if (t - 2 <= size_t(max_depth) && crossed[t].is_finite()) by_depth[t - 2] += crossed[t].luminance();
      }
    });
  });
  Normalization b;
  b.per_depth.assign(depths, 0.0);
  double sum = 0, sum_sq = 0;
  for (uint64_t i = 0; i < n; ++i) {
    double v = 0;
    for (size_t d = 0; d < depths; ++d) {
      b.per_depth[d] += luminance[i * depths + d] / double(n);
      v += luminance[i * depths + d];
    }
    sum += v;
    sum_sq += v * v;
  }
  b.value = sum / double(n);
  double var = std::max(0.0, sum_sq / double(n) - b.value * b.value);
  b.relative_error = b.value > 0 ? std::sqrt(var / double(n)) / b.value : 0;  // ignores the stratification: an upper bound
  return b;
}

}  // namespace

RenderStats render_mlt(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  auto start_time = std::chrono::steady_clock::now();
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
  // The chains' deposits are scaled by b, the image's mean luminance, from its own estimator (the
  // bootstrap's mean would do in principle, but with far more noise).
  const BdptIntegrator bdpt_with_roulette(scene, settings);
  const Normalization normalization =
      estimate_normalization(scene, bdpt_with_roulette, settings, arena, ray_counts, uint64_t(settings.mlt_bootstrap));
  const double b = normalization.value;
  stats.mlt_normalization = b;
  stats.mlt_normalization_relative_error = normalization.relative_error;
  if (!(b > 0) || !(sum > 0)) {
    progress.finish();
    film.set_splat_scale(0);
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
    return stats;
  }
  const Distribution1D bootstrap(weights);

  // The chains. Their starts are chosen proportionally to the bootstrap weights, stratified over the
  // chains. Each depth's deposits are then scaled by that depth's own mean luminance over the number
  // of mutations its chains make, so the image does not depend on how many chains a depth happened
  // to get (which pbrt's single scale would leave to chance).
  const uint64_t chains = std::max<uint64_t>(1, std::min<uint64_t>(uint64_t(settings.mlt_chains), total_mutations));
  std::vector<size_t> start(chains);
  std::vector<uint64_t> depth_mutations(size_t(depths), 0);
  for (uint64_t chain = 0; chain < chains; ++chain) {
    Rng rng(chain, hash_values(settings.seed, 0x7374617274));
    float u = std::min((float(chain) + rng.next_float()) / float(chains), 0x1.fffffep-1f);
    start[chain] = bootstrap.sample(u);
    depth_mutations[start[chain] % size_t(depths)] += (chain + 1) * total_mutations / chains - chain * total_mutations / chains;
  }
  if (std::getenv("CANDELA_MLT_DEBUG")) {
    std::vector<double> boot(size_t(depths), 0.0);
    for (size_t i = 0; i < weights.size(); ++i) boot[i % size_t(depths)] += weights[i] / double(settings.mlt_bootstrap);
    for (size_t d = 0; d < size_t(depths); ++d)
      std::fprintf(stderr, "depth %zu: normalization %.5f bootstrap %.5f mutations %llu\n", d, normalization.per_depth[d],
                   boot[d], (unsigned long long)depth_mutations[d]);
  }
  // Deposits are kept near 1 (relative to the largest depth scale) for the fixed-point splat sums.
  std::vector<double> per_mutation(size_t(depths), 0.0);
  double largest = 0;
  for (size_t d = 0; d < size_t(depths); ++d)
    if (depth_mutations[d] > 0) {
      per_mutation[d] = normalization.per_depth[d] / double(depth_mutations[d]);
      largest = std::max(largest, per_mutation[d]);
    }
  std::vector<float> depth_scale(size_t(depths), 0.0f);
  for (size_t d = 0; d < size_t(depths); ++d)
    if (largest > 0) depth_scale[d] = float(per_mutation[d] / largest);
  std::atomic<uint64_t> done{0};
  std::atomic<uint64_t> non_finite{0};
  std::atomic<bool> out_of_time{false};
  arena.execute([&] {
    tbb::parallel_for(uint64_t(0), chains, [&](uint64_t chain) {
      RayCounts& counts = ray_counts.local();
      uint64_t first = chain * total_mutations / chains, last = (chain + 1) * total_mutations / chains;
      Rng rng(chain, hash_values(settings.seed, 0x636861696e));
      size_t index = start[chain];
      int depth = int(index % size_t(depths));
      const float scale = depth_scale[size_t(depth)];
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
        if (accept > 0 && !film.splats().add(proposed.raster, proposed.L * (accept * scale / y_proposed), filter))
          non_finite.fetch_add(1, std::memory_order_relaxed);
        if (accept < 1 && y_current > 0 &&
            !film.splats().add(current.raster, current.L * ((1 - accept) * scale / y_current), filter))
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
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count() >=
                  options.time_limit_seconds)
            out_of_time.store(true);
        }
      }
      progress.advance(since_report);
    });
  });
  progress.finish();

  // A depth's deposits carry its mean luminance per mutation; times the film area they make the image.
  // A render stopped early scales up by the share of mutations it made.
  const uint64_t mutations = done.load();
  film.set_splat_scale(mutations > 0 ? largest * double(scene.camera().importance_film_pixels()) *
                                           double(total_mutations) / double(mutations)
                                     : 0);
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  stats.samples = mutations;
  stats.non_finite_samples = non_finite.load();
  stats.cancelled = cancelled();
  stats.time_limited = out_of_time.load() && mutations < total_mutations;
  for (const auto& c : ray_counts) stats.rays += c;
  return stats;
}

}  // namespace candela
