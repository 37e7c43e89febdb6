#include "candela/film/filter.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "candela/base/error.h"

namespace candela {
namespace {

constexpr int kCellsPerUnitRadius = 32;  // pbrt-v4's FilterSampler resolution
// |f| is averaged over a few points per cell rather than taken at the centre, so that a cell where
// Mitchell's kernel crosses zero near its centre still gets the probability its |f| deserves.
constexpr int kPointsPerCell = 8;

bool is_positive_finite(float v) { return std::isfinite(v) && v > 0; }

bool is_known(FilterType type) {
  switch (type) {
    case FilterType::Box:
    case FilterType::Tent:
    case FilterType::Gaussian:
    case FilterType::Mitchell:
    case FilterType::LanczosSinc:
      return true;
  }
  return false;
}

// The scene readers refuse these values naming the place (a SceneError): one reaching here is a bug.
void validate(const FilterDesc& desc) {
  if (!is_known(desc.type)) throw InternalError(fmt::format("unknown filter type {}", int(desc.type)));
  if (!is_positive_finite(desc.radius.x) || !is_positive_finite(desc.radius.y))
    throw InternalError(
        fmt::format("filter radius must be positive and finite, got ({}, {})", desc.radius.x, desc.radius.y));
  if (desc.type == FilterType::Gaussian && !is_positive_finite(desc.gaussian_sigma))
    throw InternalError(
        fmt::format("gaussian filter sigma must be positive and finite, got {}", desc.gaussian_sigma));
  if (desc.type == FilterType::Mitchell && !(std::isfinite(desc.mitchell_b) && std::isfinite(desc.mitchell_c)))
    throw InternalError(
        fmt::format("mitchell filter B and C must be finite, got {} and {}", desc.mitchell_b, desc.mitchell_c));
  if (desc.type == FilterType::LanczosSinc && !is_positive_finite(desc.sinc_tau))
    throw InternalError(fmt::format("sinc filter tau must be positive and finite, got {}", desc.sinc_tau));
}

// The normal density with deviation sigma; in double so that g(x) - g(r) keeps its digits when sigma
// is large against the radius.
double gaussian(double x, double sigma) {
  return std::exp(-x * x / (2 * sigma * sigma)) / (sigma * std::sqrt(2 * std::numbers::pi));
}

// pbrt's Gaussian filter: shifted down by its value at the radius so that it reaches zero there.
float truncated_gaussian(float x, float radius, float sigma) {
  return float(std::max(0.0, gaussian(x, sigma) - gaussian(radius, sigma)));
}

// Integral of truncated_gaussian over [-radius, radius].
float truncated_gaussian_integral(float radius, float sigma) {
  double r = radius;
  return float(std::erf(r / (sigma * std::numbers::sqrt2)) - 2 * r * gaussian(r, sigma));
}

// The Mitchell-Netravali cubic on [-2, 2] (Mitchell and Netravali 1988); its integral is 1 for every B, C.
float mitchell_1d(float x, float b, float c) {
  x = std::abs(x);
  if (x <= 1) return ((12 - 9 * b - 6 * c) * x * x * x + (-18 + 12 * b + 6 * c) * x * x + (6 - 2 * b)) / 6;
  if (x <= 2)
    return ((-b - 6 * c) * x * x * x + (6 * b + 30 * c) * x * x + (-12 * b - 48 * c) * x + (8 * b + 24 * c)) / 6;
  return 0;
}

// sin(pi x) / (pi x), 1 at 0.
double sinc(double x) {
  double px = std::numbers::pi * x;
  return std::abs(px) < 1e-5 ? 1 - px * px / 6 : std::sin(px) / px;
}

// pbrt-v4's windowed sinc: the sinc cut off at the radius and tapered by a Lanczos window of width tau.
float lanczos_sinc(float x, float radius, float tau) {
  return std::abs(x) <= radius ? float(sinc(x) * sinc(x / tau)) : 0.0f;
}

// Its integral over [-radius, radius], by Simpson's rule on 256 intervals per pixel (the kernel is
// smooth: the error is far below float precision).
float lanczos_sinc_integral(float radius, float tau) {
  int n = 2 * std::max(1, int(std::ceil(128 * radius)));
  double h = 2.0 * radius / n, sum = 0;
  for (int i = 0; i <= n; ++i) {
    double x = -radius + i * h;
    double weight = i == 0 || i == n ? 1 : i % 2 ? 4 : 2;
    sum += weight * sinc(x) * sinc(x / tau);
  }
  return float(sum * h / 3);
}

// Inverts the CDF of the tent density (r - |x|) / r^2 on [-r, r]; the lower half of u gives x <= 0.
float sample_tent(float u, float r) {
  if (u < 0.5f) return -r + r * std::sqrt(2 * u);
  return r - r * std::sqrt(2 * (1 - u));
}

}  // namespace

Filter::Filter(const FilterDesc& desc)
    : type_(desc.type),
      radius_(desc.radius),
      sigma_(desc.gaussian_sigma),
      mitchell_b_(desc.mitchell_b),
      mitchell_c_(desc.mitchell_c),
      sinc_tau_(desc.sinc_tau) {
  validate(desc);
  integral_ = integral_axis(radius_.x) * integral_axis(radius_.y);
  if (type_ != FilterType::Box && type_ != FilterType::Tent) {
    table_x_ = tabulate_axis(radius_.x);
    table_y_ = tabulate_axis(radius_.y);
  }
}

float Filter::evaluate_axis(float x, float radius) const {
  switch (type_) {
    case FilterType::Box:
      return std::abs(x) <= radius ? 1.0f : 0.0f;
    case FilterType::Tent:
      return std::max(0.0f, radius - std::abs(x));
    case FilterType::Gaussian:
      return std::abs(x) <= radius ? truncated_gaussian(x, radius, sigma_) : 0.0f;
    case FilterType::Mitchell:
      return mitchell_1d(2 * x / radius, mitchell_b_, mitchell_c_);
    case FilterType::LanczosSinc:
      return lanczos_sinc(x, radius, sinc_tau_);
  }
  return 0;  // unreachable: the constructor rejects unknown types
}

float Filter::integral_axis(float radius) const {
  switch (type_) {
    case FilterType::Box:
      return 2 * radius;
    case FilterType::Tent:
      return radius * radius;
    case FilterType::Gaussian:
      return truncated_gaussian_integral(radius, sigma_);
    case FilterType::Mitchell:
      return radius / 2;  // the unit-integral kernel on [-2, 2] stretched to [-radius, radius]
    case FilterType::LanczosSinc:
      return lanczos_sinc_integral(radius, sinc_tau_);
  }
  return 0;  // unreachable: the constructor rejects unknown types
}

Filter::TabulatedAxis Filter::tabulate_axis(float radius) const {
  int cell_count = std::max(1, int(kCellsPerUnitRadius * radius));
  TabulatedAxis table;
  table.cell_width = 2 * radius / float(cell_count);
  std::vector<float> mean_abs_f(size_t(cell_count), 0.0f);
  for (int i = 0; i < cell_count; ++i) {
    double sum = 0;
    for (int k = 0; k < kPointsPerCell; ++k) {
      float x = -radius + (float(i) + (float(k) + 0.5f) / kPointsPerCell) * table.cell_width;
      sum += std::abs(evaluate_axis(x, radius));
    }
    mean_abs_f[size_t(i)] = float(sum / kPointsPerCell);
  }
  table.cells = Distribution1D(mean_abs_f);
  return table;
}

Filter::AxisSample Filter::sample_tabulated_axis(float u, float radius, const TabulatedAxis& table) const {
  size_t cell = table.cells.sample(u);
  float within_cell = table.cells.remap(u, cell);
  float x = std::clamp(-radius + (float(cell) + within_cell) * table.cell_width, -radius, radius);
  float pdf = table.cells.pmf(cell) / table.cell_width;
  return {x, pdf > 0 ? evaluate_axis(x, radius) / pdf : 0.0f};
}

Filter::AxisSample Filter::sample_axis(float u, float radius, const TabulatedAxis& table) const {
  switch (type_) {
    case FilterType::Box:
      return {lerp(u, -radius, radius), 2 * radius};
    case FilterType::Tent:
      return {sample_tent(u, radius), radius * radius};
    case FilterType::Gaussian:
    case FilterType::Mitchell:
    case FilterType::LanczosSinc:
      return sample_tabulated_axis(u, radius, table);
  }
  return {0, 0};  // unreachable: the constructor rejects unknown types
}

Filter::Sample Filter::sample(Vec2 u) const {
  AxisSample x = sample_axis(u.x, radius_.x, table_x_);
  AxisSample y = sample_axis(u.y, radius_.y, table_y_);
  return {{x.offset, y.offset}, x.weight * y.weight};
}

}  // namespace candela
