#pragma once
// pbrt-v4's distant light: parallel light from infinitely far away arriving from the single
// direction -direction. `radiance` is the irradiance it gives a surface facing it.
#include <cmath>
#include <limits>

#include "candela/base/error.h"
#include "candela/lights/light_sample.h"
#include "candela/description/scene_desc.h"

namespace candela {

struct DistantLightSource {
  static constexpr LightFlags flags = LightFlags::DeltaDirection;
  Vec3 direction{0, 0, 1};  // unit, the direction the light travels
  RGB radiance;
  float scene_radius = 1;  // bounding-sphere radius of the scene, for power()

  LightSample sample_li(const LightSampleContext& ctx, Vec2) const {
    Vec3 wi = -direction;
    // The point two scene radii away stands in for "infinitely far" (pbrt-v4 does the same).
    return {radiance, wi, std::numeric_limits<float>::infinity(), 1, ctx.p + wi * (2 * scene_radius), direction,
            true};
  }
  // Emission: the single direction, from a point of the scene disk facing it.
  LightEmission sample_le(Vec2 u_pos, Vec2, const SceneSphere& s) const {
    return {radiance, point_on_scene_disk(s, direction, u_pos), direction, Normal3(0.0f),
            1 / (kPi * s.radius * s.radius), 1};
  }
  EmissionPdf pdf_le(const Point3&, const Normal3&, const Vec3&, const SceneSphere& s) const {
    return {1 / (kPi * s.radius * s.radius), 0};
  }
  float pdf_li(const LightSampleContext&, const Vec3&, const Point3&, const Normal3&) const { return 0; }
  // The light crosses a disk of the scene's radius: pi r^2 E (pbrt-v4's DistantLight::Phi).
  float power() const { return kPi * scene_radius * scene_radius * radiance.luminance(); }
  // Estimated irradiance at ctx: E cos.
  float importance(const LightSampleContext& ctx) const {
    float cos_p = ctx.n == Normal3(0.0f) ? 1.0f : std::max(0.0f, -dot(ctx.n, direction));
    return radiance.luminance() * cos_p;
  }
};

inline DistantLightSource make_distant_light(const DistantLight& desc, float scene_radius) {
  float len = length(desc.direction);
  if (!(len > 0) || !std::isfinite(len)) throw SceneError("distant light: the direction must be a non-zero vector");
  return {desc.direction / len, desc.radiance, scene_radius};
}

}  // namespace candela
