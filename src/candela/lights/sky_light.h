#pragma once
// Light from infinitely far away: a constant colour or a zenith/horizon/ground gradient around `up`.
// Sampled cosine-weighted about the receiving normal when there is one (exact for diffuse surfaces
// under a constant sky), uniformly over the sphere otherwise.
#include "candela/lights/light_sample.h"
#include "candela/math/frame.h"
#include "candela/sampling/warp.h"

namespace candela {

struct SkyLightSource {
  static constexpr LightFlags flags = LightFlags::Infinite;
  RGB zenith, horizon, ground;
  Vec3 up{0, 1, 0};
  float scene_radius = 1;  // bounding-sphere radius of the scene, for power()

  RGB radiance(const Vec3& w) const {
    float c = dot(normalize(w), up);
    if (c < 0) return ground;
    return horizon * (1 - c) + zenith * c;
  }

  LightSample sample_li(const LightSampleContext& ctx, Vec2 u) const {
    Vec3 wi;
    float pdf;
    if (ctx.n == Normal3(0.0f)) {
      wi = square_to_uniform_sphere(u);
      pdf = uniform_sphere_pdf();
    } else {
      Vec3 local = square_to_cosine_hemisphere(u);
      pdf = cosine_hemisphere_pdf(local);
      wi = Frame(ctx.n).to_world(local);
    }
    if (pdf <= 0) return {};
    LightSample s;
    s.radiance = radiance(wi);
    s.wi = wi;
    s.pdf = pdf;
    return s;
  }
  // Emission: from a uniformly chosen direction of the sphere, through the scene disk facing it.
  LightEmission sample_le(Vec2 u_pos, Vec2 u_dir, const SceneSphere& s) const {
    Vec3 w = -square_to_uniform_sphere(u_dir);
    return {radiance(-w), point_on_scene_disk(s, w, u_pos), w, Normal3(0.0f), 1 / (kPi * s.radius * s.radius),
            uniform_sphere_pdf()};
  }
  EmissionPdf pdf_le(const Point3&, const Normal3&, const Vec3&, const SceneSphere& s) const {
    return {1 / (kPi * s.radius * s.radius), uniform_sphere_pdf()};
  }
  float pdf_li(const LightSampleContext& ctx, const Vec3& wi, const Point3&, const Normal3&) const {
    if (ctx.n == Normal3(0.0f)) return uniform_sphere_pdf();
    return std::max(0.0f, dot(ctx.n, wi)) * kInvPi;
  }
  // pi R^2 times the integral of radiance over the sphere (pbrt's definition for infinite lights),
  // integrated exactly for the piecewise-linear profile: the upper hemisphere averages (zenith+horizon)/2.
  // Estimated irradiance: average radiance times pi (the hemisphere's projected solid angle).
  float importance(const LightSampleContext&) const {
    return kPi * (0.5f * ground.luminance() + 0.25f * (zenith.luminance() + horizon.luminance()));
  }
  float power() const {
    float avg = 0.5f * ground.luminance() + 0.5f * (0.5f * (zenith.luminance() + horizon.luminance()));
    return kPi * scene_radius * scene_radius * 4 * kPi * avg;
  }
};

}  // namespace candela
