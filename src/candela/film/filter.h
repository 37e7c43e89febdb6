#pragma once
// Pixel reconstruction filters with filter importance sampling (pbrt-v4, sec. 8.8).
//
// Instead of splatting every sample onto all the pixels its filter covers, the renderer places each
// pixel's samples at offsets drawn from (approximately) |f| around that pixel's centre and adds every
// sample to the pixel it was generated for only, with the weight w = f(offset) / pdf(offset) that
// sample() returns. A pixel's value is then sum(w L) / sum(w) over its samples: unbiased in the limit
// of many samples (numerator and denominator both converge to their filtered integrals), free of
// correlation between neighbouring pixels, and with no splatting across pixels. Weights are signed
// where the filter is (Mitchell's negative lobes).
//
// Filters follow pbrt-v4's definitions; all are separable, f(x, y) = f_x(x) f_y(y):
//   box       1 for |x| <= r_x, |y| <= r_y
//   tent      max(0, r_x - |x|) max(0, r_y - |y|)                          (pbrt's triangle)
//   gaussian  max(0, g(x) - g(r_x)) max(0, g(y) - g(r_y)), g the normal density of deviation sigma
//   mitchell  M(2x / r_x) M(2y / r_y), M the Mitchell-Netravali cubic with parameters B, C on [-2, 2]
//   sinc      s(x) s(y), s(x) = sinc(x) sinc(x / tau) for |x| <= r (pbrt's Lanczos windowed sinc)
#include "candela/math/vec.h"
#include "candela/sampling/distribution1d.h"
#include "candela/description/scene_desc.h"

namespace candela {

class Filter {
 public:
  struct Sample {
    Vec2 offset;   // from the pixel centre, in pixels, within radius()
    float weight;  // f(offset) / pdf(offset); the constant integral() for box and tent
  };

  // Throws InternalError for a non-positive or non-finite radius or Gaussian sigma, non-finite
  // Mitchell parameters or an unknown filter type (the scene readers refuse them first).
  explicit Filter(const FilterDesc& desc);

  FilterType type() const { return type_; }
  Vec2 radius() const { return radius_; }
  // f at `offset` from the pixel centre, in pixels.
  float evaluate(Vec2 offset) const { return evaluate_axis(offset.x, radius_.x) * evaluate_axis(offset.y, radius_.y); }
  // The integral of evaluate() over its support.
  float integral() const { return integral_; }
  // Draws an offset with density proportional to |f| (exactly for box and tent, piecewise-constant
  // in 16 cells per pixel for gaussian, mitchell and sinc); u uniform in [0,1)^2.
  Sample sample(Vec2 u) const;

 private:
  // pbrt-v4's FilterSampler tabulates |f| on a grid of 32 cells per unit of radius and samples it as a
  // PiecewiseConstant2D. For a separable filter that 2D table is the product of one table per axis,
  // so each axis is sampled on its own.
  struct TabulatedAxis {
    Distribution1D cells;  // probability of each cell, proportional to the mean of |f_axis| over it
    float cell_width = 0;
  };
  struct AxisSample {
    float offset;
    float weight;  // this axis's factor of f / pdf
  };

  float evaluate_axis(float x, float radius) const;
  float integral_axis(float radius) const;
  TabulatedAxis tabulate_axis(float radius) const;
  AxisSample sample_axis(float u, float radius, const TabulatedAxis& table) const;
  AxisSample sample_tabulated_axis(float u, float radius, const TabulatedAxis& table) const;

  FilterType type_;
  Vec2 radius_;
  float sigma_;
  float mitchell_b_, mitchell_c_;
  float sinc_tau_;
  float integral_ = 0;
  TabulatedAxis table_x_, table_y_;  // empty for the exactly sampled box and tent
};

}  // namespace candela
