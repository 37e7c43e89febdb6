#pragma once
// The film: per-pixel weighted sums of samples. With filter importance sampling every sample adds
// to the pixel it was generated for with its filter weight w, and the pixel's value is
// sum(w L) / sum(w). Sums of squares of w L give per-pixel error estimates (for adaptive sampling
// and tests). Accumulated in double so long renders do not lose precision. A pixel is only ever
// written by one thread at a time.
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

class Film {
 public:
  Film(int width, int height) : width_(width), height_(height), pixels_(size_t(width) * size_t(height)) {}
  int width() const { return width_; }
  int height() const { return height_; }

  void add_sample(int x, int y, const RGB& L, float weight = 1) {
    PixelSums& px = pixels_[size_t(y) * width_ + x];
    for (int c = 0; c < 3; ++c) {
      double v = double(weight) * L[c];
      px.weighted[c] += v;
      px.weighted_sq[c] += v * v;
    }
    px.weight += weight;
    ++px.count;
  }
  // Splats (see SplatImage), kept apart from the per-pixel sums and multiplied by splat_scale() in
  // the image. Empty until enable_splats().
  void enable_splats() { splats_ = SplatImage(width_, height_); }
  bool has_splats() const { return !splats_.empty(); }
  SplatImage& splats() { return splats_; }
  const SplatImage& splats() const { return splats_; }
  double splat_scale() const { return splat_scale_; }
  void set_splat_scale(double s) { splat_scale_ = s; }

  const PixelSums& pixel(int x, int y) const { return pixels_[size_t(y) * width_ + x]; }
  // All pixels, row-major: for checkpoints, which store and restore the sums bit for bit.
  const std::vector<PixelSums>& pixels() const { return pixels_; }
  std::vector<PixelSums>& pixels() { return pixels_; }

  // Per pixel: the mean of its samples plus its splats times splat_scale().
  Image mean_image() const;
  // Per-pixel variance of the mean (squared standard error), for error estimates in tests.
  Image variance_of_mean_image() const;
  // Per-pixel sample counts, in every channel.
  Image sample_count_image() const;
  uint64_t total_samples() const;
  // Fewest and most samples any pixel has (0, 0 for an empty film).
  uint64_t min_samples() const;
  uint64_t max_samples() const;

 private:
  int width_, height_;
  std::vector<PixelSums> pixels_;
  SplatImage splats_;
  double splat_scale_ = 1;
};

}  // namespace candela
