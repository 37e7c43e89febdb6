#include "candela/integrators/mlt.h"
#include "candela/integrators/volpath.h"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <cstring>
#include <limits>
#include <optional>

#include "candela/film/filter.h"
#include "candela/integrators/bdpt.h"
#include "candela/integrators/mlt_sampler.h"
#include "candela/integrators/path_integrator.h"
#include "candela/render/progress.h"
#include "candela/render/render_loop.h"
#include "candela/sampling/distribution1d.h"
#include "candela/sampling/sampler.h"

namespace candela {
namespace {

struct PathState {
  RGB L;
  Vec2 raster;
  int s = 0, t = 0;  // the strategy the numbers chose
  float luminance() const { return L.luminance(); }
  // Whether a lens or a caustic perturbation changes anything: a light-traced path (t = 1) does not
  // read its film position, a light subpath of fewer than two vertices not its direction.
  bool lens_moves() const { return t >= 2; }
  bool caustic_moves() const { return s >= 2; }
};

// The contribution of the path the sampler's current numbers describe, at a given depth: the
// numbers choose the strategy (s, t), the film position, the lens point and the time, then the two
// subpaths are traced with exactly s and t vertices and joined.
class MltPathSampler {
 public:
  MltPathSampler(const Scene& scene, const BdptIntegrator& bdpt, bool spectral)
      : scene_(scene), bdpt_(bdpt), spectral_(spectral) {}

  // The numbers the perturbations move: the film position is the camera stream's numbers 1-2 (after
  // the strategy, drawn at every depth >= 1, the only depths chains run), the direction leaving the
  // light the light stream's numbers 3-4 (BdptIntegrator::light_subpath draws the light, the point
  // on it, then the direction).
  static constexpr int kFilmNumber = 1, kLightDirectionNumber = 3;

  PathState sample(MltSampler& sampler, int depth, RayCounts& counts) const {
    thread_local std::vector<BdptVertex> camera_path, light_path;
    thread_local std::vector<RGB> crossed;
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
    Wavelengths storage;  // a spectral render's wavelengths are part of the state
    const Wavelengths* wl = sample_wavelengths_if(spectral_, sampler, storage);
    Ray ray = camera.generate_ray(raster, lens, time);
    PathState state{RGB(0.0f), raster, s, t};
    // The s = 0 strategy also takes the light the camera subpath meets without a vertex of its own
    // (emissive interfaces, emissive media): BdptIntegrator::camera_subpath's crossed emission.
    crossed.assign(size_t(t) + 1, RGB(0.0f));
    if (bdpt_.camera_subpath(ray, sampler, counts, t, camera_path.data(), s == 0 ? crossed.data() : nullptr, wl) != t)
      return state;
    sampler.start_stream(MltSampler::kLightStream);
    if (bdpt_.light_subpath(sampler, counts, s, time, light_path.data(), wl, camera_path[0].hero) != s) return state;
    sampler.start_stream(MltSampler::kConnectionStream);
    BdptIntegrator::Connection c =
        bdpt_.connect(light_path.data(), camera_path.data(), s, t, sampler, counts, time, wl);
    if (t == 1) state.raster = c.raster;
    if (s == 0) c.L += crossed[size_t(t)];
    state.L = wavelengths_to_rgb(c.L, wl) * float(strategies);
    if (!state.L.is_finite() || !(state.luminance() > 0)) state.L = RGB(0.0f);
    return state;
  }

