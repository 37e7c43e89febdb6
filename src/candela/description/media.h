#pragma once
// Participating media and their volume grids. Part of the format-neutral scene description (description/scene_desc.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "candela/base/enum_names.h"
#include "candela/base/error.h"
#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/math/vec.h"
#include "candela/description/schema.h"

namespace candela {

// A quantity that varies over space (Mitsuba's volume plugins): a constant, or samples on a grid over
// the unit cube [0,1]^3 of its own space, which to_world places in the scene. Sample (i, j, k) sits at
// the voxel centre ((i + 0.5) / nx, (j + 0.5) / ny, (k + 0.5) / nz); values in between are trilinear,
// and between the outermost centres and the cube's faces they are clamped (Mitsuba's gridvolume with
// its default wrap mode "clamp") or fade to zero (pbrt-v4's grids, whose samples beyond the grid are 0).
enum class VolumeBorder { Clamp, Zero };
constexpr std::string_view enum_name(VolumeBorder v) {
  switch (v) {
    case VolumeBorder::Clamp: return "clamp";
    case VolumeBorder::Zero: return "zero";
  }
  return {};
}
// pbrt-v4's procedural cloud (its "cloud" medium, CloudMedium): a density in [0, 1] at every point p of
// the cloud's own space, pbrt-v4's definition step by step:
//   1. q = frequency p, displaced (where wispiness > 0) by two octaves of the noise's gradient (pbrt-v4's
//      DNoise, a forward difference over 0.01): q += 0.05 wispiness 0.5^i grad noise(10 x 1.99^i q), i = 0, 1;
//   2. s = sum over five octaves i of 0.5^(i + 1) noise(1.99^i q) (Perlin noise, textures/noise.h);
//   3. the altitude falloff: clamp((1 - p.y) 4.5 density s, 0, 1) + 2 max(0, 0.5 - p.y), clamped to [0, 1]
//      (so 1 wherever p.y <= 0, and no cloud from the noise's positive values above p.y = 1).
// The cloud fills the box [box_min, box_max] of its space and nothing outside it. Its parameters carry
// pbrt-v4's names and defaults.
struct CloudDensity {
  float density = 1;    // how strongly the noise turns into cloud (any finite value)
  float wispiness = 1;  // how far the noise's gradient displaces the lookup point; <= 0: not at all
  float frequency = 5;  // the noise's lattice cells per unit length of the cloud's space
  Point3 box_min{0.0f}, box_max{1.0f};  // the box the cloud fills (pbrt-v4's p0 and p1, sorted per axis)
  // The unit cube onto the box: a cloud's VolumeDesc::to_world is the cloud's placement times this.
  Transform unit_cube_to_cloud() const { return Transform::translate(box_min) * Transform::scale(box_max - box_min); }
  bool operator==(const CloudDensity&) const = default;
};

struct VolumeDesc {
  RGB constant{1.0f};  // the value everywhere when there is no grid and no cloud
  std::array<int, 3> resolution{0, 0, 0};
  int channels = 1;  // 1 (a scalar) or 3 (RGB)
  // nx ny nz channels floats, a sample's channels together, x fastest, then y, then z; null = constant.
  std::shared_ptr<const std::vector<float>> values;
  Transform to_world;    // the grid's unit cube to world space
  VolumeBorder border = VolumeBorder::Clamp;
  std::string filename;  // where it was read from, for messages (empty: made in memory)
  std::string grid_name;  // the grid within an OpenVDB or NanoVDB file
  // The part of to_world that the file itself gives (a VDB grid's voxel placement; identity for .vol
  // files and inline grids): to_world = the scene's own placement x file_to_world.
  Transform file_to_world;
  // pbrt-v4's procedural cloud in place of samples (values stays null; a density only): the density at
  // unit-cube point u is the cloud's at unit_cube_to_cloud() u, and to_world = the cloud's placement x
  // unit_cube_to_cloud().
  std::optional<CloudDensity> cloud;
  bool is_constant() const { return !values && !cloud; }
};

// A participating medium (pbrt-v4's homogeneous, uniformgrid, nanovdb and cloud, Mitsuba 3's homogeneous
// and heterogeneous): extinction sigma_t(p) = scale * sigma_t * density(p), of which the fraction
// albedo(p) scatters (sigma_s = albedo sigma_t) and the rest is absorbed (sigma_a = sigma_t - sigma_s).
// A medium whose density is a grid or a cloud has no density outside its unit cube (Mitsuba bounds a
// heterogeneous medium by its volume's box; pbrt-v4 a cloud by its box). It emits radiance Le(p)
// (`emission`, or a temperature's blackbody, times an emission scale) in proportion to absorption (the
// source term sigma_a Le, as pbrt-v4 defines Le). Light scatters by Henyey-Greenstein's phase
// function with mean cosine g in (-1, 1) (0: isotropic).
struct MediumDesc {
  RGB sigma_t{1.0f};    // per unit length, times density and scale
  VolumeDesc density;   // a scalar; constant 1 = homogeneous
  VolumeDesc albedo;    // RGB in [0, 1]
  float scale = 1;
  RGB emission{0.0f};
  // Emission that varies through the medium (pbrt-v4's grid and NanoVDB media): the radiance emitted
  // at p is emission_scale(p) times, with a temperature, pbrt-v4's peak-normalised blackbody
  // (spectral/blackbody.h) at (temperature(p) - temperature_offset) x temperature_scale kelvin where
  // that exceeds temperature_cutoff (nothing elsewhere), and without one `emission`.
  VolumeDesc emission_scale;               // a scalar >= 0; constant 1 by default
  std::optional<VolumeDesc> temperature;  // a scalar (kelvin before offset and scale)
  float temperature_scale = 1, temperature_offset = 0, temperature_cutoff = 100;
  float g = 0;
  // A density grid's majorant: the largest density over cells of this many samples along each axis
  // (at most 64 cells per axis), traversed cell by cell; 0 = one majorant for the whole grid (what
  // Mitsuba does by default, majorant_resolution_factor = 0). A cloud's majorant: a bound per slab of
  // altitude (32 of them) when > 0, else one (pbrt-v4's, 1). Changes the noise, not the expectation.
  int majorant_cell_samples = 4;
  // A subsurface medium (pbrt-v4's "subsurface" material: a dielectric boundary around it): a path's
  // whole excursion inside counts as one bounce, as pbrt-v4's BSSRDF does. Its scattering events, and
  // the surfaces it meets while inside (the boundary's internal reflections and the way out), do not
  // count towards max_depth; the bounce that entered it does (integrators/volpath.cpp).
  bool subsurface = false;
  std::string name;      // for messages
  SourceLocation where;  // where the scene file declares it
  bool is_homogeneous() const { return density.is_constant() && albedo.is_constant(); }
};
// A medium's "type" is "homogeneous" where density and albedo are constants, "grid" where either
// varies (the readers' check; the schema has no member for it). sigma_a and sigma_s are JSON's and
// pbrt-v4's other way of giving sigma_t and the albedo (set_sigma_a_sigma_s).
template <>
struct SchemaOf<MediumDesc> {
  using T = MediumDesc;
  static constexpr Field fields[] = {
      field<&T::sigma_t>("sigma_t", kNonNegative, "extinction per unit length, times density and scale"),
      volume_field<&T::albedo>("albedo", true, kAlbedo, "the fraction of extinction that scatters"),
      volume_field<&T::density>("density", false, kNonNegative,
                                "multiplies sigma_t; a grid or a procedural cloud for a \"grid\" medium"),
      field<&T::scale>("scale", kNonNegative, "multiplies sigma_t"),
      field<&T::g>("g", ValueRange{.lo = -1, .hi = 1, .lo_open = true, .hi_open = true},
                   "Henyey-Greenstein's mean cosine"),
      field<&T::emission>("emission", kNonNegative, "radiance emitted in proportion to absorption")
          .ignored_where("temperature"),
      volume_field<&T::emission_scale>("emission_scale", false, kNonNegative, "multiplies the emission"),
      volume_field<&T::temperature>("temperature", false, kAnyValue, "kelvin: a blackbody replaces emission"),
      field<&T::temperature_scale>("temperature_scale"),
      field<&T::temperature_offset>("temperature_offset"),
      field<&T::temperature_cutoff>("temperature_cutoff"),
      field<&T::majorant_cell_samples>("majorant_cell_samples", ValueRange{.lo = 0, .hi = 1 << 20},
                                       "a density grid's samples per majorant cell along each axis; 0: one majorant"),
      field<&T::subsurface>("subsurface", kAnyValue,
                            "a path's excursion inside counts as one bounce (volpath), as a BSSRDF's does"),
  };
  static constexpr TypeSchema schema{.name = "homogeneous", .fields = fields, .help = "a participating medium"};
};

// pbrt-v4's and JSON's way of giving a medium: absorption and scattering coefficients.
inline void set_sigma_a_sigma_s(MediumDesc& m, const RGB& sigma_a, const RGB& sigma_s) {
  m.sigma_t = sigma_a + sigma_s;
  m.albedo.constant = {m.sigma_t.r > 0 ? sigma_s.r / m.sigma_t.r : 0.0f, m.sigma_t.g > 0 ? sigma_s.g / m.sigma_t.g : 0.0f,
                       m.sigma_t.b > 0 ? sigma_s.b / m.sigma_t.b : 0.0f};
}

}  // namespace candela
