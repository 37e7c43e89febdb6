#pragma once
// The render loop that the integrators tracing camera samples share (pbrt-v4's ImageTileIntegrator):
// the image is cut into tiles, the samples into passes; each pass renders every tile in parallel
// with oneTBB. Every pixel sample draws its random numbers as a function of (pixel, sample index,
// seed) and each pixel accumulates its samples in sample order, so the image is bitwise identical
// for any thread count.
//
// Adaptive sampling (Häkkinen 2002, sec. 4.3): all pixels first get one batch of F samples (F a
// power of two, so stratification holds within the batch); then, round by round, pixels whose
// relative standard error still exceeds the threshold get another batch, up to the maximum spp, or,
// with a budget of samples, each pixel gets a share proportional to its estimated relative
// deviation (RenderSettings::adaptive_spp).
//
// Across MPI ranks (RenderOptions::cluster) the tiles of each pass are handed out dynamically, every
// rank keeps the whole film, and the ranks exchange the tiles they rendered after each pass, so the
// image is bitwise the one a single process renders (render/cluster.h).
//
// An integrator gives the loop a TileIntegrator (usually CameraSampleTiles, render/camera_sample_tiles.h,
// around its radiance function); integrators/integrator.h chooses the integrator.
#include <any>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "candela/film/film.h"
#include "candela/film/filter.h"
#include "candela/film/live_film.h"
#include "candela/render/cluster.h"
#include "candela/sampling/samplers.h"
#include "candela/scene/scene.h"

namespace candela {

class AovFilm;  // film/aov_film.h

// What an integrator makes besides the film, in a form only it knows: its registry entry makes them
// for a request that asks (integrators/integrator.h), the integrator fills them as it renders, the
// loop adds up the ranks' shares after the last pass, and the caller writes them once the film is
// final. Contributions are scaled like the film's splats.
class IntegratorOutputs {
 public:
  virtual ~IntegratorOutputs() = default;
  // Adds up every rank's share, called on every rank at the same point (one process: nothing to do).
  virtual void sum_across(Cluster& cluster) = 0;
  // Writes them, scaled as `film`'s splats are, with the image's metadata.
  virtual void write(const Film& film, const std::map<std::string, std::string>& metadata) const = 0;
};

struct RenderOptions {
  int threads = 0;       // 0 = all cores
  bool progress = true;  // draw a progress bar when stderr is a terminal
  // When set, the fraction of the work done (0 to 1) is stored here as the render advances, for a
  // caller that shows progress its own way (the Python module polls it).
  std::atomic<double>* progress_fraction = nullptr;
  // Set (e.g. by a signal handler) to stop: checked before every tile and between passes, so the
  // render stops within one tile. Pixels keep the samples they have; each pixel's count says how many.
  const std::atomic<bool>* cancel = nullptr;
  // Stop after the first whole pass (batch) that ends at or after this many seconds; 0 = no limit.
  double time_limit_seconds = 0;
  // > 0: each sample's RGB is scaled so its largest component is at most this (biased).
  float clamp = 0;
  // Render only this pixel (all its samples); the rest of the film stays empty. -1 = every pixel.
  int only_x = -1, only_y = -1;
  // How many non-finite samples to report (the ones with the smallest (sample, y, x)).
  int max_reported_non_finite = 5;
  // Called between whole passes (never while tiles run) with the film as it stands, e.g. to write
  // a checkpoint, and the number of non-finite samples dropped so far in this call (by all ranks).
  // Across ranks it is called on every rank at the same passes; the film's splats are then this
  // rank's own (add them with Cluster::sum_int64). Not called for adaptive renders.
  std::function<void(const Film&, uint64_t non_finite_so_far)> after_pass;
  // When set, what the integrator makes besides the film (IntegratorOutputs below), which only that
  // integrator fills and knows the meaning of; the loop adds it up across the ranks.
  IntegratorOutputs* integrator_outputs = nullptr;
  // The processes rendering this image together; null = this process alone. Every rank calls the
  // render with the same scene, settings and film; after it every rank's film holds the whole image
  // (splats included), and the stats count every rank's samples, rays and non-finite values.
  Cluster* cluster = nullptr;
  // Job-array parts (--part K/N): render only the tiles whose index is K-1 modulo N. {0, 1} = all.
  int part_index = 0, part_count = 1;
  // > 0: render until the image's estimated relMSE (film/error_estimate.h) is at most this, up to
  // settings.spp samples per pixel (or the time limit). Needs independent halves (SamplerDesc::replicas).
  double target_error = 0;
  // When set, the AOV layers (film/aov_film.h) of every camera sample are added here, sized like the
  // film (render/first_hit_aovs.h). Drawn from random numbers of their own: the film is unchanged.
  AovFilm* aovs = nullptr;
  // When set, each tile's pixels are copied there as the tile finishes and the whole film after each
  // pass, for viewers watching the render (the browser preview, tev; film/live_film.h).
  LiveFilm* live = nullptr;
};

struct NonFiniteSample {
  int x = 0, y = 0;
  uint64_t sample = 0;  // sample index within the pixel
};

struct RenderStats {
  double seconds = 0;
  uint64_t samples = 0;             // rendered in this call (a resumed render's earlier ones excluded)
  uint64_t non_finite_samples = 0;  // NaN/inf radiance values, dropped (counted as black)
  std::vector<NonFiniteSample> first_non_finite;  // up to max_reported_non_finite, by (sample, y, x)
  bool cancelled = false;                         // stopped by RenderOptions::cancel
  bool time_limited = false;                      // stopped by the time limit before all samples
  bool reached_target = false;                    // stopped at RenderOptions::target_error
  RayCounts rays;
  // Per rank, the thread-seconds it spent rendering (tiles, or Markov chains), and the threads of
  // all ranks: the job's parallel efficiency is the busy time over threads x wall time.
  std::vector<double> rank_busy_seconds;
  int threads = 1;
  // The standard error, relative to it, of an estimated factor that scales the film's splats (0:
  // the scale is exact), which the image's error estimate adds (film/error_estimate.h).
  double splat_scale_relative_error = 0;
  // Seconds spent before the first sample that counts towards the image could be taken, which a
  // longer render does not repeat (set-up such as a bootstrap; 0 for most integrators).
  double setup_seconds = 0;
  // What the integrator reports beyond these, in a type of its own that the integrator's header
  // declares and reads back (std::any_cast); empty for most.
  std::any details;
};

// The relative error adaptive sampling compares with its threshold: the largest over the channels
// of standard error / sqrt(mean^2 + 0.01), the per-pixel form of relMSE with epsilon 0.01.
float relative_error(const PixelSums& pixel);

// The non-finite samples to report: the `limit` smallest by (sample, y, x), so the list does not
// depend on thread timing.
class NonFiniteLog {
 public:
  explicit NonFiniteLog(int limit);
  void add(int x, int y, uint64_t sample);
  std::vector<NonFiniteSample> samples() const { return samples_; }