 private:
  const Scene& scene_;
  const BdptIntegrator& bdpt_;
  bool spectral_;
};

// After run_shared across ranks: every rank gets the others' items of `values` (`per_item` values
// each).
template <typename T>
void exchange_values(Cluster& cluster, const std::vector<uint8_t>& mine, std::vector<T>& values, size_t per_item) {
  exchange_items(
      cluster, mine,
      [&](uint64_t item, std::vector<std::byte>& out) {
        const auto* p = reinterpret_cast<const std::byte*>(&values[item * per_item]);
        out.insert(out.end(), p, p + per_item * sizeof(T));
      },
      [&](uint64_t item, const std::byte* in) {
        std::memcpy(&values[item * per_item], in, per_item * sizeof(T));
        return in + per_item * sizeof(T);
      });
}

// The luminance of the whole image function, averaged over the film (margin included): every
// bidirectional strategy of every depth for camera rays through a jittered grid over the film, plus
// the luminance of what their light paths splat. Stratifying the film position matters: the
// bootstrap's uniform film positions estimate the share of small bright regions (a visible light)
// with a relative error of 10% and more at 10^5 samples.
struct Normalization {
  std::vector<double> per_depth;  // the mean luminance of each depth's paths
  double value = 0, relative_error = 0;
};

// Stops early (its result then unused) once `cancelled` says so.
// The samples are taken in blocks handed out across the cluster's ranks; each block's sums are
// added in block order, so the estimate is the same whichever rank or thread took a block.
Normalization estimate_normalization(const Scene& scene, const BdptIntegrator& bdpt, const RenderSettings& settings,
                                     Cluster& cluster, tbb::task_arena& arena,
                                     tbb::enumerable_thread_specific<RayCounts>& ray_counts,
                                     std::atomic<uint64_t>& busy_nanoseconds, uint64_t samples,
                                     const std::function<bool()>& cancelled, uint64_t batch = 0) {
  const PerspectiveCamera& camera = scene.camera();
  const Vec2 margin = camera.margin();
  const float width = float(camera.width()) + 2 * margin.x, height = float(camera.height()) + 2 * margin.y;
  const int gx = std::max(1, int(std::lround(std::sqrt(double(samples) * width / height))));
  const int gy = std::max(1, int((samples + uint64_t(gx) - 1) / uint64_t(gx)));
  const uint64_t n = uint64_t(gx) * uint64_t(gy);
  const int max_depth = settings.max_depth;
  const size_t depths = size_t(max_depth) + 1;
  // Per block of kBlock samples: each depth's luminance summed, then the sum and the sum of squares
  // of the samples' total luminance.
  constexpr uint64_t kBlock = 64;
  const uint64_t blocks = (n + kBlock - 1) / kBlock;
  const size_t per_block = depths + 2;
  std::vector<double> block_sums(blocks * per_block, 0.0);
  std::vector<uint8_t> mine = run_shared(cluster, arena, blocks, [&](uint64_t block) {
      // Once cancelled, the remaining blocks (hundreds of thousands at a deep max_depth) are passed
      // over without a clock reading each.
      if (cancelled()) return;
      BusyTimer busy(busy_nanoseconds);
      thread_local std::vector<BdptVertex> camera_path, light_path;
      thread_local std::vector<RGB> crossed;
      thread_local std::vector<double> by_depth;
      camera_path.resize(size_t(max_depth) + 2);
      light_path.resize(size_t(max_depth) + 1);
      RayCounts& counts = ray_counts.local();
      IndependentSampler sampler(batch == 0 ? hash_values(settings.seed, 0x6e6f726d)
                                            : hash_values(settings.seed, 0x6e6f726d, batch));
      double* sums = &block_sums[block * per_block];
      for (uint64_t i = block * kBlock; i < std::min(n, (block + 1) * kBlock); ++i) {
        if (cancelled()) return;  // a deep max_depth makes each sample long: answer a signal promptly
        int cx = int(i % uint64_t(gx)), cy = int(i / uint64_t(gx));
        sampler.start_pixel_sample(cx, cy, 0);
        Vec2 u = sampler.get_2d();
        Vec2 raster{-margin.x + (float(cx) + u.x) / float(gx) * width, -margin.y + (float(cy) + u.y) / float(gy) * height};
        Vec2 lens = sampler.get_2d();
        float time = lerp(sampler.get_1d(), camera.shutter_open(), camera.shutter_close());
        Wavelengths storage;
        const Wavelengths* wl = sample_wavelengths_if(settings.spectral, sampler, storage);
        auto luminance_of = [&](const RGB& v) { return wavelengths_to_rgb(v, wl).luminance(); };
        Ray ray = camera.generate_ray(raster, lens, time);
        crossed.assign(size_t(max_depth) + 3, RGB(0.0f));
        int nc = bdpt.camera_subpath(ray, sampler, counts, max_depth + 2, camera_path.data(), crossed.data(), wl);
        int nl = bdpt.light_subpath(sampler, counts, max_depth + 1, time, light_path.data(), wl,
                                    nc > 0 ? camera_path[0].hero : -1);
        by_depth.assign(depths, 0.0);
        for (int t = 1; t <= nc; ++t) {
          // A deep path has nc x nl connections, seconds of work: answer a signal between them.
          if (cancelled()) return;
          for (int s = 0; s <= nl; ++s) {
            int depth = s + t - 2;
            if ((s == 1 && t == 1) || depth < 0 || depth > max_depth) continue;
            RGB L = bdpt.connect(light_path.data(), camera_path.data(), s, t, sampler, counts, time, wl).L;
            if (L.is_finite()) by_depth[size_t(depth)] += luminance_of(L);
          }
        }
        for (size_t t = 2; t < crossed.size(); ++t)
          if (t - 2 <= size_t(max_depth) && crossed[t].is_finite()) by_depth[t - 2] += luminance_of(crossed[t]);
        double v = 0;
        for (size_t d = 0; d < depths; ++d) {
          sums[d] += by_depth[d];
          v += by_depth[d];
        }
        sums[depths] += v;
        sums[depths + 1] += v * v;
      }
  });
  if (cluster.distributed()) exchange_values(cluster, mine, block_sums, per_block);
  Normalization b;
  b.per_depth.assign(depths, 0.0);
  double sum = 0, sum_sq = 0;
  for (uint64_t block = 0; block < blocks; ++block) {
    const double* sums = &block_sums[block * per_block];
    for (size_t d = 0; d < depths; ++d) b.per_depth[d] += sums[d] / double(n);
    sum += sums[depths];
    sum_sq += sums[depths + 1];
  }
  b.value = sum / double(n);
  double var = std::max(0.0, sum_sq / double(n) - b.value * b.value);
  b.relative_error = b.value > 0 ? std::sqrt(var / double(n)) / b.value : 0;  // ignores the stratification: an upper bound
  return b;
}

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Step 0 (mlt.h): depth 0, the emission that camera rays see directly, needs no Markov chain: it is
// rendered as the path tracer renders it (stratified camera samples of one ray each) into the film's
// own pixel sums, and the chains' splats of the depths >= 1 are added to it. Left to chains, the
// share of the film covered by small visible lights is estimated far more noisily.
// Under a time limit it takes at most kMltDirectTimeShare of it (but at least one pass): at 256 spp
// it took 3.5 s of a 15 s budget on veach-ajar, time the chains then lacked.
RenderStats render_depth_zero(const Scene& scene, const RenderSettings& settings, Film& film,
                              const RenderOptions& options) {
  RenderSettings emission = settings;
  emission.max_depth = 0;
  emission.spp = mlt_direct_spp(settings.spp);
  emission.adaptive_threshold = 0;
  RenderOptions emission_options = options;
  emission_options.progress = false;
  emission_options.after_pass = nullptr;
  emission_options.time_limit_seconds = options.time_limit_seconds * kMltDirectTimeShare;
  emission_options.target_error = 0;
  emission_options.integrator_outputs = nullptr;
  // (Through media, the volumetric path tracer, which attenuates what the camera sees.)
  RenderStats stats = scene.has_media() ? render_volpath(scene, emission, film, emission_options)
                                        : render_path(scene, emission, film, emission_options);
  stats.samples = 0;
  stats.time_limited = false;  // the depth-0 pass's share of the limit, not the render's
  return stats;
}

// Russian roulette would end subpaths short of the lengths the state asks for: off.
RenderSettings without_roulette(const RenderSettings& settings) {
  RenderSettings bdpt_settings = settings;
  bdpt_settings.rr_start_depth = std::numeric_limits<int>::max();
  return bdpt_settings;
}

// One Markov chain: its sampler (the state's primary sample vector), the random numbers that decide
// acceptance, the path of its current state and what its deposits are scaled by.
struct Chain {
  MltSampler sampler;
  Rng rng;
  PathState current;
  int depth = 0;
  float scale = 0;
  float brightness = 0;  // the depth's mean luminance b_d
  bool first_half = false;
};

// Steps 1-3 of the algorithm (mlt.h) after the depth-0 pass: the bootstrap and the normalization
// constant b, the chains' set-up, the chains' rounds of mutations and the film's splat scale.
//
// Across ranks: the depth-0 pass and the bootstrap and normalisation samples are shared out and
// exchanged, so every rank starts the same chains; each rank then runs every size()-th chain, and
// the chains' splats (integer sums) are added up at the end.
class MltRender {
 public:
  MltRender(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options,
            Cluster& cluster, Clock::time_point start_time, const RenderStats& direct_stats, const MltStats& details)
      : scene_(scene),
        settings_(settings),
        film_(film),
        options_(options),
        cluster_(cluster),
        start_time_(start_time),
        stats_(direct_stats),
        details_(details),
        bdpt_settings_(without_roulette(settings)),
        bdpt_(scene, bdpt_settings_),
        paths_(scene, bdpt_, settings.spectral),
        filter_(settings.filter),
        depths_(settings.max_depth + 1),
        arena_(options.threads > 0 ? options.threads : tbb::task_arena::automatic),
        cancelled_([&options] { return options.cancel && options.cancel->load(std::memory_order_relaxed); }),
        total_mutations_(uint64_t(settings.spp) * uint64_t(film.width()) * uint64_t(film.height())),
        bootstrap_count_(uint64_t(settings.mlt.bootstrap) * uint64_t(depths_)),
        progress_(bootstrap_count_ + total_mutations_, options.progress, options.progress_fraction) {}

