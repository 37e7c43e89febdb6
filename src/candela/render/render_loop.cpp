#include "candela/render/render_loop.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <cstring>
#include <span>
#include <ctime>
#include <tuple>

#include "candela/base/error.h"
#include "candela/film/aov_film.h"
#include "candela/film/error_estimate.h"
#include "candela/render/film_part.h"
#include "candela/render/progress.h"

namespace candela {
namespace {

constexpr int kTileSize = 16;
// Across MPI ranks passes grow until they last this long (up to kLongestPassSpp samples per pixel).
constexpr double kDistributedPassSeconds = 2.0;
constexpr int kLongestPassSpp = 1024;
// With an error target the spp that meets it is predicted as spp (estimate / target)^(1 / this): the
// estimate falls a little faster than 1 / spp at the low counts where a loose target stops (QMC's
// nets converge faster, and the variance taken off the denominators shrinks). Measured on Bitterli's
// Cornell box (path) and veach-bidir (bdpt), seeds 11-15, checking every spp: 1.1 stops 6 spp (3%)
// sooner in all than 1 for one more check in all (docs/error-estimates.md).
constexpr double kErrorDecayExponent = 1.1;
constexpr int kPassSpp = 16;  // samples per pixel per pass in plain renders: a responsive progress bar, and
                               // runs of one pixel's samples long enough for samplers to reuse per-pixel work

// Everything one pass needs, shared by all tiles.
struct PassContext {
  const TileIntegrator& integrator;
  TileContext tile;
  tbb::enumerable_thread_specific<RayCounts>& ray_counts;
  const std::atomic<bool>* cancel;
  Cluster& cluster;
  std::atomic<uint64_t>& busy_nanoseconds;
  LiveFilm* live;
};

bool cancelled(const PassContext& pc) { return pc.cancel && pc.cancel->load(std::memory_order_relaxed); }

// A stride coprime to n near n / golden ratio: i -> i * stride mod n visits 0..n-1 once each, and any
// run of consecutive i lands all over the range (a rank-1 lattice).
uint64_t spread_stride(uint64_t n) {
  if (n < 3) return 1;
  uint64_t stride = std::max<uint64_t>(1, uint64_t(double(n) * 0.6180339887498949));
  while (std::gcd(stride, n) != 1) ++stride;
  return stride;
}

// About the samples a tile gets in a pass (as many per pixel as its first pixel's), for the progress
// bar of another rank's tiles.
uint64_t tile_samples(const Tile& tile, const SampleRanges& range) {
  return uint64_t(tile.x1 - tile.x0) * uint64_t(tile.y1 - tile.y0) * uint64_t(std::max(range(tile.x0, tile.y0).count, 0));
}

// One pass over the tiles: pixel (x, y) gets the samples range(x, y) names. Tiles not yet started
// when the cancel flag is set are skipped. Which thread or rank renders a tile changes nothing in
// its pixels; across ranks, the ranks then exchange the tiles they rendered, so that every rank's
// film is again the same.
void run_pass(const PassContext& pc, const std::vector<Tile>& tiles, tbb::task_arena& arena, const SampleRanges& range,
              ProgressBar& progress) {
  Film& film = pc.tile.film;
  // The tiles are handed out in a strided order that visits the whole image early and evenly, so that
  // any run of them costs about the same wherever the expensive regions are.
  const uint64_t n = tiles.size();
  const uint64_t stride = spread_stride(n);
  std::vector<uint8_t> handed = run_shared(
      pc.cluster, arena, n,
      [&](uint64_t item) {
        const uint64_t t = item * stride % n;
        if (cancelled(pc)) return;
        BusyTimer busy(pc.busy_nanoseconds);
        progress.advance(pc.integrator.render_tile(tiles[t], range, pc.tile, pc.ray_counts.local()));
        if (pc.live) pc.live->tile_done(film, tiles[t].x0, tiles[t].y0, tiles[t].x1, tiles[t].y1);
      },
      [&](uint64_t first, uint64_t count) {
        if (!progress.enabled()) return;
        for (uint64_t item = first; item < first + count; ++item) progress.advance(tile_samples(tiles[item * stride % n], range));
      });
  if (!pc.cluster.distributed()) return;
  std::vector<uint8_t> mine(n, 0);
  for (uint64_t item = 0; item < n; ++item) mine[item * stride % n] = handed[item];
  auto row_of = [&](const Tile& tile, int y) { return &film.pixels()[size_t(y) * size_t(film.width()) + size_t(tile.x0)]; };
  // The AOVs' sums travel with the film's (each row of the tile after the film's rows).
  AovFilm* aovs = pc.tile.aovs && pc.tile.aovs->has_sample_layers() ? pc.tile.aovs : nullptr;
  auto aov_row_bytes = [&](const Tile& tile) {
    return aovs ? sizeof(double) * aovs->doubles_per_pixel() * size_t(tile.x1 - tile.x0) : 0;
  };
  exchange_items(
      pc.cluster, mine,
      [&](uint64_t t, std::vector<std::byte>& out) {
        const Tile& tile = tiles[t];
        for (int y = tile.y0; y < tile.y1; ++y) {
          const auto* row = reinterpret_cast<const std::byte*>(row_of(tile, y));
          out.insert(out.end(), row, row + sizeof(PixelSums) * size_t(tile.x1 - tile.x0));
        }
        for (int y = tile.y0; y < tile.y1 && aovs; ++y) {
          const auto* row = reinterpret_cast<const std::byte*>(aovs->sums(tile.x0, y));
          out.insert(out.end(), row, row + aov_row_bytes(tile));
        }
      },
      [&](uint64_t t, const std::byte* in) {
        const Tile& tile = tiles[t];
        for (int y = tile.y0; y < tile.y1; ++y) {
          size_t row = sizeof(PixelSums) * size_t(tile.x1 - tile.x0);
          std::memcpy(row_of(tile, y), in, row);
          in += row;
        }
        for (int y = tile.y0; y < tile.y1 && aovs; ++y) {
          std::memcpy(aovs->sums(tile.x0, y), in, aov_row_bytes(tile));
          in += aov_row_bytes(tile);
        }
        return in;
      });
}

// ---- Adaptive sampling -------------------------------------------------------------------------

// Samples per randomised set in adaptive renders. Stratified and Poisson-disc sets must be rendered
// whole, so they are one batch. A ZSobol set spans the most a pixel can get: a pixel's samples are
// then the first n points of one net, as in a plain render of n samples.
int adaptive_set_size(const RenderSettings& settings) {
  if (settings.sampler.type == SamplerType::ZSobol)
    return int(std::bit_ceil(unsigned(std::max(settings.adaptive_spp_limit(), settings.adaptive_batch))));
  return settings.adaptive_batch;
}

// The smallest number of samples a pixel is given at a time.
int adaptive_granule(const RenderSettings& settings) {
  bool whole_sets = settings.sampler.type == SamplerType::Stratified || settings.sampler.type == SamplerType::Poisson;
  return whole_sets ? settings.adaptive_batch : 1;
}

// A pixel's relative deviation squared: n times its squared standard error over (mean^2 + 0.01),
// averaged over the channels. Its error after n samples is this over n, and its share of the
// image's relMSE (epsilon 0.01) falls the most per sample where this is largest.
double relative_deviation_sq(const PixelSums& pixel) {
  RGB mean = pixel.mean(), se = pixel.standard_error();
  double sum = 0;
  for (int c = 0; c < 3; ++c) sum += double(se[c]) * se[c] / (double(mean[c]) * mean[c] + 0.01);
  return double(pixel.count) * sum / 3;
}

// The mean of `v` over the (2r+1)^2 pixels around each pixel (fewer at the borders): one pixel's
// variance estimated from a few samples is itself very noisy, and neighbours' variances are alike.
std::vector<double> box_mean(const std::vector<double>& v, int w, int h, int r) {
  // Separably: the mean over the 2r+1 pixels along x, then of that along y.
  auto pass = [&](const std::vector<double>& in, bool along_y) {
    std::vector<double> out(in.size());
    const int size = along_y ? h : w;
    const size_t stride = along_y ? size_t(w) : 1;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const int at = along_y ? y : x;
        const size_t line_start = size_t(y) * w + x - size_t(at) * stride;
        double sum = 0;
        int n = 0;
        for (int i = std::max(0, at - r); i <= std::min(size - 1, at + r); ++i, ++n) sum += in[line_start + size_t(i) * stride];
        out[size_t(y) * w + x] = sum / n;
      }
    return out;
  };
  return pass(pass(v, false), true);
}

// How many samples each open pixel gets so that `total` are added and the counts come as close as
// the caps allow to lambda x deviation (the relMSE-optimal allocation: minimising sum r_i^2 / n_i
// at a fixed sum n_i gives n_i proportional to r_i): n_i' = clamp(lambda r_i, n_i, cap), lambda
// found by bisection. Whole granules only; fractions carry over to the next pixel in raster order,
// so the total comes out exact and the result does not depend on threads.
std::vector<int> allocate_samples(const std::vector<double>& deviation, const std::vector<uint64_t>& count,
                                  const std::vector<uint8_t>& open, int cap, double total, int granule) {
  const size_t n = deviation.size();
  auto added = [&](double lambda) {
    double sum = 0;
    for (size_t i = 0; i < n; ++i)
      if (open[i]) sum += std::clamp(lambda * deviation[i], double(count[i]), double(cap)) - double(count[i]);
    return sum;
  };
  double hi = 1;
  for (int i = 0; i < 200 && added(hi) < total; ++i) hi *= 2;
  double lo = 0;
  for (int i = 0; i < 60; ++i) {
    double mid = 0.5 * (lo + hi);
    (added(mid) < total ? lo : hi) = mid;
  }
  std::vector<int> give(n, 0);
  double carry = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!open[i]) continue;
    double want = std::clamp(hi * deviation[i], double(count[i]), double(cap)) - double(count[i]) + carry;
    int granules = int(std::floor(want / granule + 0.5));
    granules = std::clamp(granules, 0, int((uint64_t(cap) - count[i]) / uint64_t(granule)));
    give[i] = granules * granule;
    carry = want - give[i];
  }
  // The bisection's tolerance and the caps can leave the sum a granule or so off: settle the
  // difference on the last pixels that can take or give one.
  int64_t surplus = -int64_t(total / granule) * granule;
  for (int g : give) surplus += g;
  for (size_t i = n; i-- > 0 && surplus != 0;) {
    if (!open[i]) continue;
    if (surplus > 0 && give[i] > 0) {
      give[i] -= granule;
      surplus -= granule;
    } else if (surplus < 0 && count[i] + uint64_t(give[i] + granule) <= uint64_t(cap)) {
      give[i] += granule;
      surplus += granule;
    }
  }
  return give;
}

