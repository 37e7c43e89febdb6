#pragma once
// Light from infinitely far away in every direction, read from an image (pbrt-v4's
// ImageInfiniteLight, Mitsuba's envmap). Two parameterisations of the sphere by the image's
// (u, v) in [0,1]^2 (v = 0 the top row), in the light's local frame:
//   Equirectangular       (sin(theta) sin(phi), cos(theta), -sin(theta) cos(phi)), phi = 2 pi u,
//                         theta = pi v (+y up, as Mitsuba); d(omega) = 2 pi^2 sin(theta) du dv
//   EqualAreaOctahedral   Clarberg's equal-area square (+z up, as pbrt-v4); square images only;
//                         d(omega) = 4 pi du dv
// Pixel centres sit at ((x + 0.5) / width, (y + 0.5) / height) and radiance is interpolated
// bilinearly between them (wrapping around in phi for equirectangular maps, clamped at the poles;
// across the folded edges for the octahedral square).
//
// Directions are sampled from a piecewise-constant density over the pixels (for pole rows, over the
// patches between texel centres) proportional to the luminance the bilinear radiance has on average
// over each, times its solid angle, then uniformly within it in (u, v); pdf_li reports exactly that
// density, converted to solid angle.
#include <filesystem>
#include <memory>

#include "candela/film/image.h"
#include "candela/lights/light_sample.h"
#include "candela/math/transform.h"
#include "candela/description/scene_desc.h"

namespace candela {

class EnvironmentLight {
 public:
  static constexpr LightFlags flags = LightFlags::Infinite;
  // `image` is linear RGB radiance (negative and NaN values count as zero) and is multiplied by
  // `scale`; world_from_light orients the map (a rotation; directions are normalised after it).
  // Throws SceneError for an empty image, or a non-square one with the octahedral mapping.
  // mis_compensation: sample in proportion to max(luminance - its mean, 0) instead (Mitsuba's
  // envmap option, after Karlik et al. 2019), leaving the directions that BSDF sampling finds well
  // to it under MIS; every direction with radiance keeps a small density.
  // nearest: each texel's radiance is constant over its cell (pbrt-v4's lookups), not bilinear.
  EnvironmentLight(const Image& image, EnvironmentMapping mapping, const RGB& scale,
                   const Transform& world_from_light, float scene_radius, bool mis_compensation = false,
                   bool nearest = false);

  // Radiance arriving along -world_dir, i.e. seen looking in direction world_dir (for rays that
  // escape the scene). world_dir need not be normalised.
  RGB radiance(const Vec3& world_dir) const;

  LightSample sample_li(const LightSampleContext& ctx, Vec2 u) const;
  float pdf_li(const LightSampleContext& ctx, const Vec3& wi, const Point3& p, const Normal3& n) const;
  // Emission: a direction drawn as sample_li draws it, through the scene disk facing it.
  LightEmission sample_le(Vec2 u_pos, Vec2 u_dir, const SceneSphere& s) const;
  EmissionPdf pdf_le(const Point3& p, const Normal3& n, const Vec3& w, const SceneSphere& s) const;
  // pi R^2 times the luminance integrated over the sphere (pbrt's definition for infinite lights).
  float power() const;
  // Estimated irradiance: pi times the average radiance luminance.
  float importance(const LightSampleContext& ctx) const;

  // The parameterisation itself, in the light's local frame (exposed for tests).
  EnvironmentMapping mapping() const;
  Vec2 direction_to_uv(const Vec3& local_dir) const;
  Vec3 uv_to_direction(Vec2 uv) const;
  Vec3 to_local(const Vec3& world_dir) const;
  Vec3 to_world(const Vec3& local_dir) const;
  // Bilinearly interpolated, scaled radiance at image position uv.
  RGB lookup(Vec2 uv) const;
  // The average luminance of the radiance per unit solid angle.
  float average_luminance() const;

 private:
  struct Data;
  // Shared and immutable: the Light variant stays small and cheap to copy.
  std::shared_ptr<const Data> data_;
};

// Reads desc.filename with read_image and builds the light; throws SceneError naming the file when
// it cannot be read or does not fit the mapping.
EnvironmentLight make_environment_light(const EnvironmentMap& desc, float scene_radius);

}  // namespace candela