  const MltStats& details() const { return details_; }

  RenderStats run() {
    std::vector<float> weights;
    if (!generate_bootstrap_samples(weights)) return stop_cancelled();
    double sum = 0;
    for (float w : weights) sum += w;
    std::optional<Normalization> normalization = compute_normalization();
    if (!normalization) return stop_cancelled();
    if (!(normalization->value > 0) || !(sum > 0)) return stop_without_chains();

    progress_.set_label("MLT chains");
    stats_.setup_seconds = seconds_since(start_time_);
    if (!start_chains(weights, *normalization)) return stop_without_chains();
    const uint64_t mutations_per_chain = run_markov_chains(normalization->relative_error);
    return finish(mutations_per_chain);
  }

 private:
  // Interrupted before the chains: the image is the depth-0 pass alone.
  RenderStats stop_cancelled() {
    progress_.finish();
    stats_.cancelled = true;
    stats_.seconds = seconds_since(start_time_);
    return stats_;
  }

  // Nothing for the chains to render (no light found, no lit depth): the image is the depth-0 pass.
  RenderStats stop_without_chains() {
    progress_.finish();
    film_.set_splat_scale(0);
    stats_.seconds = seconds_since(start_time_);
    return stats_;
  }

  // Step 1: generate bootstrap samples, the luminance of independent states (bootstrap_count_ of
  // them, depth by depth in turn), in blocks handed out across the ranks; every rank then has them
  // all. False when interrupted.
  bool generate_bootstrap_samples(std::vector<float>& weights) {
    // The bootstrap grows with max_depth (one per depth): the bar says which phase it is in.
    progress_.set_label(fmt::format("MLT bootstrap ({} depths x {})", depths_, settings_.mlt.bootstrap));
    constexpr uint64_t kBootstrapBlock = 64;
    // (What the blocks read, as locals: the lambda then reaches them without going through `this`.)
    const uint64_t bootstrap_count = bootstrap_count_;
    const int depths = depths_;
    const RenderSettings& settings = settings_;
    const MltPathSampler& paths = paths_;
    const std::function<bool()>& cancelled = cancelled_;
    weights.assign(bootstrap_count, 0.0f);
    const uint64_t bootstrap_blocks = (bootstrap_count + kBootstrapBlock - 1) / kBootstrapBlock;
    std::vector<uint8_t> bootstrap_mine = run_shared(
        cluster_, arena_, bootstrap_blocks,
        [&](uint64_t block) {
          if (cancelled()) return;  // as in the normalisation
          BusyTimer busy(busy_nanoseconds_);
          RayCounts& counts = ray_counts_.local();
          const uint64_t end = std::min(bootstrap_count, (block + 1) * kBootstrapBlock);
          for (uint64_t i = block * kBootstrapBlock; i < end; ++i) {
            if (cancelled()) return;
            int depth = int(i % uint64_t(depths));
            if (depth == 0) continue;  // rendered directly (step 0)
            MltSampler sampler(settings.seed, i, settings.mlt.sigma);
            weights[i] = paths.sample(sampler, depth, counts).luminance();
          }
          progress_.advance(end - block * kBootstrapBlock);
        },
        [&](uint64_t, uint64_t count) { progress_.advance(count * kBootstrapBlock); });
    if (cluster_.any(cancelled_())) return false;
    details_.bootstrap_seconds = seconds_since(start_time_) - details_.direct_seconds;
    if (cluster_.distributed()) {
      weights.resize(bootstrap_blocks * kBootstrapBlock);  // whole blocks to exchange
      exchange_values(cluster_, bootstrap_mine, weights, kBootstrapBlock);
      weights.resize(bootstrap_count_);
    }
    return true;
  }

