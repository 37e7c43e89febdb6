#include "candela/film/live_film.h"

#include <algorithm>
#include <cmath>

#include "candela/film/error_estimate.h"

namespace candela {
namespace {

// The per-sample form of the image's relMSE: the mean over pixels and channels of the variance of the
// mean over (mean^2 + 0.01). Exact for independent samples; an overestimate for QMC samplers, whose
// means converge faster than their samples' spread says. For films without independent halves.
double per_sample_relmse(const Film& film) {
  double sum = 0;
  uint64_t n = 0;
  for (const PixelSums& p : film.pixels()) {
    if (p.count < 2) continue;
    RGB mean = p.mean(), se = p.standard_error();
    for (int c = 0; c < 3; ++c) sum += double(se[c]) * se[c] / (double(mean[c]) * mean[c] + kErrorEpsilon);
    n += 3;
  }
  return n ? sum / double(n) : -1;
}

}  // namespace

LiveFilm::LiveFilm(int width, int height)
    : width_(width),
      height_(height),
      rgb_(size_t(width) * size_t(height) * 3, 0.0f),
      spp_(size_t(width) * size_t(height), 0.0f),
      row_version_(size_t(height), 0) {
  status_.width = width;
  status_.height = height;
}

double LiveFilm::seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void LiveFilm::start(std::string description, uint64_t planned_spp, bool adaptive, double time_limit_seconds,
                     double target_error) {
  std::lock_guard lock(mutex_);
  start_ = std::chrono::steady_clock::now();
  status_.state = LiveState::Rendering;
  status_.description = std::move(description);
  status_.planned_spp = planned_spp;
  status_.adaptive = adaptive;
  status_.time_limit_seconds = time_limit_seconds;
  status_.target_error = target_error;
}

void LiveFilm::copy_rows(const Film& film, int x0, int y0, int x1, int y1, bool with_splats) {
  const double splat_scale = with_splats && film.has_splats() ? film.splat_scale() : 0;
  const uint64_t version = version_.load(std::memory_order_relaxed) + 1;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const PixelSums& p = film.pixel(x, y);
      RGB v = p.mean();
      if (splat_scale > 0) v += film.splats().at(x, y) * float(splat_scale);
      const size_t i = size_t(y) * size_t(width_) + size_t(x);
      rgb_[3 * i] = v.r;
      rgb_[3 * i + 1] = v.g;
      rgb_[3 * i + 2] = v.b;
      total_samples_ += p.count - uint64_t(spp_[i]);
      spp_[i] = float(p.count);
    }
    row_version_[size_t(y)] = version;
  }
  version_.store(version, std::memory_order_release);
}

void LiveFilm::tile_done(const Film& film, int x0, int y0, int x1, int y1) {
  if (film.has_splats() || film.width() != width_ || film.height() != height_) return;
  std::lock_guard lock(mutex_);
  copy_rows(film, x0, y0, x1, y1, false);
}

void LiveFilm::pass_done(const Film& film) {
  if (film.width() != width_ || film.height() != height_) return;
  std::lock_guard lock(mutex_);
  copy_rows(film, 0, 0, width_, height_, true);
  status_.min_spp = UINT64_MAX;
  status_.max_spp = 0;
  for (const PixelSums& p : film.pixels()) {
    status_.min_spp = std::min(status_.min_spp, p.count);
    status_.max_spp = std::max(status_.max_spp, p.count);
  }
  const double mean_spp = double(total_samples_) / (double(width_) * height_);
  // The convergence curve, at most once a second (the estimate reads every pixel and its neighbours).
  const double now = seconds();
  if (now - last_error_seconds_ < 1.0) return;
  last_error_seconds_ = now;
  ErrorEstimate e = estimate_error(film);
  ErrorPoint point{now, e.relmse, e.low, e.high, mean_spp};
  status_.halves = e.valid;
  if (!e.valid) {
    point.relmse = point.low = point.high = per_sample_relmse(film);
    if (point.relmse < 0) return;
  }
  status_.error_history.push_back(point);
}

void LiveFilm::finish(LiveState state) {
  std::lock_guard lock(mutex_);
  status_.state = state;
  status_.seconds = seconds();
  version_.fetch_add(1, std::memory_order_release);
}

LiveStatus LiveFilm::status() const {
  std::lock_guard lock(mutex_);
  LiveStatus s = status_;
  s.version = version_.load(std::memory_order_acquire);
  s.mean_spp = double(total_samples_) / (double(width_) * height_);
  if (s.state != LiveState::Rendering) {
    s.fraction = s.state == LiveState::Finished ? 1 : fraction_.load();
    s.eta_seconds = 0;
    return s;
  }
  s.seconds = seconds();
  s.fraction = std::clamp(fraction_.load(), 0.0, 1.0);
  // ETA: the planned samples at the pace so far, cut by the time limit, and with an error target
  // where the error (falling as 1 / time) will meet it.
  double eta = s.fraction > 0 ? s.seconds * (1 - s.fraction) / s.fraction : -1;
  if (s.time_limit_seconds > 0) {
    double left = std::max(0.0, s.time_limit_seconds - s.seconds);
    eta = eta < 0 ? left : std::min(eta, left);
  }
  if (s.target_error > 0 && !s.error_history.empty()) {
    const ErrorPoint& last = s.error_history.back();
    double left = std::max(0.0, last.seconds * last.relmse / s.target_error - s.seconds);
    eta = eta < 0 ? left : std::min(eta, left);
  }
  s.eta_seconds = eta;
  return s;
}

bool LiveFilm::snapshot(LiveSnapshot& out) const {
  std::lock_guard lock(mutex_);
  const uint64_t v = version_.load(std::memory_order_relaxed);
  const bool same_film = out.width == width_ && out.height == height_ && out.rgb.size() == rgb_.size();
  if (same_film && out.version == v) return false;
  if (!same_film) {
    out.width = width_;
    out.height = height_;
    out.rgb = rgb_;
    out.spp = spp_;
    out.row_version = row_version_;
  } else {
    // Only the rows changed since the viewer's copy: the render waits on this lock at its tiles' ends.
    const size_t w = size_t(width_);
    for (size_t y = 0; y < size_t(height_); ++y) {
      if (row_version_[y] <= out.version) continue;
      std::copy_n(&rgb_[3 * w * y], 3 * w, &out.rgb[3 * w * y]);
      std::copy_n(&spp_[w * y], w, &out.spp[w * y]);
      out.row_version[y] = row_version_[y];
    }
  }
  out.version = v;
  return true;
}

}  // namespace candela
