#pragma once
// Spot lights: a point light of intensity I on its axis, restricted to a cone.
//   pbrt-v4's falloff: full strength out to cos_falloff_start, fading to zero at cos_falloff_end with
//     a smoothstep in cos(theta): I(w) = intensity * smoothstep(cos theta, cos_falloff_end, cos_falloff_start).
//   Mitsuba 3's (`mitsuba`): 1 within the beam angle, then linear in the angle itself down to zero
//     at the cutoff angle: (cutoff - theta) / (cutoff - beam), zero from the cutoff on.
// Either may be multiplied by an image projected over the cone with Mitsuba's uv: in the light's
// frame (s, t, n) = (x, y, axis), uv = (1/2 + x / (2 z tan(cutoff)), 1/2 + y / (2 z tan(cutoff))).
#include <cmath>

#include "candela/base/error.h"
#include "candela/lights/light_sample.h"
#include "candela/math/frame.h"
#include "candela/description/scene_desc.h"
#include "candela/textures/texture.h"

namespace candela {

struct SpotLightSource {
  static constexpr LightFlags flags = LightFlags::DeltaPosition;
  Point3 position;
  Frame frame;    // frame.n is the unit cone axis, the direction the light points; s, t the texture's x, y
  RGB intensity;  // W/sr on the axis
  float cos_falloff_start = 1, cos_falloff_end = 0;  // cosines of the inner and outer cone angles
  bool mitsuba = false;                              // Mitsuba's linear falloff in the angle
  float beam_angle = 0, cutoff_angle = 0;            // radians (the inner and outer angles)
  const TextureSet* textures = nullptr;              // with texture >= 0: the projected image
  int texture = -1;
  float uv_factor = 1;      // tan(cutoff angle)
  float cone_integral = -1;  // the integral of falloff x texture luminance over directions (< 0: closed form)