  // Step 1: compute the normalization constant b, the image's mean luminance (and each depth's),
  // which scales the chains' deposits, from its own estimator (the bootstrap's mean would do in
  // principle, but with far more noise). Empty when interrupted.
  // At least mlt_bootstrap samples, more for long renders (1 per 8 mutations), so that the image's
  // brightness converges with the rest of it. The estimate is heavy-tailed where caustics are
  // found by rare paths: with 1 per 64 the glass-sphere caustic's mean came out 3% high on two
  // seeds of three (a few rare paths in the estimate); with 1 per 8 within 0.6% on all three. It
  // costs 10-15% more time on the caustic and veach-mis, 40% on the Cornell box (whose normalization
  // evaluates every strategy of paths up to 16 bounces).
  std::optional<Normalization> compute_normalization() {
    const BdptIntegrator bdpt_with_roulette(scene_, settings_);
    const uint64_t normalization_samples =
        std::max<uint64_t>(uint64_t(settings_.mlt.bootstrap),
                           options_.time_limit_seconds > 0 || options_.target_error > 0 ? 0 : total_mutations_ / 8);
    const auto normalization_start = Clock::now();
    progress_.set_label(fmt::format("MLT normalisation ({} paths)", normalization_samples));
    Normalization normalization = estimate_normalization(scene_, bdpt_with_roulette, settings_, cluster_, arena_,
                                                         ray_counts_, busy_nanoseconds_, normalization_samples,
                                                         cancelled_);
    if (cluster_.any(cancelled_())) return std::nullopt;
    // Under a time limit the number of mutations is not known: further independent batches of
    // mlt_bootstrap samples, averaged, until the normalisation has taken about a ninth of the time
    // (1 sample per 8 mutations costs about that much).
    uint64_t batches = 1;
    if (options_.time_limit_seconds > 0) {
      double sum_sq_error = std::pow(normalization.relative_error * normalization.value, 2);
      while (cluster_.from_root(seconds_since(normalization_start) < options_.time_limit_seconds / 9) &&
             !cluster_.any(cancelled_())) {
        Normalization more = estimate_normalization(scene_, bdpt_with_roulette, settings_, cluster_, arena_,
                                                    ray_counts_, busy_nanoseconds_, normalization_samples,
                                                    cancelled_, batches);
        if (cluster_.any(cancelled_())) return std::nullopt;
        double k = double(batches);
        for (size_t d = 0; d < normalization.per_depth.size(); ++d)
          normalization.per_depth[d] = (normalization.per_depth[d] * k + more.per_depth[d]) / (k + 1);
        normalization.value = (normalization.value * k + more.value) / (k + 1);
        sum_sq_error += std::pow(more.relative_error * more.value, 2);
        ++batches;
      }
      normalization.relative_error =
          normalization.value > 0 ? std::sqrt(sum_sq_error) / double(batches) / normalization.value : 0;
    }
    details_.normalization = normalization.value;
    stats_.splat_scale_relative_error = normalization.relative_error;
    details_.normalization_samples = normalization_samples * batches;
    details_.normalization_seconds = seconds_since(normalization_start);
    return normalization;
  }

