#pragma once
// The film: per-pixel weighted sums of samples. With filter importance sampling every sample adds
// to the pixel it was generated for with its filter weight w, and the pixel's value is
// sum(w L) / sum(w). Sums of squares of w L give per-pixel error estimates (for adaptive sampling
// and tests). Accumulated in double so long renders do not lose precision. A pixel is only ever
// written by one thread at a time.
//
// Every pixel's samples also fall into two halves, each an independent estimate of the pixel
// (render_loop.h says which samples go where): the sums of the first half are kept beside the
// totals, so the difference of the two halves measures the image's error (film/error_estimate.h).
#include <cstdint>
#include <vector>

#include "candela/film/filter.h"
#include "candela/film/image.h"
#include "candela/math/color.h"

namespace candela {

struct PixelSums {
  double weighted[3] = {0, 0, 0};     // sum of w L
  double weighted_sq[3] = {0, 0, 0};  // sum of (w L)^2
  double weight = 0;                  // sum of w
  uint64_t count = 0;                 // number of samples
  double half_weighted[3] = {0, 0, 0};  // sum of w L over the first half's samples
  double half_weight = 0;               // sum of w over them
  uint64_t half_count = 0;              // their number

  RGB mean() const;
  // Standard error of mean() per channel, from the spread of the samples (0 with fewer than 2).
  RGB standard_error() const;
};

// Contributions that land wherever they land on the film rather than on the pixel being sampled
// (light paths of bidirectional path tracing, Metropolis chains). A splat is spread over the
// pixels the filter covers with weights f / integral(f). The sums are fixed point (kUnit per unit)
// added with atomic integer adds, so they come out the same whatever order threads add in; each value
// is rounded up or down by a deterministic dither so that the sums stay unbiased for tiny values.
class SplatImage {
 public:
  static constexpr double kUnit = 16777216.0;  // 2^24: resolution 6e-8, range 5e11 per sum

  SplatImage() = default;
  SplatImage(int width, int height) : width_(width), height_(height), sums_(size_t(width) * size_t(height) * 3, 0) {}
  bool empty() const { return sums_.empty(); }
  int width() const { return width_; }
  int height() const { return height_; }
  // Adds v at raster position p; false (and nothing added) for non-finite or absurdly large values.
  bool add(Vec2 p, const RGB& v, const Filter& filter);
  void add_to_pixel(int x, int y, const RGB& v);
  RGB at(int x, int y) const;
  // Every pixel times `scale`.
  Image image(double scale) const;
  // The raw sums (3 per pixel, row-major): for checkpoints.
  const std::vector<int64_t>& sums() const { return sums_; }
  std::vector<int64_t>& sums() { return sums_; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<int64_t> sums_;
};

// A pixel's two independent estimates (film/error_estimate.h): the first half's samples and splats
// (A) and the second half's (B), the splats' part of each, and A's share of the pixel's weight, so
// that the pixel's mean is share_a A + (1 - share_a) B.
struct PixelHalves {
  double a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
  double splat_a[3] = {0, 0, 0}, splat_b[3] = {0, 0, 0};
  double share_a = 0.5;
};

class Film {
 public:
  Film(int width, int height) : width_(width), height_(height), pixels_(size_t(width) * size_t(height)) {}
  int width() const { return width_; }
  int height() const { return height_; }

  void add_sample(int x, int y, const RGB& L, float weight = 1, bool first_half = true) {
    PixelSums& px = pixels_[size_t(y) * width_ + x];
    for (int c = 0; c < 3; ++c) {
      double v = double(weight) * L[c];
      px.weighted[c] += v;
      px.weighted_sq[c] += v * v;
      if (first_half) px.half_weighted[c] += v;
    }
    px.weight += weight;
    ++px.count;
    if (first_half) {
      px.half_weight += weight;
      ++px.half_count;
    }
  }
  // Splats (see SplatImage), kept apart from the per-pixel sums and multiplied by splat_scale() in
  // the image. Empty until enable_splats(). The splats of the first half's samples (or chains) are
  // also added to half_splats().
  void enable_splats() {
    splats_ = SplatImage(width_, height_);
    half_splats_ = SplatImage(width_, height_);
  }
  bool has_splats() const { return !splats_.empty(); }
  SplatImage& splats() { return splats_; }
  const SplatImage& splats() const { return splats_; }
  SplatImage& half_splats() { return half_splats_; }
  const SplatImage& half_splats() const { return half_splats_; }
  // Either an explicit scale, or (bidirectional path tracing) one light path per camera sample: the
  // light image is the splats times the importance film's area over the number of samples.
  double splat_scale() const;
  void set_splat_scale(double s) { splat_scale_ = s; }
  void set_one_light_path_per_sample(double importance_film_area) { light_path_area_ = importance_film_area; }
  // The share of the splats' paths (or chains) in the first half: 0.5 unless set, or, with one light
  // path per sample, the first half's share of the samples.
  double splat_half_fraction() const;
  void set_splat_half_fraction(double f) { splat_half_fraction_ = f; }

  const PixelSums& pixel(int x, int y) const { return pixels_[size_t(y) * width_ + x]; }
  // All pixels, row-major: for checkpoints, which store and restore the sums bit for bit.
  const std::vector<PixelSums>& pixels() const { return pixels_; }
  std::vector<PixelSums>& pixels() { return pixels_; }

  // Pixel (x, y)'s halves; false (and `out` untouched) where it has no samples or lacks a half.
  bool pixel_halves(int x, int y, PixelHalves& out) const;

  // Per pixel: the mean of its samples plus its splats times splat_scale().
  Image mean_image() const;
  // Per-pixel variance of the mean (squared standard error), for error estimates in tests.
  Image variance_of_mean_image() const;
  // Per-pixel sample counts, in every channel.
  Image sample_count_image() const;
  uint64_t total_samples() const;
  uint64_t first_half_samples() const;
  // Fewest and most samples any pixel has (0, 0 for an empty film).
  uint64_t min_samples() const;
  uint64_t max_samples() const;

 private:
  int width_, height_;
  std::vector<PixelSums> pixels_;
  SplatImage splats_, half_splats_;
  double splat_scale_ = 1;
  double light_path_area_ = 0;  // > 0: one light path per camera sample
  double splat_half_fraction_ = 0.5;
};

}  // namespace candela
