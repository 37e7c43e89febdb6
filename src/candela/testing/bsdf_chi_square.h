#pragma once
// Chi-square tests of BSDF sampling with a zoomed binning (narrow lobes at the poles spread over many
// cells), shared by the microfacet and Beckmann tests.
#include <functional>

#include "candela/materials/bsdf.h"
#include "candela/math/frame.h"
#include "candela/sampling/rng.h"
#include "candela/testing/statistics.h"

namespace candela::testing {

// How directions are binned for a chi-square test. The binning grid is uniform in (cos theta, phi)
// around `axis`; `zoom` > 1 additionally magnifies the neighbourhoods of both poles of that frame by
// the linear map diag(zoom, zoom, 1) (followed by normalisation), with the pdf transformed by its
// Jacobian, so that narrow lobes at the poles spread over many cells. The map keeps the equator, so
// with the default axis the horizon (where reflection lobes are cut off) stays a cell boundary: the
// harness integrates the pdf per cell by a midpoint rule, which is inaccurate across such edges.
// The settings below were checked over several seeds (all p-values well spread, none systematically
// small); the usual cause of a failure with too coarse a setting is that integration error.
struct Binning {
  Vec3 axis{0, 0, 1};
  float zoom = 1;
  float z_min = -1;
  int resolution = 12;  // integration points per cell and axis
};

inline double zoomed_chi_square(const std::function<Vec3(Vec2)>& sample_fn, const std::function<float(const Vec3&)>& pdf_fn,
                  const Binning& binning, uint64_t seed = 17) {
  Frame frame(normalize(binning.axis));
  const float k = binning.zoom;
  auto sample = [&](Vec2 u) {
    Vec3 w = sample_fn(u);
    if (length_squared(w) == 0) return w;
    Vec3 v = frame.to_local(normalize(w));
    return normalize(Vec3(k * v.x, k * v.y, v.z));
  };
  auto pdf = [&](const Vec3& warped) {
    // Undo the zoom: dw / dw'' = 1 / (k^2 |A^-1 w''|^3) for the map w'' = normalize(A w).
    Vec3 u(warped.x / k, warped.y / k, warped.z);
    float len = length(u);
    return pdf_fn(frame.to_world(u / len)) / (k * k * len * len * len);
  };
  return spherical_chi_square_p_value(sample, pdf, kChiSquareSamples, seed, binning.z_min, 20, 40, binning.resolution);
}

// Chi-square of the non-delta directions bsdf.sample() returns against bsdf.pdf().
inline double bsdf_chi_square(const Bsdf& bsdf, const Vec3& wo, const Binning& binning = {}) {
  Rng lobe_rng(42, 43);
  auto sample = [&](Vec2 u) {
    auto s = bsdf_sample(bsdf, wo, lobe_rng.next_float(), u);
    return s && !s->is_delta ? s->wi : Vec3(0.0f);
  };
  return zoomed_chi_square(sample, [&](const Vec3& wi) { return bsdf_pdf(bsdf, wo, wi); }, binning);
}

}  // namespace candela::testing
