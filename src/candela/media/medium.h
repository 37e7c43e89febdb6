#pragma once
// Participating media as the renderer looks them up (scene/description.h's MediumDesc): the
// coefficients at a point, and the majorant, an upper bound of the extinction along a ray, piecewise
// constant over the cells of a coarse grid (pbrt-v4's majorant grid, traversed by a 3D DDA as its
// DDAMajorantIterator is), so that delta and ratio tracking in sparse grids take long steps through
// empty space instead of the small ones one global maximum would force.
//
// Everything here is in RGB; the integrator converts to a spectral path's wavelengths.
#include <array>
#include <bit>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "candela/geometry/ray.h"
#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/media/phase.h"
#include "candela/sampling/rng.h"
#include "candela/description/scene_desc.h"

namespace candela {

// Why `medium` cannot be rendered, or "" when it can: a negative or non-finite coefficient, scale or
// emission, an albedo outside [0, 1], g outside (-1, 1), a grid whose value count is not nx ny nz
// channels, a density, emission-scale or temperature grid that is not scalar, an albedo grid that is
// neither scalar nor RGB, or a grid value that is negative or not finite (a temperature: not finite). Readers call it to point at the place in the file.
std::string medium_problem(const MediumDesc& medium);

// pbrt-v4's cloud density (description/media.h's CloudDensity, steps 1 to 3) at point p of the cloud's
// own space, whether or not p lies in the cloud's box (the medium clips to it). Within [0, 1].
float cloud_density(const CloudDensity& cloud, const Point3& p);

// An upper bound of cloud_density over every point of the cloud's space whose altitude p.y lies in
// [y_lo, y_hi], from a bound of the noise alone (so it holds for any x, z and displacement): at most 1.
float cloud_density_bound(const CloudDensity& cloud, float y_lo, float y_hi);

// A VolumeDesc ready for lookups at world points.
class Volume {
 public:
  Volume() = default;
  explicit Volume(const VolumeDesc& desc);
  bool is_constant() const { return values_ == nullptr && !cloud_; }
  bool is_cloud() const { return cloud_.has_value(); }
  const RGB& constant() const { return constant_; }
  // Trilinear lookup at world point p (a scalar grid's value in all three channels).
  RGB at(const Point3& p) const;
  // Channel 0 only: the density of a scalar grid.
  float scalar_at(const Point3& p) const;
  // From world space to the grid's unit cube.
  const Transform& world_to_grid() const { return world_to_grid_; }
  const std::array<int, 3>& resolution() const { return resolution_; }
  // The largest channel-0 value any lookup inside the grid-space box [lo, hi] can return (a cloud's:
  // an upper bound of it).
  float max_in(const Point3& lo, const Point3& hi) const;

 private:
  // A cloud's density at grid-space (unit-cube) point g.
  float cloud_at(const Point3& grid_p) const;
  // Sample (x, y, z), channel c, with the border rule outside the grid.
  float sample(int x, int y, int z, int c) const;
  float lookup(const Point3& grid_p, int c) const;

  RGB constant_{1.0f};
  std::array<int, 3> resolution_{0, 0, 0};
  int channels_ = 1;
  std::shared_ptr<const std::vector<float>> values_;
  Transform world_to_grid_;
  VolumeBorder border_ = VolumeBorder::Clamp;
  std::optional<CloudDensity> cloud_;  // a procedural density in place of samples
};

// The coefficients at a point, per unit length.
struct MediumPoint {
  RGB sigma_a, sigma_s;
};

class Medium {
 public:
  explicit Medium(const MediumDesc& desc);

  // scale * sigma_t: the extinction at density 1.
  const RGB& sigma_t() const { return sigma_t_; }
  // The density at p (0 outside a grid's or a cloud's cube; the constant of a homogeneous medium).
  float density(const Point3& p) const;
  RGB albedo(const Point3& p) const { return albedo_.at(p); }
  bool has_albedo_grid() const { return !albedo_.is_constant(); }
  // The radiance emitted at p (MediumDesc: `emission` or a temperature's blackbody, times the
  // emission scale; the blackbody's negative, out-of-gamut components clipped to 0).
  RGB emission(const Point3& p) const;
  bool is_emissive() const { return emissive_; }
  const HenyeyGreenstein& phase() const { return phase_; }
  bool is_homogeneous() const { return density_.is_constant() && albedo_.is_constant(); }
  // The extinction is the same everywhere (the albedo may still vary).
  bool has_constant_density() const { return density_.is_constant(); }
  // A subsurface medium (MediumDesc::subsurface): a path's excursion inside counts as one bounce.
  bool is_subsurface() const { return subsurface_; }

  // Visits the majorant along `ray` over [t_min, t_max): visit(t0, t1, density_bound) for
  // consecutive pieces in order, where the density stays at most density_bound (the majorant of
  // the extinction is density_bound * sigma_t()). Pieces where the medium has no density (outside
  // a grid) are skipped. Stops early when visit returns false; returns whether it ran to the end.
  // `ray.direction` need not be normalised; t is measured in its units.
  template <typename Visit>
  bool for_each_majorant(const Ray& ray, float t_min, float t_max, Visit&& visit) const;

