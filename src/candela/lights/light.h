#pragma once
// The light contract. Each light offers
//   sample_li(ctx, u)         a point or direction on the light as seen from ctx, with the radiance
//                             arriving along it and the solid-angle pdf (1 for delta lights)
//   pdf_li(ctx, wi, p, n)     the solid-angle pdf sample_li would give for the direction wi reaching
//                             the light at point p with normal n (for MIS on BSDF-sampled hits)
//   power()                   emitted power (luminance), for choosing lights proportionally
//   sample_le(u_pos, u_dir, S) a ray of emitted light with its position and direction densities
//                             (lights at infinity start theirs on a disk of the scene's sphere S)
//   pdf_le(p, n, w, S)        the densities sample_le gives the ray from p along w
//   static constexpr flags    what kind of emitter the type is (light_flags.h)
// Lights that surround the scene (LightFlags::Infinite: sky, environment map) also offer radiance(dir)
// for rays that escape the scene; delta lights (point, spot, projector, goniometric, distant) are reached only by
// sampling them.
// The closed list of lights is the variant `Light`; dispatch happens once, here.
#include <limits>
#include <variant>

#include "candela/lights/area_lights.h"
#include "candela/lights/distant_light.h"
#include "candela/lights/environment_light.h"
#include "candela/lights/goniometric_light.h"
#include "candela/lights/point_light.h"
#include "candela/lights/projector_light.h"
#include "candela/lights/sky_light.h"
#include "candela/lights/spot_light.h"

namespace candela {

using Light = std::variant<PointLightSource, TriangleLight, RectangleLight, SphereLight, SkyLightSource,
                           SpotLightSource, DistantLightSource, EnvironmentLight, DiskLight, CylinderLight,
                           ProjectorLightSource, PartialSphereLight, GoniometricLightSource>;

inline LightSample light_sample_li(const Light& l, const LightSampleContext& ctx, Vec2 u) {
  return std::visit([&](const auto& x) { return x.sample_li(ctx, u); }, l);
}
inline float light_pdf_li(const Light& l, const LightSampleContext& ctx, const Vec3& wi, const Point3& p,
                          const Normal3& n) {
  return std::visit([&](const auto& x) { return x.pdf_li(ctx, wi, p, n); }, l);
}
inline float light_power(const Light& l) {
  return std::visit([](const auto& x) { return x.power(); }, l);
}
// A ray leaving the light (u_pos picks its origin, u_dir its direction), for paths traced from lights.
inline LightEmission light_sample_le(const Light& l, Vec2 u_pos, Vec2 u_dir, const SceneSphere& scene) {
  return std::visit([&](const auto& x) { return x.sample_le(u_pos, u_dir, scene); }, l);
}
// The densities with which light_sample_le produces the ray from p (normal n) along w.
inline EmissionPdf light_pdf_le(const Light& l, const Point3& p, const Normal3& n, const Vec3& w,
                                const SceneSphere& scene) {
  return std::visit([&](const auto& x) { return x.pdf_le(p, n, w, scene); }, l);
}
// Estimated irradiance the light gives at ctx (radiance x projected solid angle): the paper's rule
// for spending shadow rays (sec. 4.5). Only a heuristic: estimators stay unbiased whatever it says.
inline float light_importance(const Light& l, const LightSampleContext& ctx) {
  return std::visit([&](const auto& x) { return x.importance(ctx); }, l);
}
// The light's flags (light_flags.h): what kind of emitter its type is.
inline LightFlags light_flags(const Light& l) {
  return std::visit([](const auto& x) { return std::decay_t<decltype(x)>::flags; }, l);
}
// Lights of a single point or direction: found only by sampling them, never by a ray.
inline bool light_is_delta(const Light& l) {
  return has(light_flags(l), LightFlags::DeltaPosition | LightFlags::DeltaDirection);
}
// Lights at infinity: their light paths start on the disk of the scene's bounding sphere (those
// that surround the scene, and those of a single direction; pbrt-v4's IsInfiniteLight).
inline bool light_is_at_infinity(const Light& l) {
  return has(light_flags(l), LightFlags::Infinite | LightFlags::DeltaDirection);
}
// Radiance arriving along -dir from a light that surrounds the scene (LightFlags::Infinite), seen by
// a ray escaping along dir; the other lights are never seen by escaping rays.
inline RGB light_escaped_radiance(const Light& l, const Vec3& dir) {
  return std::visit(
      [&](const auto& x) {
        if constexpr (has(std::decay_t<decltype(x)>::flags, LightFlags::Infinite)) return x.radiance(dir);
        else return RGB(0.0f);
      },
      l);
}

}  // namespace candela