// Adaptive sampling (sec. 4.3; see RenderSettings): rounds of passes, each pixel's share of the
// next round decided from the film alone between rounds, so the result does not depend on threads.
template <typename StopAfterPass>
void render_adaptive(const PassContext& pc, const std::vector<Tile>& tiles, tbb::task_arena& arena,
                     ProgressBar& progress, const RenderSettings& settings, const RenderOptions& options,
                     StopAfterPass stop_after_pass) {
  Film& film = pc.tile.film;
  const int w = film.width(), h = film.height();
  const size_t pixels = size_t(w) * h;
  const int batch = settings.adaptive_batch, cap = std::max(settings.adaptive_spp_limit(), batch);
  const int granule = adaptive_granule(settings);
  std::vector<uint8_t> in_image(pixels, 1);  // the pixels this render may sample
  if (options.only_x >= 0) {
    std::fill(in_image.begin(), in_image.end(), 0);
    in_image[size_t(options.only_y) * w + options.only_x] = 1;
  }
  const uint64_t sampled_pixels = options.only_x >= 0 ? 1 : pixels;
  const uint64_t budget = settings.adaptive_spp > 0 ? uint64_t(settings.adaptive_spp) * sampled_pixels : 0;

  // Every pixel starts with one batch.
  std::vector<int> give(pixels, 0);
  for (size_t i = 0; i < pixels; ++i) give[i] = in_image[i] ? std::min(batch, cap) : 0;
  uint64_t spent = 0;
  std::vector<uint64_t> count(pixels);
  std::vector<double> error(pixels), deviation_sq(pixels);
  std::vector<uint8_t> open(pixels);
  for (;;) {
    run_pass(pc, tiles, arena,
             [&](int x, int y) {
               size_t i = size_t(y) * w + x;
               return SampleRange{int64_t(film.pixel(x, y).count), give[i]};
             },
             progress);
    if (options.live) options.live->pass_done(film);
    for (int g : give) spent += uint64_t(g);
    bool more = budget > 0 ? spent < budget : true;
    if (stop_after_pass(more) || !more) break;

    // Each pixel's errors, from its own samples. With a budget, where the film has two independent
    // halves (and no splats, which each rank holds only its own of until the end), each pixel's
    // share comes from the error estimate's per-pixel errors: their denominators resist fireflies,
    // which the per-sample rule reads as noise-free pixels and starves (veach-mis, 64 spp, 3 seeds:
    // relMSE 0.018, 4.9, 0.019 against the per-sample rule's 0.050, 4.9, 0.19 and uniform's 0.033,
    // 0.55, 0.022; the Cornell box 3% behind the per-sample rule; docs/error-estimates.md).
    std::vector<double> half_errors;
    const bool halves = budget > 0 && !film.has_splats() && estimate_error(film, 0, &half_errors).valid;
    arena.execute([&] {
      tbb::parallel_for(0, h, [&](int y) {
        for (int x = 0; x < w; ++x) {
          size_t i = size_t(y) * w + x;
          const PixelSums& p = film.pixel(x, y);
          count[i] = p.count;
          if (settings.adaptive_threshold > 0) error[i] = relative_error(p);
          if (budget > 0) deviation_sq[i] = relative_deviation_sq(p);
          if (halves && !std::isnan(half_errors[i])) deviation_sq[i] = half_errors[i] * double(p.count);
        }
      });
    });
    // Pixels whose relative error (RMS over the 3x3 neighbourhood) is below the threshold, and
    // pixels at the cap, are done.
    bool any_open = false;
    if (settings.adaptive_threshold > 0) {
      std::vector<double> error_sq(pixels);
      for (size_t i = 0; i < pixels; ++i) error_sq[i] = error[i] * error[i];
      error_sq = box_mean(error_sq, w, h, 1);
      for (size_t i = 0; i < pixels; ++i) error[i] = std::sqrt(error_sq[i]);
    }
    for (size_t i = 0; i < pixels; ++i) {
      open[i] = in_image[i] && count[i] < uint64_t(cap) &&
                (settings.adaptive_threshold <= 0 || error[i] > settings.adaptive_threshold);
      any_open = any_open || open[i];
    }
    if (!any_open) break;

    if (budget == 0) {
      // No budget: another batch for every open pixel.
      for (size_t i = 0; i < pixels; ++i) give[i] = open[i] ? int(std::min<uint64_t>(batch, cap - count[i])) : 0;
      continue;
    }
    // A budget: each round adds as many samples as the film holds (or what is left), so the
    // estimates the allocation rests on get better as it spends more. Deviations are smoothed over
    // 3x3 pixels (5x5 and 9x9 were no better on the Cornell box) and kept above a small floor, so
    // no pixel is starved on the word of a few samples.
    std::vector<double> deviation = box_mean(deviation_sq, w, h, 1);
    double mean_deviation = 0;
    for (size_t i = 0; i < pixels; ++i) {
      deviation[i] = std::sqrt(deviation[i]);
      if (in_image[i]) mean_deviation += deviation[i] / double(sampled_pixels);
    }
    for (double& d : deviation) d = std::max(d, 0.05 * mean_deviation);
    give = allocate_samples(deviation, count, open, cap, double(std::min(budget - spent, spent)), granule);
    if (std::all_of(give.begin(), give.end(), [](int g) { return g == 0; })) break;
  }
}