  const std::array<int, 3>& majorant_resolution() const { return majorant_resolution_; }

 private:
  Volume density_, albedo_, emission_scale_, temperature_;
  RGB sigma_t_{1.0f}, emission_{0.0f};
  bool has_temperature_ = false, emissive_ = false, subsurface_ = false;
  float temperature_scale_ = 1, temperature_offset_ = 0, temperature_cutoff_ = 100;
  HenyeyGreenstein phase_;
  // Density grids and clouds: the largest density (a cloud's: a bound of it) over each cell of a
  // coarse grid over the unit cube.
  std::array<int, 3> majorant_resolution_{1, 1, 1};
  std::vector<float> majorant_;
};

// ---------------------------------------------------------------- walks with one extinction

// Distance sampling and transmittance where one extinction per unit density holds for every channel
// (a grey medium, or one colour channel chosen for the whole path): what BDPT and MLT walk media with.
// (volpath carries every channel at once, with its own tracking in integrators/volpath.cpp.)

// A fresh random stream for one walk through a medium, from two sampler dimensions (pbrt-v4 does the
// same), so that the unbounded number of collisions does not consume sampler dimensions. Drawn only
// where there are media, so scenes without keep their samples.
template <typename Sampler>
Rng medium_walk_rng(Sampler& sampler) {
  uint64_t a = std::bit_cast<uint32_t>(sampler.get_1d()), b = std::bit_cast<uint32_t>(sampler.get_1d());
  return Rng(hash_values(a, b, 11), hash_values(b, a, 13));
}

// Delta tracking along `ray` (unit direction) over [ray.t_min, t_max), extinction sigma x density:
// the distance of the first real collision, or infinity.
float sample_collision(const Medium& m, float sigma, const Ray& ray, float t_max, Rng& rng);

// The transmittance over [0, t_max) of `ray`: exact where the density is constant, else ratio
// tracking's unbiased estimate (with Russian roulette where little gets through).
float estimate_transmittance(const Medium& m, float sigma, const Ray& ray, float t_max, Rng& rng);

// ---------------------------------------------------------------- implementation of the traversal

template <typename Visit>
bool Medium::for_each_majorant(const Ray& ray, float t_min, float t_max, Visit&& visit) const {
  if (!(t_max > t_min)) return true;
  if (density_.is_constant()) return visit(t_min, t_max, density_.constant().r);

  // Into grid space (affine, so t keeps its meaning) and clip to the unit cube.
  const Transform& to_grid = density_.world_to_grid();
  const Point3 o = to_grid.point(ray.origin);
  const Vec3 d = to_grid.vector(ray.direction);
  float t0 = t_min, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0) {
      if (o[a] < 0 || o[a] > 1) return true;
      continue;
    }
    float inv = 1 / d[a];
    float near = (0 - o[a]) * inv, far = (1 - o[a]) * inv;
    if (near > far) std::swap(near, far);
    t0 = std::max(t0, near);
    t1 = std::min(t1, far);
  }
  if (!(t1 > t0)) return true;

  // 3D DDA over the majorant cells (Amanatides and Woo), starting in the cell that holds the
  // entry point.
  const std::array<int, 3>& res = majorant_resolution_;
  const Point3 entry = o + d * t0;
  int cell[3], step[3], stop[3];
  float next_t[3], delta_t[3];
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::clamp(int(entry[a] * float(res[a])), 0, res[a] - 1);
    if (d[a] == 0) {
      next_t[a] = std::numeric_limits<float>::infinity();
      delta_t[a] = 0;
      step[a] = 0;
      stop[a] = -2;
    } else if (d[a] > 0) {
      next_t[a] = t0 + (float(cell[a] + 1) / float(res[a]) - entry[a]) / d[a];
      delta_t[a] = 1 / (float(res[a]) * d[a]);
      step[a] = 1;
      stop[a] = res[a];
    } else {
      next_t[a] = t0 + (float(cell[a]) / float(res[a]) - entry[a]) / d[a];
      delta_t[a] = -1 / (float(res[a]) * d[a]);
      step[a] = -1;
      stop[a] = -1;
    }
  }
  float t = t0;
  for (;;) {
    int axis = next_t[0] < next_t[1] ? (next_t[0] < next_t[2] ? 0 : 2) : (next_t[1] < next_t[2] ? 1 : 2);
    float t_end = std::min(next_t[axis], t1);
    if (t_end > t) {
      float bound = majorant_[(size_t(cell[2]) * size_t(res[1]) + size_t(cell[1])) * size_t(res[0]) + size_t(cell[0])];
      if (bound > 0 && !visit(t, t_end, bound)) return false;
      t = t_end;
    }
    if (t_end >= t1) return true;
    cell[axis] += step[axis];
    if (cell[axis] == stop[axis]) return true;
    next_t[axis] += delta_t[axis];
  }
}

}  // namespace candela
