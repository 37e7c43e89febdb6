#include "candela/media/medium.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "candela/spectral/blackbody.h"
#include "candela/textures/noise.h"

namespace candela {

namespace {

bool valid_rgb(const RGB& c) { return c.is_finite() && c.min_component() >= 0; }

// Why a cloud cannot be rendered: a parameter that is not finite, or a box without volume.
std::string cloud_problem(const CloudDensity& c) {
  for (auto [name, value] : {std::pair{"density", c.density}, std::pair{"wispiness", c.wispiness},
                             std::pair{"frequency", c.frequency}})
    if (!std::isfinite(value)) return fmt::format("the cloud's {} {} must be finite", name, value);
  const Point3 &lo = c.box_min, &hi = c.box_max;
  if (!is_finite(lo) || !is_finite(hi) || !(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
    return fmt::format("the cloud's box from ({}, {}, {}) to ({}, {}, {}) must be finite and have volume", lo.x,
                       lo.y, lo.z, hi.x, hi.y, hi.z);
  return "";
}

std::string volume_problem(const VolumeDesc& v, const char* what, bool scalar_only, float max_value,
                           float min_value = 0) {
  if (v.cloud)
    return std::string_view(what) == "density" ? cloud_problem(*v.cloud)
                                               : fmt::format("{} is a procedural cloud; only a density may be one", what);
  const std::string source = v.filename.empty() ? std::string(what) : fmt::format("{} grid \"{}\"", what, v.filename);
  if (v.is_constant()) {
    if (!v.constant.is_finite() || v.constant.min_component() < min_value || v.constant.max_component() > max_value)
      return fmt::format("{} ({}, {}, {}) must be within [{}, {}]", what, v.constant.r, v.constant.g, v.constant.b,
                         min_value, max_value);
    return "";
  }
  const auto& r = v.resolution;
  if (r[0] < 1 || r[1] < 1 || r[2] < 1)
    return fmt::format("{}: resolution {} x {} x {} must be at least 1 on every axis", source, r[0], r[1], r[2]);
  if (scalar_only ? v.channels != 1 : (v.channels != 1 && v.channels != 3))
    return fmt::format("{} has {} channels; {}", source, v.channels, scalar_only ? "it must have 1" : "it must have 1 or 3");
  const uint64_t expected = uint64_t(r[0]) * uint64_t(r[1]) * uint64_t(r[2]) * uint64_t(v.channels);
  if (v.values->size() != expected)
    return fmt::format("{} has {} values; {} x {} x {} x {} channel(s) needs {}", source, v.values->size(), r[0], r[1],
                       r[2], v.channels, expected);
  for (size_t i = 0; i < v.values->size(); ++i) {
    float x = (*v.values)[i];
    if (!std::isfinite(x) || x < min_value || x > max_value)
      return fmt::format("{}: value {} (number {}) must be within [{}, {}]", source, x, i, min_value, max_value);
  }
  return "";
}

}  // namespace

std::string medium_problem(const MediumDesc& m) {
  if (!valid_rgb(m.sigma_t)) return fmt::format("sigma_t ({}, {}, {}) must be finite and >= 0", m.sigma_t.r, m.sigma_t.g, m.sigma_t.b);
  if (!std::isfinite(m.scale) || m.scale < 0) return fmt::format("scale {} must be finite and >= 0", m.scale);
  if (!valid_rgb(m.emission)) return fmt::format("emission ({}, {}, {}) must be finite and >= 0", m.emission.r, m.emission.g, m.emission.b);
  if (!(m.g > -1 && m.g < 1)) return fmt::format("g = {} must be within (-1, 1)", m.g);
  if (m.majorant_cell_samples < 0) return fmt::format("majorant_cell_samples {} must be >= 0", m.majorant_cell_samples);
  constexpr float kHuge = std::numeric_limits<float>::max();
  if (std::string p = volume_problem(m.density, "density", true, kHuge); !p.empty()) return p;
  if (std::string p = volume_problem(m.emission_scale, "emission scale", true, kHuge); !p.empty()) return p;
  if (m.temperature)
    if (std::string p = volume_problem(*m.temperature, "temperature", true, kHuge, -kHuge); !p.empty()) return p;
  for (auto [name, value] : {std::pair{"temperature scale", m.temperature_scale},
                             std::pair{"temperature offset", m.temperature_offset},
                             std::pair{"temperature cutoff", m.temperature_cutoff}})
    if (!std::isfinite(value)) return fmt::format("{} {} must be finite", name, value);
  return volume_problem(m.albedo, "albedo", false, 1.0f);
}

namespace {

// pbrt-v4's DNoise: the noise's gradient at p as forward differences over 0.01 (not the analytic
// gradient: the cloud's displacement is defined by these differences).
Vec3 cloud_noise_forward_gradient(const Point3& p) {
  constexpr float kStep = 0.01f;
  const float n = perlin_noise(p);
  return Vec3(perlin_noise(p + Vec3(kStep, 0, 0)) - n, perlin_noise(p + Vec3(0, kStep, 0)) - n,
              perlin_noise(p + Vec3(0, 0, kStep)) - n) /
         kStep;
}

}  // namespace

float cloud_density(const CloudDensity& cloud, const Point3& p) {
  // Step 1: the lookup point, scaled by the frequency and displaced by two octaves of the noise's
  // gradient (amplitude 0.05 wispiness, halving; frequency 10, times 1.99 per octave).
  Point3 q = p * cloud.frequency;
  if (cloud.wispiness > 0) {
    float amplitude = 0.05f * cloud.wispiness, frequency = 10;
    for (int octave = 0; octave < 2; ++octave) {
      q += amplitude * cloud_noise_forward_gradient(q * frequency);
      amplitude *= 0.5f;
      frequency *= 1.99f;
    }
  }
  // Step 2: five octaves of noise of amplitude 0.5^(i + 1) and frequency 1.99^i, which is half of
  // fbm with omega 0.5 (the same products in the same order, halved exactly).
  const float noise = 0.5f * fbm(q, 0.5f, 5);
  // Step 3: the altitude falloff, the noise's cloud thinning towards p.y = 1 and a floor of full
  // density rising below p.y = 0.5.
  const float from_noise = std::clamp((1 - p.y) * 4.5f * cloud.density * noise, 0.0f, 1.0f);
  return std::min(from_noise + 2 * std::max(0.0f, 0.5f - p.y), 1.0f);
}

float cloud_density_bound(const CloudDensity& cloud, float y_lo, float y_hi) {
  // Each octave of noise is a convex combination (faded trilinear weights) of corner values +-u +- v
  // with offsets |u|, |v| <= 1, so within [-2, 2] wherever the lookup point is; the five octaves'
  // amplitudes sum to 1 - 1/32. The 1e-3 covers rounding in the noise and the products.
  constexpr float kNoiseBound = 2 * (1 - 1.0f / 32) * (1 + 1e-3f);
  const float lever = std::max(std::abs(1 - y_lo), std::abs(1 - y_hi));  // |1 - p.y| at most
  const float from_noise = std::min(lever * 4.5f * std::abs(cloud.density) * kNoiseBound, 1.0f);
  return std::min(from_noise + 2 * std::max(0.0f, 0.5f - y_lo), 1.0f);
}

Volume::Volume(const VolumeDesc& desc)
    : constant_(desc.constant),
      resolution_(desc.resolution),
      channels_(desc.channels),
      values_(desc.values),
      world_to_grid_(desc.to_world.inverse()),
      border_(desc.border),
      cloud_(desc.cloud) {}

float Volume::cloud_at(const Point3& g) const {
  // The unit cube's point in the cloud's own space (CloudDensity::unit_cube_to_cloud).
  return cloud_density(*cloud_, cloud_->box_min + g * (cloud_->box_max - cloud_->box_min));
}

float Volume::sample(int x, int y, int z, int c) const {
  const int nx = resolution_[0], ny = resolution_[1], nz = resolution_[2];
  if (border_ == VolumeBorder::Zero) {
    if (x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz) return 0;
  } else {
    x = std::clamp(x, 0, nx - 1);
    y = std::clamp(y, 0, ny - 1);
    z = std::clamp(z, 0, nz - 1);
  }
  return (*values_)[((size_t(z) * size_t(ny) + size_t(y)) * size_t(nx) + size_t(x)) * size_t(channels_) + size_t(c)];
}

// Samples sit at voxel centres: grid point u maps to sample coordinate u n - 1/2.
float Volume::lookup(const Point3& g, int c) const {
  float fx = g.x * float(resolution_[0]) - 0.5f, fy = g.y * float(resolution_[1]) - 0.5f,
        fz = g.z * float(resolution_[2]) - 0.5f;
  float x0 = std::floor(fx), y0 = std::floor(fy), z0 = std::floor(fz);
  float wx = fx - x0, wy = fy - y0, wz = fz - z0;
  int ix = int(x0), iy = int(y0), iz = int(z0);
  auto lerp = [](float a, float b, float w) { return a + (b - a) * w; };
  float c00 = lerp(sample(ix, iy, iz, c), sample(ix + 1, iy, iz, c), wx);
  float c10 = lerp(sample(ix, iy + 1, iz, c), sample(ix + 1, iy + 1, iz, c), wx);
  float c01 = lerp(sample(ix, iy, iz + 1, c), sample(ix + 1, iy, iz + 1, c), wx);
  float c11 = lerp(sample(ix, iy + 1, iz + 1, c), sample(ix + 1, iy + 1, iz + 1, c), wx);
  return lerp(lerp(c00, c10, wy), lerp(c01, c11, wy), wz);
}

RGB Volume::at(const Point3& p) const {
  if (cloud_) return RGB(cloud_at(world_to_grid_.point(p)));
  if (!values_) return constant_;
  Point3 g = world_to_grid_.point(p);
  if (channels_ == 1) return RGB(lookup(g, 0));
  return {lookup(g, 0), lookup(g, 1), lookup(g, 2)};
}

float Volume::scalar_at(const Point3& p) const {
  if (cloud_) return cloud_at(world_to_grid_.point(p));
  if (!values_) return constant_.r;
  return lookup(world_to_grid_.point(p), 0);
}

float Volume::max_in(const Point3& lo, const Point3& hi) const {
  if (cloud_) {
    // The cloud's bound depends on altitude only. The cell a tracking step lands in and the altitude
    // of its point are rounded separately, so the altitude range is widened a little.
    const float y0 = cloud_->box_min.y, extent = cloud_->box_max.y - cloud_->box_min.y;
    const float y_lo = y0 + lo.y * extent, y_hi = y0 + hi.y * extent;
    const float pad = 1e-3f * (y_hi - y_lo) + 1e-5f * (1 + std::max(std::abs(y_lo), std::abs(y_hi)));
    return cloud_density_bound(*cloud_, y_lo - pad, y_hi + pad);
  }
  if (!values_) return constant_.r;
  // The samples a lookup in [lo, hi] interpolates: from floor(lo n - 1/2) to floor(hi n - 1/2) + 1.
  int first[3], last[3];
  for (int a = 0; a < 3; ++a) {
    const int n = resolution_[a];
    first[a] = std::clamp(int(std::floor(lo[a] * float(n) - 0.5f)), 0, n - 1);
    last[a] = std::clamp(int(std::floor(hi[a] * float(n) - 0.5f)) + 1, 0, n - 1);
  }
  float m = 0;
  for (int z = first[2]; z <= last[2]; ++z)
    for (int y = first[1]; y <= last[1]; ++y)
      for (int x = first[0]; x <= last[0]; ++x) m = std::max(m, sample(x, y, z, 0));
  return m;
}

RGB Medium::emission(const Point3& p) const {
  if (!emissive_) return RGB(0.0f);
  const float scale = emission_scale_.scalar_at(p);
  if (!(scale > 0)) return RGB(0.0f);
  if (!has_temperature_) return emission_ * scale;
  // Possibly nothing: pbrt-v4 emits only above the cutoff (its grid medium's 100 K).
  const float kelvin = (temperature_.scalar_at(p) - temperature_offset_) * temperature_scale_;
  if (!(kelvin > temperature_cutoff_)) return RGB(0.0f);
  // Below about 1,900 K the blackbody lies outside the sRGB gamut (blue, then green, negative):
  // clipped, as emission is never negative.
  const RGB c = blackbody_peak_normalised_rgb(kelvin) * scale;
  return c.map([](float v) { return std::max(v, 0.0f); });
}

Medium::Medium(const MediumDesc& desc)
    : density_(desc.density),
      albedo_(desc.albedo),
      emission_scale_(desc.emission_scale),
      temperature_(desc.temperature.value_or(VolumeDesc{})),
      sigma_t_(desc.sigma_t * desc.scale),
      emission_(desc.emission),
      has_temperature_(desc.temperature.has_value()),
      temperature_scale_(desc.temperature_scale),
      temperature_offset_(desc.temperature_offset),
      temperature_cutoff_(desc.temperature_cutoff),
      phase_{desc.g} {
  subsurface_ = desc.subsurface;
  // Emissive unless the scale is 0 everywhere, or nothing is emitted where it is not.
  const bool scale_is_zero = emission_scale_.is_constant() && !(emission_scale_.constant().r > 0);
  emissive_ = !scale_is_zero && (has_temperature_ || !emission_.is_black());
  if (density_.is_constant()) return;
  // The majorant grid: a cell per majorant_cell_samples^3 samples of the density (4 by default), at
  // most 64 per axis and at least one (pbrt-v4 uses a fixed 16^3; scaling with the grid keeps empty
  // space skippable in large clouds). A cloud's bound varies with altitude only: slabs along the
  // cloud's y axis (its box's y is the unit cube's), or one bound as pbrt-v4 has.
  const int k = desc.majorant_cell_samples;
  constexpr int kCloudAltitudeSlabs = 32;
  if (density_.is_cloud())
    majorant_resolution_ = {1, k > 0 ? kCloudAltitudeSlabs : 1, 1};
  else
    for (int a = 0; a < 3; ++a)
      majorant_resolution_[a] = k > 0 ? std::clamp((density_.resolution()[a] + k - 1) / k, 1, 64) : 1;
  const auto& r = majorant_resolution_;
  majorant_.resize(size_t(r[0]) * size_t(r[1]) * size_t(r[2]));
  for (int z = 0; z < r[2]; ++z)
    for (int y = 0; y < r[1]; ++y)
      for (int x = 0; x < r[0]; ++x) {
        Point3 lo(float(x) / float(r[0]), float(y) / float(r[1]), float(z) / float(r[2]));
        Point3 hi(float(x + 1) / float(r[0]), float(y + 1) / float(r[1]), float(z + 1) / float(r[2]));
        majorant_[(size_t(z) * size_t(r[1]) + size_t(y)) * size_t(r[0]) + size_t(x)] = density_.max_in(lo, hi);
      }
  // A dense cloud's slabs all reach the bound of 1: one cell then, which the tracking crosses without
  // stopping at every slab.
  if (density_.is_cloud() &&
      std::all_of(majorant_.begin(), majorant_.end(), [&](float bound) { return bound == majorant_.front(); })) {
    majorant_resolution_ = {1, 1, 1};
    majorant_.resize(1);
  }
}

float Medium::density(const Point3& p) const {
  if (density_.is_constant()) return density_.constant().r;
  Point3 g = density_.world_to_grid().point(p);
  // No medium outside the grid's cube (Mitsuba bounds a heterogeneous medium by its volume's box,
  // pbrt-v4 a cloud by its box).
  if (g.x < 0 || g.y < 0 || g.z < 0 || g.x > 1 || g.y > 1 || g.z > 1) return 0;
  return density_.scalar_at(p);
}

float sample_collision(const Medium& m, float sigma, const Ray& ray, float t_max, Rng& rng) {
  float collision = std::numeric_limits<float>::infinity();
  m.for_each_majorant(ray, ray.t_min, t_max, [&](float t0, float t1, float bound) {
    const float sigma_maj = sigma * bound;
    if (!(sigma_maj > 0)) return true;
    for (float t = t0;;) {
      t += -std::log1p(-rng.next_float()) / sigma_maj;
      if (!(t < t1)) return true;
      // A real collision with probability density / bound; else a null one, and on.
      if (rng.next_float() * bound < m.density(ray.at(t))) {
        collision = t;
        return false;
      }
    }
  });
  return collision;
}

float estimate_transmittance(const Medium& m, float sigma, const Ray& ray, float t_max, Rng& rng) {
  if (m.has_constant_density()) {
    const float sigma_t = sigma * m.density(ray.origin);
    return sigma_t > 0 ? std::exp(-sigma_t * t_max) : 1.0f;
  }
  float T = 1;
  m.for_each_majorant(ray, 0, t_max, [&](float t0, float t1, float bound) {
    const float sigma_maj = sigma * bound;
    if (!(sigma_maj > 0)) return true;
    for (float t = t0;;) {
      t += -std::log1p(-rng.next_float()) / sigma_maj;
      if (!(t < t1)) return true;
      T *= std::max(0.0f, 1 - m.density(ray.at(t)) / bound);
      if (T < 0.05f) {
        if (rng.next_float() < 0.75f) T = 0;
        else T /= 0.25f;
      }
      if (!(T > 0)) return false;
    }
  });
  return T;
}

}  // namespace candela
