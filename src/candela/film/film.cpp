#include "candela/film/film.h"

#include <algorithm>
#include <atomic>
#include <cstring>

#include "candela/sampling/rng.h"
#include <cmath>

namespace candela {
namespace {

// The image whose pixel (x, y) is value(x, y).
template <class PixelValue>
Image image_of(int width, int height, PixelValue value) {
  Image img(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) img.set(x, y, value(x, y));
  return img;
}

}  // namespace

RGB PixelSums::mean() const {
  if (weight == 0) return RGB(0.0f);
  return {float(weighted[0] / weight), float(weighted[1] / weight), float(weighted[2] / weight)};
}

RGB PixelSums::standard_error() const {
  if (count < 2 || weight == 0) return RGB(0.0f);
  double n = double(count), mean_weight = weight / n;
  float se[3];
  for (int c = 0; c < 3; ++c) {
    // Sample variance of w L, scaled to the ratio estimator sum(w L) / sum(w).
    double m = weighted[c] / n;
    double var = std::max(0.0, (weighted_sq[c] - n * m * m) / (n - 1));
    se[c] = float(std::sqrt(var / n) / std::abs(mean_weight));
  }
  return RGB(se[0], se[1], se[2]);
}

bool Film::pixel_halves(int x, int y, PixelHalves& out) const {
  const PixelSums& p = pixel(x, y);
  const double w_a = p.half_weight, w_b = p.weight - p.half_weight;
  if (p.count == 0 || p.half_count == 0 || p.half_count == p.count || w_a == 0 || w_b == 0) return false;
  // The pixel sums' share of the weight in the first half sets how the halves combine (the splats
  // split about evenly too).
  out.share_a = w_a / p.weight;
  const bool splats = has_splats();
  const double scale = splats ? splat_scale() : 0, f_splat = splats ? splat_half_fraction() : 0.5;
  const RGB splat_all = splats ? splats_.at(x, y) : RGB(0.0f);
  const RGB splat_first = splats ? half_splats_.at(x, y) : RGB(0.0f);
  for (int c = 0; c < 3; ++c) {
    const double s_all = double(splat_all[c]) * scale, s_a = double(splat_first[c]) * scale;
    out.splat_a[c] = splats ? s_a / f_splat : 0;
    out.splat_b[c] = splats ? (s_all - s_a) / (1 - f_splat) : 0;
    out.a[c] = p.half_weighted[c] / w_a + out.splat_a[c];
    out.b[c] = (p.weighted[c] - p.half_weighted[c]) / w_b + out.splat_b[c];
  }
  return true;
}

Image Film::mean_image() const {
  const double scale = has_splats() ? splat_scale() : 0;
  return image_of(width_, height_, [&](int x, int y) {
    RGB v = pixel(x, y).mean();
    if (has_splats()) v += splats_.at(x, y) * float(scale);
    return v;
  });
}

void SplatImage::add_to_pixel(int x, int y, const RGB& v) {
  int64_t* sums = &sums_[(size_t(y) * size_t(width_) + size_t(x)) * 3];
  for (int c = 0; c < 3; ++c) {
    if (v[c] == 0) continue;
    // Rounded up or down with probabilities that make the expected sum exact (plain rounding would
    // lose every value below half a unit). The "random" number is a hash of the value and the
    // place, so the sum stays the same whatever order threads add in.
    double scaled = double(v[c]) * kUnit;
    float value = v[c];
    uint32_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    double dither = double(hash_values(bits, uint64_t(x), uint64_t(y), uint64_t(c)) >> 11) * 0x1p-53;
    int64_t fixed = int64_t(std::floor(scaled + dither));
    if (fixed != 0) std::atomic_ref<int64_t>(sums[c]).fetch_add(fixed, std::memory_order_relaxed);
  }
}

bool SplatImage::add(Vec2 p, const RGB& v, const Filter& filter) {
  // Larger values would overflow the fixed-point sums within a few hundred splats.
  constexpr float kLargest = 1e9f;
  for (int c = 0; c < 3; ++c)
    if (!(std::abs(v[c]) < kLargest)) return false;
  if (v.is_black()) return true;
  Vec2 r = filter.radius();
  if (filter.type() == FilterType::Box && r.x == 0.5f && r.y == 0.5f) {
    // The common case: the pixel the point lies in, with weight 1.
    add_to_pixel(std::clamp(int(p.x), 0, width_ - 1), std::clamp(int(p.y), 0, height_ - 1), v);
    return true;
  }
  // Every pixel whose centre lies within the filter's radius of p.
  int x0 = std::max(0, int(std::ceil(p.x - 0.5f - r.x))), x1 = std::min(width_ - 1, int(std::floor(p.x - 0.5f + r.x)));
  int y0 = std::max(0, int(std::ceil(p.y - 0.5f - r.y))), y1 = std::min(height_ - 1, int(std::floor(p.y - 0.5f + r.y)));
  float inv_integral = 1 / filter.integral();
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      float w = filter.evaluate({p.x - (float(x) + 0.5f), p.y - (float(y) + 0.5f)}) * inv_integral;
      if (w != 0) add_to_pixel(x, y, v * w);
    }
  return true;
}

RGB SplatImage::at(int x, int y) const {
  if (empty()) return RGB(0.0f);
  const int64_t* sums = &sums_[(size_t(y) * size_t(width_) + size_t(x)) * 3];
  return {float(double(sums[0]) / kUnit), float(double(sums[1]) / kUnit), float(double(sums[2]) / kUnit)};
}

Image SplatImage::image(double scale) const {
  return image_of(width_, height_, [&](int x, int y) { return at(x, y) * float(scale); });
}

Image Film::variance_of_mean_image() const {
  return image_of(width_, height_, [&](int x, int y) {
    RGB se = pixel(x, y).standard_error();
    return se * se;
  });
}

Image Film::sample_count_image() const {
  return image_of(width_, height_, [&](int x, int y) { return RGB(float(pixel(x, y).count)); });
}

uint64_t Film::total_samples() const {
  uint64_t n = 0;
  for (const auto& px : pixels_) n += px.count;
  return n;
}

uint64_t Film::first_half_samples() const {
  uint64_t n = 0;
  for (const auto& px : pixels_) n += px.half_count;
  return n;
}

double Film::splat_scale() const {
  if (light_path_area_ <= 0) return splat_scale_;
  const uint64_t paths = total_samples();
  return paths > 0 ? light_path_area_ / double(paths) : 0;
}

double Film::splat_half_fraction() const {
  if (light_path_area_ <= 0) return splat_half_fraction_;
  const uint64_t paths = total_samples();
  return paths > 0 ? double(first_half_samples()) / double(paths) : 0.5;
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