// After the last pass across ranks, what they rendered besides the film: the non-finite samples,
// rays and busy time of every rank, and the splats of their light paths (integer sums, so adding
// them is exact whatever the order).
void combine_ranks(Cluster& cluster, Film& film, const RenderOptions& options, int limit, RenderStats& stats) {
  uint64_t non_finite = 0;
  for (uint64_t n : cluster.gather_values(stats.non_finite_samples)) non_finite += n;
  stats.non_finite_samples = non_finite;
  RayCounts rays;
  for (const RayCounts& r : cluster.gather_values(stats.rays)) rays += r;
  stats.rays = rays;
  NonFiniteLog first(limit);
  for (const auto& bytes : cluster.all_gather(std::as_bytes(std::span(stats.first_non_finite))))
    for (size_t at = 0; at + sizeof(NonFiniteSample) <= bytes.size(); at += sizeof(NonFiniteSample)) {
      NonFiniteSample n;
      std::memcpy(&n, bytes.data() + at, sizeof n);
      first.add(n.x, n.y, n.sample);
    }
  stats.first_non_finite = first.samples();
  stats.rank_busy_seconds = cluster.gather_values(stats.rank_busy_seconds.at(0));
  int threads = 0;
  for (int t : cluster.gather_values(stats.threads)) threads += t;
  stats.threads = threads;
  if (film.has_splats()) {
    cluster.sum_int64(film.splats().sums());
    cluster.sum_int64(film.half_splats().sums());
  }
  if (options.integrator_outputs) options.integrator_outputs->sum_across(cluster);
}

}  // namespace

