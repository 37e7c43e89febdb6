#include "candela/film/film.h"

namespace candela {

Image Film::mean_image() const {
  Image img(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const PixelSums& px = pixel(x, y);
      double inv = px.count ? 1.0 / double(px.count) : 0.0;
      img.set(x, y, RGB(float(px.sum[0] * inv), float(px.sum[1] * inv), float(px.sum[2] * inv)));
    }
  return img;
}

Image Film::variance_of_mean_image() const {
  Image img(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const PixelSums& px = pixel(x, y);
      RGB v(0.0f);
      if (px.count > 1) {
        double n = double(px.count);
        for (int c = 0; c < 3; ++c) {
          double mean = px.sum[c] / n;
          double var = std::max(0.0, (px.sum_sq[c] - n * mean * mean) / (n - 1));
          v[c] = float(var / n);
        }
      }
      img.set(x, y, v);
    }
  return img;
}

uint64_t Film::total_samples() const {
  uint64_t n = 0;
  for (const auto& px : pixels_) n += px.count;
  return n;
}

}  // namespace candela
