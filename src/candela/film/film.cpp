#include "candela/film/film.h"

#include <algorithm>
#include <cmath>

namespace candela {

RGB PixelSums::mean() const {
  if (weight == 0) return RGB(0.0f);
  return {float(weighted[0] / weight), float(weighted[1] / weight), float(weighted[2] / weight)};
}

RGB PixelSums::standard_error() const {
  RGB se(0.0f);
  if (count < 2 || weight == 0) return se;
  double n = double(count), mean_weight = weight / n;
  for (int c = 0; c < 3; ++c) {
    // Sample variance of w L, scaled to the ratio estimator sum(w L) / sum(w).
    double m = weighted[c] / n;
    double var = std::max(0.0, (weighted_sq[c] - n * m * m) / (n - 1));
    se[c] = float(std::sqrt(var / n) / std::abs(mean_weight));
  }
  return se;
}

Image Film::mean_image() const {
  Image img(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) img.set(x, y, pixel(x, y).mean());
  return img;
}

Image Film::variance_of_mean_image() const {
  Image img(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      RGB se = pixel(x, y).standard_error();
      img.set(x, y, se * se);
    }
  return img;
}

Image Film::sample_count_image() const {
  Image img(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) img.set(x, y, RGB(float(pixel(x, y).count)));
  return img;
}

uint64_t Film::total_samples() const {
  uint64_t n = 0;
  for (const auto& px : pixels_) n += px.count;
  return n;
}

uint64_t Film::min_samples() const {
  if (pixels_.empty()) return 0;
  uint64_t n = pixels_[0].count;
  for (const auto& px : pixels_) n = std::min(n, px.count);
  return n;
}

uint64_t Film::max_samples() const {
  uint64_t n = 0;
  for (const auto& px : pixels_) n = std::max(n, px.count);
  return n;
}

}  // namespace candela