 private:
  size_t limit_;
  std::mutex mutex_;
  std::vector<NonFiniteSample> samples_;
};

struct Tile {
  int x0, y0, x1, y1;
};

// Which samples a pixel gets in a pass: [first, first + count); count <= 0 skips the pixel.
struct SampleRange {
  int64_t first;
  int count;
};
using SampleRanges = std::function<SampleRange(int x, int y)>;

// What every tile of a render shares.
struct TileContext {
  const Scene& scene;
  const Filter& filter;
  const Sampler& prototype;  // copied per tile: samplers carry per-sample state
  Film& film;
  std::atomic<uint64_t>& non_finite;
  NonFiniteLog& non_finite_log;
  float clamp;
  bool spectral;
  // Sample i of a pixel is in the film's first half when (i / half_block) is even (half_block()).
  uint64_t half_block;
  bool first_half(uint64_t sample_index) const { return (sample_index / half_block) % 2 == 0; }
  // RenderOptions::aovs, and the seed their random numbers are drawn with (render/first_hit_aovs.h).
  AovFilm* aovs = nullptr;
  uint64_t seed = 0;
};

// An integrator as the loop sees it: renders the samples `range` names for every pixel of a tile,
// adding them to context.film, and returns how many it rendered. Called concurrently for different
// tiles (never for two tiles that share a pixel).
class TileIntegrator {
 public:
  virtual ~TileIntegrator() = default;
  virtual uint64_t render_tile(const Tile& tile, const SampleRanges& range, const TileContext& context,
                               RayCounts& counts) const = 0;
};

// Adds the CPU time the calling thread spends from its construction to its destruction to `total`
// (nanoseconds): the busy time behind the parallel efficiency. CPU time, not wall time, so that
// ranks sharing cores (oversubscribed) still report the work they did.
class BusyTimer {
 public:
  explicit BusyTimer(std::atomic<uint64_t>& total);
  ~BusyTimer();
  BusyTimer(const BusyTimer&) = delete;
  BusyTimer& operator=(const BusyTimer&) = delete;

 private:
  std::atomic<uint64_t>& total_;
  uint64_t start_;
};

// Runs body(item) for the items [0, items) on `arena`'s threads, the items handed out dynamically
// across the cluster's ranks (each item runs on one rank). Returns which items ran on this rank.
std::vector<uint8_t> run_shared(Cluster& cluster, tbb::task_arena& arena, uint64_t items,
                                const std::function<void(uint64_t item)>& body,
                                const std::function<void(uint64_t first, uint64_t count)>& granted = nullptr);

// After run_shared across ranks: every rank sends what its items produced (`write` appends item's
// bytes) and takes in the others' (`read` consumes one item's bytes from `in` and returns the
// position after them), so every rank ends with every item's result.
void exchange_items(Cluster& cluster, const std::vector<uint8_t>& mine,
                    const std::function<void(uint64_t item, std::vector<std::byte>& out)>& write,
                    const std::function<const std::byte*(uint64_t item, const std::byte* in)>& read);

// The film's estimated relMSE (film/error_estimate.h; infinity when it has no estimate), computed
// by the root and agreed. Across ranks, where each rank's film holds only its own splats, they are
// added up first (in a copy).
double agreed_error_estimate(Cluster& cluster, const Film& film, double scale_relative_error = 0);

// With a time limit started at `start`: how many more units of work (a pass's spp, a Markov chain's
// mutations) fit in what is left of it, at the pace of the last `last_units`, which took
// `last_seconds` (`if_unknown` when that took no measurable time). The root's clock decides, so that
// every rank cuts the same pass. Below 1: none fits.
double units_fitting_in_time_limit(Cluster& cluster, double time_limit_seconds,
                                   std::chrono::steady_clock::time_point start, double last_seconds,
                                   double last_units, double if_unknown);

// The tiles a film is cut into, in the order the loop hands them out (row by row of tiles).
std::vector<Tile> make_tiles(int width, int height);

// Renders settings.spp samples per pixel into `film` (sized to the camera's resolution) with
// `integrator`, or adaptively when settings.adaptive(). Without adaptive sampling the film may
// already hold samples (a resumed checkpoint): each pixel continues from its own sample count, so
// the result is bitwise the same as one uninterrupted render.
RenderStats render_tiles(const Scene& scene, const RenderSettings& settings, Film& film, const RenderOptions& options,
                         const TileIntegrator& integrator);

}  // namespace candela
