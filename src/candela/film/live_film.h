#pragma once
// The image as it renders, for viewers that watch a render (the browser preview and the tev client,
// preview/): the render loop copies each tile's pixel means here when the tile is done (its worker
// owns those pixels then, so the copy races with nothing) and the whole film between passes
// (splats included); viewers take copies under the same lock. Every change bumps a version and marks
// the rows it touched, so a viewer sends only the rows changed since the version it last sent.
//
// The render side costs one lock and a mean per pixel per tile: well under 1% of a tile's samples.
// Between passes the error estimate (film/error_estimate.h, or where the film has no independent
// halves the per-sample variance form of the same relMSE) is recorded at most once a second, for the
// page's convergence curve.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "candela/film/film.h"

namespace candela {

enum class LiveState { Waiting, Rendering, Finished, Stopped };

// One point of the convergence curve.
struct ErrorPoint {
  double seconds = 0;  // since the render started
  double relmse = 0;   // estimated relMSE (epsilon 0.01)
  double low = 0, high = 0;  // its 95% interval (equal to relmse for the per-sample form)
  double mean_spp = 0;
};

struct LiveStatus {
  LiveState state = LiveState::Waiting;
  std::string description;  // scene and integrator, for the page's title
  int width = 0, height = 0;
  double seconds = 0;       // since the render started
  double fraction = 0;      // of the planned samples (0 to 1)
  double eta_seconds = -1;  // < 0: unknown
  double mean_spp = 0;               // as tiles land
  uint64_t min_spp = 0, max_spp = 0;  // after the last whole pass
  uint64_t planned_spp = 0;  // per pixel (adaptive renders: the mean budget, or else the maximum)
  bool adaptive = false;
  bool halves = false;  // the error curve is the two-halves estimate (else the per-sample form)
  double time_limit_seconds = 0, target_error = 0;
  uint64_t version = 0;
  std::vector<ErrorPoint> error_history;
};

// A viewer's copy of the image: linear RGB means and samples per pixel, row-major, top row first.
struct LiveSnapshot {
  int width = 0, height = 0;
  std::vector<float> rgb;                // 3 per pixel
  std::vector<float> spp;                // 1 per pixel
  std::vector<uint64_t> row_version;     // per row: the version that last changed it
  uint64_t version = 0;
};

class LiveFilm {
 public:
  LiveFilm(int width, int height);

  // ---- Render side.
  // The render starts: the clock, what is rendered, and the plan (for the ETA).
  void start(std::string description, uint64_t planned_spp, bool adaptive, double time_limit_seconds,
             double target_error);
  // The fraction of the planned work done, as the progress bar sees it (RenderOptions::progress_fraction).
  std::atomic<double>& progress_fraction() { return fraction_; }
  // Tile [x0, x1) x [y0, y1) of `film` is done for this pass; the caller's thread owns its pixels.
  // Films with splats are copied only between passes (their splats land anywhere).
  void tile_done(const Film& film, int x0, int y0, int x1, int y1);
  // Between passes (no tile running): the whole film, splats included; records the error estimate.
  void pass_done(const Film& film);
  void finish(LiveState state);

  // ---- Viewer side (any thread).
  LiveStatus status() const;
  uint64_t version() const { return version_.load(std::memory_order_acquire); }
  // Brings `out` up to date (whole, or only the rows changed since out.version when it is a copy of
  // this film); returns whether anything changed.
  bool snapshot(LiveSnapshot& out) const;

 private:
  void copy_rows(const Film& film, int x0, int y0, int x1, int y1, bool with_splats);
  double seconds() const;

  const int width_, height_;
  mutable std::mutex mutex_;
  std::vector<float> rgb_, spp_;
  std::vector<uint64_t> row_version_;
  uint64_t total_samples_ = 0;  // the sum of spp_, kept as tiles land
  std::atomic<uint64_t> version_{0};
  std::atomic<double> fraction_{0};
  LiveStatus status_;  // the fields the render side sets (under mutex_)
  std::chrono::steady_clock::time_point start_;
  double last_error_seconds_ = -1e9;
};

}  // namespace candela