  // Step 2: distribute the chains over the depths. Each depth gets a share of them proportional to
  // its brightness, and at least one if it has any light (so no depth's light is lost to chance).
  // Every depth has an even number of chains: its even-numbered chains deposit also into the film's
  // first half, so the two halves are independent estimates of the image (film/error_estimate.h).
  // Also each depth's bootstrap states as a distribution proportional to their luminance.
  std::vector<uint64_t> chains_per_depth(const std::vector<float>& weights, const Normalization& normalization,
                                         std::vector<Distribution1D>& depth_bootstrap) const {
    std::vector<uint64_t> depth_chains(size_t(depths_), 0);
    depth_bootstrap.resize(size_t(depths_));
    std::vector<bool> depth_found(size_t(depths_), false);
    for (size_t d = 0; d < size_t(depths_); ++d) {
      std::vector<float> w(size_t(settings_.mlt.bootstrap));
      for (size_t k = 0; k < w.size(); ++k) w[k] = weights[k * size_t(depths_) + d];
      depth_found[d] = std::any_of(w.begin(), w.end(), [](float x) { return x > 0; });
      depth_bootstrap[d] = Distribution1D(w);
    }
    const uint64_t wanted =
        std::max<uint64_t>(1, std::min<uint64_t>(uint64_t(settings_.mlt.chains), total_mutations_));
    double b_chains = 0;  // the brightness the chains render: every depth but 0
    for (size_t d = 1; d < size_t(depths_); ++d) b_chains += normalization.per_depth[d];
    for (size_t d = 0; d < size_t(depths_); ++d)
      if (d > 0 && depth_found[d] && normalization.per_depth[d] > 0)
        depth_chains[d] = 2 * std::max<uint64_t>(
                                  1, uint64_t(std::llround(double(wanted) * normalization.per_depth[d] / b_chains / 2)));
    return depth_chains;
  }

