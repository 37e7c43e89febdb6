#pragma once
// The film: per-pixel sums of box-filtered samples (each pixel averages the samples whose jittered
// positions fall inside it), with sums of squares for per-pixel variance. Accumulated in double so
// long renders do not lose precision. A pixel is only ever written by one thread at a time.
#include <cstdint>
#include <vector>

#include "candela/film/image.h"
#include "candela/math/color.h"

namespace candela {

struct PixelSums {
  double sum[3] = {0, 0, 0};
  double sum_sq[3] = {0, 0, 0};
  uint64_t count = 0;
};

class Film {
 public:
  Film(int width, int height) : width_(width), height_(height), pixels_(size_t(width) * size_t(height)) {}
  int width() const { return width_; }
  int height() const { return height_; }

  void add_sample(int x, int y, const RGB& L) {
    PixelSums& px = pixels_[size_t(y) * width_ + x];
    for (int c = 0; c < 3; ++c) {
      px.sum[c] += L[c];
      px.sum_sq[c] += double(L[c]) * L[c];
    }
    ++px.count;
  }
  const PixelSums& pixel(int x, int y) const { return pixels_[size_t(y) * width_ + x]; }

  // Per-pixel mean of the samples.
  Image mean_image() const;
  // Per-pixel variance of the mean (sample variance / count), for error estimates.
  Image variance_of_mean_image() const;
  uint64_t total_samples() const;

 private:
  int width_, height_;
  std::vector<PixelSums> pixels_;
};

}  // namespace candela