namespace {
uint64_t thread_cpu_nanoseconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return uint64_t(t.tv_sec) * 1000000000u + uint64_t(t.tv_nsec);
}
}  // namespace

BusyTimer::BusyTimer(std::atomic<uint64_t>& total) : total_(total), start_(thread_cpu_nanoseconds()) {}
BusyTimer::~BusyTimer() { total_.fetch_add(thread_cpu_nanoseconds() - start_, std::memory_order_relaxed); }

std::vector<uint8_t> run_shared(Cluster& cluster, tbb::task_arena& arena, uint64_t items,
                                const std::function<void(uint64_t)>& body,
                                const std::function<void(uint64_t, uint64_t)>& granted) {
  std::vector<uint8_t> mine(items, 0);
  const int threads = arena.max_concurrency();
  cluster.share_work(
      items, threads,
      [&](const Cluster::NextItem& next) {
        arena.execute([&] {
          tbb::parallel_for(0, threads, 1, [&](int) {
            while (std::optional<uint64_t> item = next()) {
              mine[*item] = 1;
              body(*item);
            }
          });
        });
      },
      granted);
  return mine;
}

void exchange_items(Cluster& cluster, const std::vector<uint8_t>& mine,
                    const std::function<void(uint64_t, std::vector<std::byte>&)>& write,
                    const std::function<const std::byte*(uint64_t, const std::byte*)>& read) {
  // Kept from call to call (only the calling thread exchanges): a pass's worth of tiles is as large
  // as the film, and fresh buffers would be paged in every pass.
  thread_local std::vector<std::byte> bytes, all;
  thread_local std::vector<uint64_t> offsets;
  bytes.clear();
  for (uint64_t item = 0; item < mine.size(); ++item) {
    if (!mine[item]) continue;
    const auto* id = reinterpret_cast<const std::byte*>(&item);
    bytes.insert(bytes.end(), id, id + sizeof item);
    write(item, bytes);
  }
  cluster.all_gather(bytes, all, offsets);
  for (int r = 0; r + 1 < int(offsets.size()); ++r) {
    if (r == cluster.rank()) continue;
    const std::byte* in = all.data() + offsets[size_t(r)];
    const std::byte* end = all.data() + offsets[size_t(r) + 1];
    while (in < end) {
      uint64_t item;
      std::memcpy(&item, in, sizeof item);
      if (item >= mine.size()) throw InternalError("exchange_items: an item out of range came from rank " + std::to_string(r));
      in = read(item, in + sizeof item);
    }
  }
}