  // Step 2: set up the chains, each started from a bootstrap state of its depth chosen
  // proportionally to its luminance (no start-up bias), stratified over the depth's chains. Each
  // depth's deposits are then scaled by its own brightness over its number of chains. False when
  // there are none.
  bool start_chains(const std::vector<float>& weights, const Normalization& normalization) {
    std::vector<Distribution1D> depth_bootstrap;
    const std::vector<uint64_t> depth_chains = chains_per_depth(weights, normalization, depth_bootstrap);
    uint64_t chains = 0;
    for (uint64_t n : depth_chains) chains += n;
    if (chains == 0) return false;
    per_chain_ = (total_mutations_ + chains - 1) / chains;
    const MltMutationProbabilities mutations{settings_.mlt.large_step, settings_.mlt.lens, settings_.mlt.caustic};
    const PerspectiveCamera& camera = scene_.camera();
    const MltPerturbedNumbers perturbed{MltPathSampler::kFilmNumber, MltPathSampler::kLightDirectionNumber,
                                        {float(camera.width()) + 2 * camera.margin().x,
                                         float(camera.height()) + 2 * camera.margin().y}};
    chains_.reserve(chains);
    for (size_t d = 0; d < size_t(depths_); ++d)
      for (uint64_t k = 0; k < depth_chains[d]; ++k) {
        uint64_t c = chains_.size();
        Rng pick(c, hash_values(settings_.seed, 0x7374617274));
        float u = std::min((float(k) + pick.next_float()) / float(depth_chains[d]), 0x1.fffffep-1f);
        size_t index = depth_bootstrap[d].sample(u) * size_t(depths_) + d;
        chains_.push_back(Chain{MltSampler(settings_.seed, index, settings_.mlt.sigma, mutations, perturbed),
                                Rng(c, hash_values(settings_.seed, 0x636861696e)), PathState{}, int(d), 0, 0,
                                k % 2 == 0});
      }
    // Deposits are kept near 1 (relative to the largest depth scale) for the fixed-point splat sums.
    std::vector<double> per_chain_share(size_t(depths_), 0.0);
    for (size_t d = 0; d < size_t(depths_); ++d)
      if (depth_chains[d] > 0) {
        per_chain_share[d] = normalization.per_depth[d] / double(depth_chains[d]);
        largest_ = std::max(largest_, per_chain_share[d]);
      }
    for (Chain& c : chains_) {
      c.scale = largest_ > 0 ? float(per_chain_share[size_t(c.depth)] / largest_) : 0.0f;
      c.brightness = float(normalization.per_depth[size_t(c.depth)]);
    }
    for (uint64_t c = uint64_t(cluster_.rank()); c < chains; c += uint64_t(cluster_.size())) my_chains_.push_back(c);
    film_.set_splat_half_fraction(0.5);
    return true;
  }

  // Step 3's scale: a chain's deposits carry its depth's mean luminance over its chains, per
  // mutation; times the film's area they make the image.
  double splat_scale(uint64_t mutations) const {
    return mutations > 0 ? largest_ * double(scene_.camera().importance_film_pixels()) / double(mutations) : 0.0;
  }

