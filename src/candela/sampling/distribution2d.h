#pragma once
// Piecewise-constant densities on [0,1] and [0,1]^2 (pbrt-v4's PiecewiseConstant1D / 2D, sec. A.4.1
// and A.4.2): sampling by inverting the CDF, in 2D first the row from the marginal density and then
// the position within the row from that row's conditional density.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include "candela/math/vec.h"

namespace candela {

// A density on [0,1] that is constant on n equal cells, proportional to non-negative weights
// (uniform when they are all zero).
//
// The density reported for cell i is n * (cdf[i+1] - cdf[i]) of the stored float CDF: exactly the
// probability with which sample() picks the cell, so sample() and pdf() agree to the last bit even
// where float rounding of the CDF differs from weight / total.
class PiecewiseConstant1D {
 public:
  PiecewiseConstant1D() = default;
  explicit PiecewiseConstant1D(std::span<const float> weights) : cdf_(weights.size() + 1, 0.0f) {
    const size_t n = weights.size();
    double total = 0;
    for (float w : weights) total += clean(w);
    integral_ = n > 0 ? total / double(n) : 0.0;
    // Running sums in double, rounded once per entry, so the CDF is monotone and ends at exactly 1.
    double acc = 0;
    for (size_t i = 0; i < n; ++i) {
      acc += total > 0 ? clean(weights[i]) : 1.0;
      cdf_[i + 1] = float(acc / (total > 0 ? total : double(n)));
    }
    if (n > 0) cdf_[n] = 1.0f;
  }

  size_t size() const { return cdf_.empty() ? 0 : cdf_.size() - 1; }
  // The integral over [0,1] of the step function of the weights (their average).
  double integral() const { return integral_; }

  // The cell holding x (clamped into [0, n-1]).
  size_t cell(float x) const {
    double c = std::floor(double(x) * double(size()));
    return size_t(std::clamp(c, 0.0, double(size() - 1)));
  }
  // Density of cell i: its probability times n.
  float cell_pdf(size_t i) const { return (cdf_[i + 1] - cdf_[i]) * float(size()); }
  float pdf(float x) const { return cell_pdf(cell(x)); }

  // Returns x in [0,1) with density pdf(x) for u uniform in [0,1); the cell it lies in goes to *cell_index.
  float sample(float u, float* pdf_out = nullptr, size_t* cell_index = nullptr) const {
    const size_t n = size();
    u = std::clamp(u, 0.0f, 0x1.fffffep-1f);
    // Invert the CDF: the cell i with cdf[i] <= u < cdf[i+1], which has non-zero probability.
    size_t i = size_t(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin()) - 1;
    i = std::min(i, n - 1);
    // Uniform within the cell: the offset of u in the cell's CDF interval.
    float width = cdf_[i + 1] - cdf_[i];
    float du = width > 0 ? (u - cdf_[i]) / width : 0.0f;
    float x = std::min((float(i) + du) / float(n), 0x1.fffffep-1f);
    // Rounding may push x across a cell boundary: nudge it back so pdf(x) is this cell's density.
    while (cell(x) > i) x = std::nextafter(x, 0.0f);
    while (cell(x) < i) x = std::nextafter(x, 1.0f);
    if (pdf_out) *pdf_out = cell_pdf(i);
    if (cell_index) *cell_index = i;
    return x;
  }

 private:
  // Negative and NaN weights count as zero.
  static double clean(float w) { return w > 0 && std::isfinite(w) ? double(w) : 0.0; }

  std::vector<float> cdf_;
  double integral_ = 0;
};

struct Distribution2DSample {
  Vec2 point;     // in [0,1)^2
  float pdf = 0;  // density with respect to area on [0,1]^2
};

// A density on [0,1]^2 constant on an nu x nv grid of cells, proportional to non-negative weights
// given row by row: weights[iv * nu + iu] for the cell [iu/nu, (iu+1)/nu) x [iv/nv, (iv+1)/nv).
// Point coordinates are (x along a row, y across rows); sample(u) uses u.y for the row, u.x within it.
class Distribution2D {
 public:
  Distribution2D() = default;
  Distribution2D(std::span<const float> weights, int nu, int nv) : nu_(nu), nv_(nv) {
    conditional_.reserve(size_t(nv));
    std::vector<float> row_integrals(static_cast<size_t>(nv));
    for (int v = 0; v < nv; ++v) {
      conditional_.emplace_back(weights.subspan(size_t(v) * size_t(nu), size_t(nu)));
      row_integrals[size_t(v)] = float(conditional_.back().integral());
    }
    marginal_ = PiecewiseConstant1D(row_integrals);
  }

  int nu() const { return nu_; }
  int nv() const { return nv_; }

  Distribution2DSample sample(Vec2 u) const {
    // Pick the row from the marginal density, then the position along it from its conditional.
    float pdf_row, pdf_col;
    size_t row;
    float y = marginal_.sample(u.y, &pdf_row, &row);
    float x = conditional_[row].sample(u.x, &pdf_col);
    return {{x, y}, pdf_row * pdf_col};
  }
  float pdf(Vec2 p) const {
    size_t row = marginal_.cell(p.y);
    return marginal_.cell_pdf(row) * conditional_[row].pdf(p.x);
  }

 private:
  int nu_ = 0, nv_ = 0;
  std::vector<PiecewiseConstant1D> conditional_;  // one per row
  PiecewiseConstant1D marginal_;                  // over rows
};

}  // namespace candela