  // Hermite smoothstep of x from 0 at a to 1 at b (a step at a when a == b).
  static float smoothstep(float x, float a, float b) {
    if (a == b) return x < a ? 0.0f : 1.0f;
    float t = std::clamp((x - a) / (b - a), 0.0f, 1.0f);
    return t * t * (3 - 2 * t);
  }
  // Mitsuba 3's spot falloff (spot.cpp's falloff_curve) for cos(theta) of a unit direction.
  static float mitsuba_falloff_curve(float cos_theta, float beam, float cutoff) {
    if (!(cos_theta > std::cos(cutoff))) return 0;
    if (cos_theta >= std::cos(beam)) return 1;
    return std::clamp((cutoff - std::acos(std::clamp(cos_theta, -1.0f, 1.0f))) / (cutoff - beam), 0.0f, 1.0f);
  }
  // The fraction of the axial intensity emitted along the unit world direction w (away from the light).
  float falloff(const Vec3& w) const {
    float c = dot(w, frame.n);
    if (mitsuba) return c > cos_falloff_end ? mitsuba_falloff_curve(c, beam_angle, cutoff_angle) : 0.0f;
    return smoothstep(c, cos_falloff_end, cos_falloff_start);
  }
  // Mitsuba's uv of the projected image for a local direction (z > 0).
  Vec2 direction_to_uv(const Vec3& local) const {
    return {0.5f + 0.5f * local.x / (local.z * uv_factor), 0.5f + 0.5f * local.y / (local.z * uv_factor)};
  }
  RGB texture_towards(const Vec3& w) const {
    if (texture < 0 || !textures) return RGB(1.0f);
    Vec3 local = frame.to_local(w);
    if (!(local.z > 0)) return RGB(0.0f);
    ColorInput in;
    in.texture = texture;
    return textures->eval(in, TextureEvalContext{position, direction_to_uv(local)});
  }
  RGB intensity_towards(const Vec3& w) const {
    float f = falloff(w);
    if (f <= 0) return RGB(0.0f);
    return intensity * f * texture_towards(w);
  }

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
  // Emission: uniformly within the outer cone (pbrt-v4 and Mitsuba), weighted by the falloff.
  LightEmission sample_le(Vec2, Vec2 u_dir, const SceneSphere&) const {
    Vec3 w = frame.to_world(square_to_uniform_cone(u_dir, cos_falloff_end));
    return {intensity_towards(w), position, w, Normal3(0.0f), 1, uniform_cone_pdf(cos_falloff_end)};
  }
  EmissionPdf pdf_le(const Point3&, const Normal3&, const Vec3& w, const SceneSphere&) const {
    return {1, dot(w, frame.n) >= cos_falloff_end ? uniform_cone_pdf(cos_falloff_end) : 0.0f};
  }
  float pdf_li(const LightSampleContext&, const Vec3&, const Point3&, const Normal3&) const { return 0; }
  // pbrt's smoothstep integrates to half its cosine range, so the cone emits
  // I 2 pi ((1 - cos_start) + (cos_start - cos_end) / 2) (pbrt-v4's SpotLight::Phi); Mitsuba's
  // falloff and textures are integrated numerically when the light is made (cone_integral).
  float power() const {
    if (cone_integral >= 0) return intensity.luminance() * cone_integral;
    return intensity.luminance() * 2 * kPi * (1 - 0.5f * (cos_falloff_start + cos_falloff_end));
  }
  // Estimated irradiance at ctx: I(w) cos / d^2.
  float importance(const LightSampleContext& ctx) const {
    Vec3 d = position - ctx.p;
    float d2 = std::max(length_squared(d), 1e-12f);
    Vec3 w = d / std::sqrt(d2);
    float cos_p = ctx.n == Normal3(0.0f) ? 1.0f : std::max(0.0f, dot(ctx.n, w));
    return intensity_towards(-w).luminance() * cos_p / d2;
  }
};

// From the description: cone_angle is where the light reaches zero, cone_delta the width of the
// falloff inside it (degrees), as pbrt-v4's "coneangle" / "conedelta" (Mitsuba: cutoff_angle and
// cutoff_angle - beam_width). `textures` is needed when desc.texture >= 0 and must outlive the light.
inline SpotLightSource make_spot_light(const SpotLight& desc, const TextureSet* textures = nullptr) {
  float len = length(desc.direction);
  if (!(len > 0) || !std::isfinite(len)) throw SceneError("spot light: the direction must be a non-zero vector");
  float outer = std::clamp(desc.cone_angle, 0.0f, 180.0f);
  float inner = std::clamp(desc.cone_angle - desc.cone_delta, 0.0f, outer);
  SpotLightSource s;
  s.position = desc.position;
  Vec3 axis = desc.direction / len;
  s.frame = Frame(axis);
  s.intensity = desc.intensity;
  s.cos_falloff_start = std::cos(radians(inner));
  s.cos_falloff_end = std::cos(radians(outer));
  s.mitsuba = desc.falloff == SpotFalloff::Linear;
  s.beam_angle = radians(inner);
  s.cutoff_angle = radians(outer);
  s.uv_factor = std::tan(s.cutoff_angle);
  if (desc.texture >= 0) {
    if (!textures || size_t(desc.texture) >= textures->size())
      throw SceneError(fmt::format("spot light: texture {} does not exist", desc.texture));
    if (!(outer < 90)) throw SceneError("spot light: a projected texture needs a cone angle below 90 degrees");
    s.textures = textures;
    s.texture = desc.texture;
    // The image's axes: x = up x axis, y = axis x x (Mitsuba's look-at frame with `up`).
    Vec3 x = cross(desc.up, axis);
    if (length_squared(x) > 1e-12f) {
      x = normalize(x);
      s.frame.s = x;
      s.frame.t = cross(axis, x);
      s.frame.n = axis;
    }
  }
  if (s.mitsuba || s.texture >= 0) {
    // The integral of falloff x texture luminance over the cone, by the midpoint rule.
    const int n_theta = 256, n_phi = s.texture >= 0 ? 128 : 1;
    double sum = 0;
    for (int i = 0; i < n_theta; ++i) {
      double theta = (i + 0.5) * double(s.cutoff_angle) / n_theta;
      float st = float(std::sin(theta)), ct = float(std::cos(theta));
      double ring = 0;
      for (int j = 0; j < n_phi; ++j) {
        float phi = float((j + 0.5) * 2 * kPi / n_phi);
        Vec3 w = s.frame.to_world(Vec3(st * std::cos(phi), st * std::sin(phi), ct));
        float f = s.falloff(w);
        if (f > 0) ring += f * s.texture_towards(w).luminance();
      }
      sum += ring / n_phi * 2 * kPi * std::sin(theta) * double(s.cutoff_angle) / n_theta;
    }
    s.cone_integral = float(sum);
  }
  return s;
}

}  // namespace candela