std::vector<Tile> make_tiles(int width, int height) {
  std::vector<Tile> tiles;
  for (int y = 0; y < height; y += kTileSize)
    for (int x = 0; x < width; x += kTileSize)
      tiles.push_back({x, y, std::min(x + kTileSize, width), std::min(y + kTileSize, height)});
  return tiles;
}

NonFiniteLog::NonFiniteLog(int limit) : limit_(size_t(std::max(limit, 0))) {}

void NonFiniteLog::add(int x, int y, uint64_t s) {
  std::lock_guard lock(mutex_);
  NonFiniteSample n{x, y, s};
  auto less = [](const NonFiniteSample& a, const NonFiniteSample& b) {
    return std::tie(a.sample, a.y, a.x) < std::tie(b.sample, b.y, b.x);
  };
  if (samples_.size() == limit_ && (limit_ == 0 || !less(n, samples_.back()))) return;
  samples_.insert(std::upper_bound(samples_.begin(), samples_.end(), n, less), n);
  if (samples_.size() > limit_) samples_.pop_back();
}

double units_fitting_in_time_limit(Cluster& cluster, double time_limit_seconds,
                                   std::chrono::steady_clock::time_point start, double last_seconds,
                                   double last_units, double if_unknown) {
  const double left =
      time_limit_seconds - std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return cluster.from_root(last_seconds > 0 ? std::floor(left / (last_seconds / last_units)) : if_unknown);
}