  // Step 2: run the Markov chains (this rank's), per_chain_ mutations each unless stopped early
  // (interrupted, time limit, error target); returns the mutations each chain made.
  // The chains advance in rounds, every chain by the same number of mutations, so that a render
  // stopped between rounds (time limit, interruption) has every depth equally far along.
  // Rounds grow towards half a second each (how a chain's mutations are cut into rounds changes
  // nothing in what it computes, so the image stays the same whatever the timing).
  uint64_t run_markov_chains(double normalization_relative_error) {
    const uint64_t chains = chains_.size();
    uint64_t round_length = 16;
    uint64_t next_check = 16;  // with an error target: the next mutation count at which it is checked
    uint64_t mutations_per_chain = 0;
    bool first_round = true;
    while (mutations_per_chain < per_chain_) {
      // With an error target, rounds also end at fixed mutation counts (16, then 1.25x each time),
      // where the estimate is checked: where the render stops then depends on the chains, not the clock.
      const uint64_t steps = std::min({round_length, per_chain_ - mutations_per_chain,
                                       options_.target_error > 0 ? next_check - mutations_per_chain : round_length});
      const auto round_start = Clock::now();
      arena_.execute([&] {
        tbb::parallel_for(size_t(0), my_chains_.size(), [&](size_t mine) {
          BusyTimer busy(busy_nanoseconds_);
          mutate_chain(chains_[my_chains_[mine]], steps, first_round, ray_counts_.local());
          progress_.advance(steps);
        });
      });
      progress_.advance(steps * (chains - my_chains_.size()));  // the other ranks' chains
      first_round = false;
      mutations_per_chain += steps;
      // Viewers see the chains' image so far (in one process: across ranks each holds its own splats).
      if (options_.live && !cluster_.distributed()) {
        film_.set_splat_scale(splat_scale(mutations_per_chain));
        options_.live->pass_done(film_);
      }
      // The root's clock sets the rounds' length and the time limit for every rank.
      double round_seconds = cluster_.from_root(seconds_since(round_start));
      double growth = round_seconds > 0 ? std::clamp(0.5 / round_seconds, 0.5, 4.0) : 4.0;
      round_length = std::max<uint64_t>(1, uint64_t(double(round_length) * growth));
      if (cluster_.any(cancelled_())) {
        stats_.cancelled = true;
        break;
      }
      // With a time limit, the next round is cut to the mutations that still fit in it at this round's
      // pace, so that the render ends at the limit, not a round past it.
      if (mutations_per_chain < per_chain_ && options_.time_limit_seconds > 0) {
        const double fits = units_fitting_in_time_limit(cluster_, options_.time_limit_seconds, start_time_,
                                                        round_seconds, double(steps), double(round_length));
        if (fits < 1) {
          stats_.time_limited = true;
          break;
        }
        round_length = std::min(round_length, uint64_t(std::min(fits, double(per_chain_))));
      }
      if (options_.target_error > 0 && mutations_per_chain == next_check && mutations_per_chain < per_chain_) {
        next_check = std::max(next_check + 1, next_check * 5 / 4);
        film_.set_splat_scale(splat_scale(mutations_per_chain));
        if (agreed_error_estimate(cluster_, film_, normalization_relative_error) <= options_.target_error) {
          stats_.reached_target = true;
          break;
        }
      }
    }
    return mutations_per_chain;
  }

  // Step 2, the hot loop: `steps` mutations of one chain (its first state drawn first in the first
  // round), each proposal accepted or rejected by the Metropolis-Hastings ratio and both states
  // deposited into the film's splats.
  void mutate_chain(Chain& c, uint64_t steps, bool first_round, RayCounts& counts) {
    // (As locals: the loop reaches them without going through `this`.)
    Film& film = film_;
    const Filter& filter = filter_;
    const MltPathSampler& paths = paths_;
    const float large_step_probability = settings_.mlt.large_step;
    std::atomic<uint64_t>& non_finite = non_finite_;
    if (first_round) c.current = paths.sample(c.sampler, c.depth, counts);
    for (uint64_t m = 0; m < steps; ++m) {
      c.sampler.start_iteration(c.current.lens_moves(), c.current.caustic_moves());
      PathState proposed = paths.sample(c.sampler, c.depth, counts);
      float y_current = c.current.luminance(), y_proposed = proposed.luminance();
      // A small step's chance depends on the path it leaves (MltSampler::start_iteration):
      // Hastings' ratio of those chances keeps detailed balance (1 without perturbations).
      float accept = 1;
      if (y_current > 0) {
        float ratio = y_proposed / y_current;
        if (c.sampler.mutation() == MltSampler::Mutation::Small)
          ratio *= c.sampler.small_step_probability(proposed.lens_moves(), proposed.caustic_moves()) /
                   c.sampler.small_step_probability(c.current.lens_moves(), c.current.caustic_moves());
        accept = std::min(1.0f, ratio);
      }
      // Deposit both states, weighted by the probability that the chain moves or stays, with
      // Kelemen et al.'s weights: a large step is also an independent sample of the film, and
      // the two estimators are combined by their densities (p_large against f / b), so dim
      // regions that chains seldom visit are estimated by the large steps instead.
      float large = c.sampler.large_step() ? 1.0f : 0.0f;
      float floor_density = large_step_probability * c.brightness;
      const FilmSensor& sensor = scene_.film_sensor();
      auto deposit = [&](Vec2 raster, const RGB& radiance) {
        const RGB v = sensor.respond(radiance);
        if (!film.splats().add(raster, v, filter)) {
          non_finite.fetch_add(1, std::memory_order_relaxed);
        } else if (c.first_half) {
          film.half_splats().add(raster, v, filter);
        }
      };
      if (y_proposed > 0 && accept + large > 0)
        deposit(proposed.raster, proposed.L * ((accept + large) * c.scale / (y_proposed + floor_density)));
      if (accept < 1 && y_current > 0)
        deposit(c.current.raster, c.current.L * ((1 - accept) * c.scale / (y_current + floor_density)));
      if (c.rng.next_float() < accept) {
        c.current = proposed;
        c.sampler.accept();
      } else {
        c.sampler.reject();
      }
    }
  }

