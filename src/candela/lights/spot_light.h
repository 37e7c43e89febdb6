#pragma once
// pbrt-v4's spotlight: a point light of intensity I on its axis, full strength out to
// cos_falloff_start and fading to zero at cos_falloff_end with a smoothstep in cos(theta):
//   I(w) = intensity * smoothstep(cos theta, cos_falloff_end, cos_falloff_start).
#include <cmath>

#include "candela/io/error.h"
#include "candela/lights/light_sample.h"
#include "candela/math/frame.h"
#include "candela/scene/description.h"

namespace candela {

struct SpotLightSource {
  Point3 position;
  Frame frame;    // frame.n is the unit cone axis, the direction the light points
  RGB intensity;  // W/sr on the axis
  float cos_falloff_start = 1, cos_falloff_end = 0;  // cosines of the inner and outer cone angles

  // Hermite smoothstep of x from 0 at a to 1 at b (a step at a when a == b).
  static float smoothstep(float x, float a, float b) {
    if (a == b) return x < a ? 0.0f : 1.0f;
    float t = std::clamp((x - a) / (b - a), 0.0f, 1.0f);
    return t * t * (3 - 2 * t);
  }
  // The fraction of the axial intensity emitted along the unit world direction w (away from the light).
  float falloff(const Vec3& w) const { return smoothstep(dot(w, frame.n), cos_falloff_end, cos_falloff_start); }
  RGB intensity_towards(const Vec3& w) const { return intensity * falloff(w); }

  LightSample sample_li(const LightSampleContext& ctx, Vec2) const {
    Vec3 d = position - ctx.p;
    float dist2 = length_squared(d);
    if (dist2 == 0) return {};
    float dist = std::sqrt(dist2);
    Vec3 wi = d / dist;
    RGB I = intensity_towards(-wi);
    if (I.is_black()) return {};
    return {I / dist2, wi, dist, 1, position, Normal3(0.0f), true};
  }
  // Emission: uniformly within the outer cone (pbrt-v4), weighted by the falloff.
  LightEmission sample_le(Vec2, Vec2 u_dir, const SceneSphere&) const {
    Vec3 w = frame.to_world(square_to_uniform_cone(u_dir, cos_falloff_end));
    return {intensity_towards(w), position, w, Normal3(0.0f), 1, uniform_cone_pdf(cos_falloff_end)};
  }
  EmissionPdf pdf_le(const Point3&, const Normal3&, const Vec3& w, const SceneSphere&) const {
    return {1, dot(w, frame.n) >= cos_falloff_end ? uniform_cone_pdf(cos_falloff_end) : 0.0f};
  }
  float pdf_li(const LightSampleContext&, const Vec3&, const Point3&, const Normal3&) const { return 0; }
  // The smoothstep integrates to half its cosine range, so the cone emits
  // I 2 pi ((1 - cos_start) + (cos_start - cos_end) / 2) (pbrt-v4's SpotLight::Phi).
  float power() const {
    return intensity.luminance() * 2 * kPi * (1 - 0.5f * (cos_falloff_start + cos_falloff_end));
  }
  // Estimated irradiance at ctx: I(w) cos / d^2.
  float importance(const LightSampleContext& ctx) const {
    Vec3 d = position - ctx.p;
    float d2 = std::max(length_squared(d), 1e-12f);
    Vec3 w = d / std::sqrt(d2);
    float cos_p = ctx.n == Normal3(0.0f) ? 1.0f : std::max(0.0f, dot(ctx.n, w));
    return intensity.luminance() * falloff(-w) * cos_p / d2;
  }
};

// From the description: cone_angle is where the light reaches zero, cone_delta the width of the
// falloff inside it (degrees), as pbrt-v4's "coneangle" / "conedelta".
inline SpotLightSource make_spot_light(const SpotLight& desc) {
  float len = length(desc.direction);
  if (!(len > 0) || !std::isfinite(len)) throw SceneError("spot light: the direction must be a non-zero vector");
  float outer = std::clamp(desc.cone_angle, 0.0f, 180.0f);
  float inner = std::clamp(desc.cone_angle - desc.cone_delta, 0.0f, outer);
  SpotLightSource s;
  s.position = desc.position;
  s.frame = Frame(desc.direction / len);
  s.intensity = desc.intensity;
  s.cos_falloff_start = std::cos(radians(inner));
  s.cos_falloff_end = std::cos(radians(outer));
  return s;
}

}  // namespace candela
