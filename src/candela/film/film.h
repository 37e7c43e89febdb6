#pragma once
// The film: per-pixel weighted sums of samples. With filter importance sampling every sample adds
// to the pixel it was generated for with its filter weight w, and the pixel's value is
// sum(w L) / sum(w). Sums of squares of w L give per-pixel error estimates (for adaptive sampling
// and tests). Accumulated in double so long renders do not lose precision. A pixel is only ever
// written by one thread at a time.
#include <cstdint>
#include <vector>

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
  const PixelSums& pixel(int x, int y) const { return pixels_[size_t(y) * width_ + x]; }
  // All pixels, row-major: for checkpoints, which store and restore the sums bit for bit.
  const std::vector<PixelSums>& pixels() const { return pixels_; }
  std::vector<PixelSums>& pixels() { return pixels_; }

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
};

}  // namespace candela