double agreed_error_estimate(Cluster& cluster, const Film& film, double scale_relative_error) {
  double e = std::numeric_limits<double>::infinity();
  auto estimate = [&](const Film& f) {
    ErrorEstimate estimate = estimate_error(f, scale_relative_error);
    if (estimate.valid) e = estimate.relmse;
  };
  if (cluster.distributed() && film.has_splats()) {
    Film total = film;
    cluster.sum_int64(total.splats().sums());
    cluster.sum_int64(total.half_splats().sums());
    if (cluster.is_root()) estimate(total);
  } else if (cluster.is_root()) {
    estimate(film);
  }
  return cluster.from_root(e);
}

float relative_error(const PixelSums& pixel) {
  RGB mean = pixel.mean(), se = pixel.standard_error();
  float worst = 0;
  for (int c = 0; c < 3; ++c) worst = std::max(worst, se[c] / std::sqrt(mean[c] * mean[c] + 0.01f));
  return worst;
}

RenderStats render_tiles(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options,
                         const TileIntegrator& integrator) {
  if (options.only_x >= film.width() || options.only_y >= film.height() || (options.only_x >= 0) != (options.only_y >= 0))
    throw InternalError("pixel to render is outside the image");
  auto start = std::chrono::steady_clock::now();
  const bool adaptive = settings.adaptive();
  const int max_spp = adaptive ? std::max(settings.adaptive_spp_limit(), settings.adaptive_batch) : settings.spp;

  const Filter filter(settings.filter);
  const bool target = options.target_error > 0 && !adaptive;
  // With replicas the set-based samplers come in sets of half the samples, or of one pass when the
  // render stops at an error target: the sets alternate between the film's halves.
  const SamplerType sampler_type = settings.sampler.type;
  const bool set_based = sampler_type == SamplerType::Stratified || sampler_type == SamplerType::Poisson;
  int set_size = adaptive ? adaptive_set_size(settings) : settings.spp;
  if (settings.sampler.replicas && set_based && !adaptive) set_size = target ? kPassSpp : std::max(1, (settings.spp + 1) / 2);
  const Sampler prototype = make_sampler(settings.sampler, set_size, settings.seed, film.width(), film.height());
  std::vector<Tile> tiles = options.only_x >= 0 ? std::vector<Tile>{{options.only_x, options.only_y,
                                                                     options.only_x + 1, options.only_y + 1}}
                                                : make_tiles(film.width(), film.height());
  const uint64_t pixel_count = options.only_x >= 0                ? 1
                               : options.part_count > 1 ? uint64_t(film.width()) * film.height() / uint64_t(options.part_count)
                                                        : uint64_t(film.width()) * film.height();
  if (options.part_count > 1) {
    // A job-array part: every part_count-th tile, from part_index on.
    std::vector<Tile> share;
    for (size_t t = 0; t < tiles.size(); ++t)
      if (tile_in_part(t, options.part_index, options.part_count)) share.push_back(tiles[t]);
    tiles = std::move(share);
  }
  Cluster& cluster = options.cluster ? *options.cluster : local_cluster();
  tbb::enumerable_thread_specific<RayCounts> ray_counts;
  std::atomic<uint64_t> non_finite{0}, busy_nanoseconds{0};
  NonFiniteLog non_finite_log(options.max_reported_non_finite);
  PassContext pc{integrator,
                 {scene, filter, prototype, film, non_finite, non_finite_log, options.clamp, settings.spectral,
                  half_block(settings.sampler, set_size), options.aovs, settings.seed},
                 ray_counts,
                 options.cancel,
                 cluster,
                 busy_nanoseconds,
                 options.live};
  const uint64_t samples_before = film.total_samples();
  const uint64_t expected_spp = adaptive && settings.adaptive_spp > 0 ? uint64_t(settings.adaptive_spp) : uint64_t(max_spp);
  ProgressBar progress(pixel_count * expected_spp, options.progress, options.progress_fraction);
  progress.advance(options.only_x >= 0 ? 0 : samples_before);
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  RenderStats stats;
  // After a whole pass: true when the render must stop (cancelled, or out of time).
  // Across ranks the answer is agreed: any rank's interruption stops all, and the root's clock
  // decides the time limit.
  auto stop_after_pass = [&](bool more_to_do) {
    if (cluster.any(cancelled(pc))) {
      stats.cancelled = true;
      return true;
    }
    if (more_to_do && options.time_limit_seconds > 0 &&
        cluster.from_root(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >=
                          options.time_limit_seconds)) {
      stats.time_limited = true;
      return true;
    }
    return false;
  };

  if (!adaptive) {
    // A Poisson-disc set is built per pixel: render it in one pass rather than rebuilding it per pass.
    // Every pixel continues from its own count, so a film resumed from a checkpoint (or one whose
    // last pass was cut short) gets exactly the samples an uninterrupted render would add, in order.
    int pass_spp = sampler_type == SamplerType::Poisson ? set_size : kPassSpp;
    // With an error target: where the estimate says the target will be met (the error of the mean
    // falls about as 1 / spp), so that the last pass does not overshoot by much; the first estimate as
    // soon as both halves have a few samples (ZSobol's replicas 8 each, independent samples 4), so
    // that a loose target is not overshot by a whole pass either.
    // The estimate is checked there, or where the spp has doubled since the last check (a pass over
    // the pixels each time: not after every pass of a long render).
    int64_t target_end = target && !set_based ? std::max<int64_t>(8, 2 * int64_t(pc.tile.half_block)) : settings.spp;
    int64_t last_check = 0;
    // With a time limit: where the samples that still fit in it end (predicted from the pace of the
    // pass before), so that the last pass is cut to them rather than run whole past the limit. Not
    // with set-based samplers, whose sets must not be cut short.
    int64_t time_end = settings.spp;
    uint64_t least = options.only_x >= 0 ? film.pixel(options.only_x, options.only_y).count : film.min_samples();
    const int first_pass = int(std::min<uint64_t>(least, uint64_t(settings.spp)) / uint64_t(pass_spp)) * pass_spp;
    for (int pass = first_pass, end = 0; pass < settings.spp; pass = end) {
      end = int(std::min<int64_t>({int64_t(pass) + pass_spp, int64_t(settings.spp), std::max<int64_t>(target_end, pass + 1),
                                   std::max<int64_t>(time_end, pass + 1)}));
      const auto pass_start = std::chrono::steady_clock::now();
      run_pass(pc, tiles, arena,
               [&](int x, int y) {
                 int64_t have = int64_t(film.pixel(x, y).count);
                 return SampleRange{have, int(std::max<int64_t>(0, end - have))};
               },
               progress);
      if (options.live) options.live->pass_done(film);
      bool stop = stop_after_pass(end < settings.spp);
      if (!stop && options.time_limit_seconds > 0 && !set_based && end < settings.spp) {
        const double fits = units_fitting_in_time_limit(
            cluster, options.time_limit_seconds, start,
            std::chrono::duration<double>(std::chrono::steady_clock::now() - pass_start).count(), double(end - pass),
            double(settings.spp));
        if (fits < 1) {
          stats.time_limited = true;
          stop = true;
        } else {
          time_end = end + int64_t(std::min(fits, double(settings.spp)));
        }
      }
      if (target && !stop && end < settings.spp && (end >= target_end || end >= 2 * last_check)) {
        last_check = end;
        const double e = arena.execute([&] { return agreed_error_estimate(cluster, film); });
        if (e <= options.target_error) {
          stats.reached_target = true;
          stop = true;
        } else if (!std::isfinite(e)) {
          target_end = settings.spp;  // no estimate yet: plain passes until there is one
        } else {
          // The estimate holds for halves of unequal size, so the render may stop at any sample
          // count, except inside a set of a set-based sampler (a partial set would leave part of the
          // pixel unsampled): there whole blocks of the halves, at least one more of each half.
          const int64_t block = set_based ? int64_t(pc.tile.half_block) : 1;
          const double predicted = double(end) * std::pow(e / options.target_error, 1 / kErrorDecayExponent);
          target_end = std::max<int64_t>(end + block, int64_t(std::ceil(predicted / double(block))) * block);
        }
      }
      if (options.after_pass && !stats.cancelled) {
        uint64_t non_finite_so_far = 0;
        for (uint64_t n : cluster.gather_values(non_finite.load())) non_finite_so_far += n;
        options.after_pass(film, non_finite_so_far);
      }
      if (stop) break;
      // Across ranks every pass ends with the film's exchange: passes grow (the root's clock decides)
      // until they take a few seconds, so that it stays a small part of the time. Where passes end
      // changes nothing in the image: every pixel continues from its own count.
      // With an error target the passes stay as they are, so that where the render stops depends on
      // the film alone, not on the clock: the same image for any number of ranks.
      if (cluster.distributed() && !target &&
          cluster.from_root(std::chrono::duration<double>(std::chrono::steady_clock::now() - pass_start).count()) <
              kDistributedPassSeconds)
        pass_spp = std::min(2 * pass_spp, kLongestPassSpp);
    }
  } else {
    if (samples_before > 0) throw InternalError("adaptive sampling cannot continue a partly rendered film");
    render_adaptive(pc, tiles, arena, progress, settings, options, stop_after_pass);
  }
  progress.finish();

  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.samples = film.total_samples() - samples_before;
  stats.non_finite_samples = non_finite.load();
  stats.first_non_finite = non_finite_log.samples();
  stats.cancelled = cluster.any(stats.cancelled || cancelled(pc));
  for (const auto& c : ray_counts) stats.rays += c;
  stats.rank_busy_seconds = {double(busy_nanoseconds.load()) * 1e-9};
  stats.threads = arena.max_concurrency();
  if (cluster.distributed()) combine_ranks(cluster, film, options, options.max_reported_non_finite, stats);
  return stats;
}

}  // namespace candela