  // Step 3: add up the ranks' splats, scale them into the image (each depth's deposits by its
  // brightness over its number of chains, over the mutations per chain) and gather the statistics.
  RenderStats finish(uint64_t mutations_per_chain) {
    progress_.finish();
    if (cluster_.distributed()) {
      cluster_.sum_int64(film_.splats().sums());
      cluster_.sum_int64(film_.half_splats().sums());
    }
    film_.set_splat_scale(splat_scale(mutations_per_chain));
    stats_.seconds = seconds_since(start_time_);
    stats_.samples = mutations_per_chain * chains_.size();
    RayCounts chain_rays;
    for (const auto& c : ray_counts_) chain_rays += c;
    for (const RayCounts& r : cluster_.gather_values(chain_rays)) stats_.rays += r;  // added to the direct pass's
    for (uint64_t n : cluster_.gather_values(non_finite_.load())) stats_.non_finite_samples += n;
    std::vector<double> busy = cluster_.gather_values(double(busy_nanoseconds_.load()) * 1e-9);
    for (size_t r = 0; r < busy.size() && r < stats_.rank_busy_seconds.size(); ++r)
      stats_.rank_busy_seconds[r] += busy[r];
    return stats_;
  }

  const Scene& scene_;
  const RenderSettings& settings_;
  Film& film_;
  const RenderOptions& options_;
  Cluster& cluster_;
  const Clock::time_point start_time_;
  RenderStats stats_;
  MltStats details_;
  const RenderSettings bdpt_settings_;
  const BdptIntegrator bdpt_;
  const MltPathSampler paths_;
  const Filter filter_;
  const int depths_;
  tbb::task_arena arena_;
  tbb::enumerable_thread_specific<RayCounts> ray_counts_;
  std::atomic<uint64_t> busy_nanoseconds_{0};
  const std::function<bool()> cancelled_;
  const uint64_t total_mutations_;
  const uint64_t bootstrap_count_;  // one per depth and bootstrap sample
  ProgressBar progress_;
  // The chains (step 2): all of them, in order of depth, the ones this rank runs, the mutations
  // each makes, and the largest depth's share of the brightness per chain (the deposits' unit).
  std::vector<Chain> chains_;
  std::vector<uint64_t> my_chains_;
  uint64_t per_chain_ = 0;
  double largest_ = 0;
  std::atomic<uint64_t> non_finite_{0};
};

}  // namespace

RenderStats render_mlt(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options) {
  const auto start_time = Clock::now();
  Cluster& cluster = options.cluster ? *options.cluster : local_cluster();
  // Step 0: render depth 0 with the path tracer.
  RenderStats stats = render_depth_zero(scene, settings, film, options);
  MltStats details;
  details.direct_seconds = seconds_since(start_time);
  film.enable_splats();
  film.set_splat_scale(0);
  if (scene.lights().empty() || settings.max_depth == 0 || stats.cancelled) {
    stats.seconds = seconds_since(start_time);
    stats.details = details;
    return stats;
  }
  // Steps 1-3: bootstrap and normalization, chains, the splats' scale.
  MltRender mlt(scene, settings, film, options, cluster, start_time, stats, details);
  RenderStats result = mlt.run();
  result.details = mlt.details();
  return result;
}

}  // namespace candela
