#pragma once
// Mitsuba 3's projector: a point light at the origin of to_world that projects an image along its
// local +z through a pinhole, with the field of view fov on the image's wider axis (the other from
// the aspect ratio: tan_y = tan_x height / width). A local point q (q.z > 0) sees the image at Mitsuba's uv
//   uv = (1/2 - q.x / (2 q.z tan_x), 1/2 - q.y / (2 q.z tan_y)),   inside [0,1]^2 only,
// and receives, as Mitsuba defines it (projector.cpp's sample_direction),
//   L_i = pi scale irradiance(uv) / (q.z^2 cos(theta)),   theta from the local +z axis,
// i.e. the intensity I = pi scale irradiance(uv) / cos^3(theta): a white Lambertian plane facing it at
// unit distance then shows radiance scale irradiance(uv) (its irradiance is pi scale irradiance(uv)).
// Emission rays are importance-sampled by the image (a 2D distribution over its texels, as
// Mitsuba's sample_ray), with solid-angle pdf p_uv / (4 tan_x tan_y cos^3 theta).
#include <cmath>
#include <memory>
#include <vector>

#include "candela/base/error.h"
#include "candela/lights/light_sample.h"
#include "candela/math/transform.h"
#include "candela/sampling/distribution2d.h"
#include "candela/description/scene_desc.h"
#include "candela/textures/texture.h"

namespace candela {

struct ProjectorLightSource {
  static constexpr LightFlags flags = LightFlags::DeltaPosition;
  Point3 position;
  Transform to_world;
  float tan_x = 1, tan_y = 1;
  RGB scale{1.0f};
  const TextureSet* textures = nullptr;  // the image (texture >= 0; -1 is a constant 1)
  int texture = -1;
  std::shared_ptr<const Distribution2D> distribution;  // over Mitsuba's (u, v), row = v
  float mean_luminance = 0;                             // of scale x image over [0,1]^2

  // Mitsuba's uv for a local direction or point (z > 0); false outside the image.
  bool local_to_uv(const Vec3& q, Vec2& uv) const {
    if (!(q.z > 0)) return false;
    uv = {0.5f - 0.5f * q.x / (q.z * tan_x), 0.5f - 0.5f * q.y / (q.z * tan_y)};
    return uv.x >= 0 && uv.x <= 1 && uv.y >= 0 && uv.y <= 1;
  }
  Vec3 uv_to_local_direction(Vec2 uv) const {
    return normalize(Vec3((1 - 2 * uv.x) * tan_x, (1 - 2 * uv.y) * tan_y, 1));
  }
  RGB image(Vec2 uv) const {
    if (texture < 0 || !textures) return scale;
    ColorInput in;
    in.texture = texture;
    return scale * textures->eval(in, TextureEvalContext{position, uv});
  }
  // Intensity along the unit local direction d inside the frustum: pi scale image / cos^3.
  RGB intensity(const Vec3& local_dir, Vec2 uv) const {
    float c = local_dir.z;
    return image(uv) * (kPi / (c * c * c));
  }

  LightSample sample_li(const LightSampleContext& ctx, Vec2) const {
    Vec3 q = to_world.inverse().point(ctx.p);
    Vec2 uv;
    if (!local_to_uv(q, uv)) return {};
    Vec3 d = position - ctx.p;
    float dist2 = length_squared(d);
    if (!(dist2 > 0)) return {};
    float dist = std::sqrt(dist2);
    float cos_theta = q.z / length(q);
    RGB L = image(uv) * (kPi / (q.z * q.z * cos_theta));
    if (L.is_black()) return {};
    return {L, d / dist, dist, 1, position, Normal3(0.0f), true};
  }
  float pdf_li(const LightSampleContext&, const Vec3&, const Point3&, const Normal3&) const { return 0; }

  // Solid-angle density of emission along the unit local direction d.
  float direction_pdf(const Vec3& d, Vec2 uv) const {
    float c = d.z;
    return distribution->pdf(uv) / (4 * tan_x * tan_y * c * c * c);
  }
  LightEmission sample_le(Vec2, Vec2 u_dir, const SceneSphere&) const {
    Distribution2DSample s = distribution->sample(u_dir);
    if (!(s.pdf > 0)) return {};
    Vec3 d = uv_to_local_direction(s.point);
    float pdf = s.pdf / (4 * tan_x * tan_y * d.z * d.z * d.z);
    Vec3 w = normalize(to_world.vector(d));
    return {intensity(d, s.point), position, w, Normal3(0.0f), 1, pdf};
  }
  EmissionPdf pdf_le(const Point3&, const Normal3&, const Vec3& w, const SceneSphere&) const {
    Vec3 d = to_world.inverse().vector(w);
    float len = length(d);
    if (!(len > 0)) return {1, 0};
    d = d / len;
    Vec2 uv;
    if (!local_to_uv(d, uv)) return {1, 0};
    return {1, direction_pdf(d, uv)};
  }
  // Phi = integral of I over the frustum = pi scale integral of the image over the unit-distance
  // image plane, whose area is 4 tan_x tan_y.
  float power() const { return kPi * 4 * tan_x * tan_y * mean_luminance; }
  float importance(const LightSampleContext& ctx) const {
    LightSample ls = sample_li(ctx, {});
    if (!(ls.pdf > 0)) return 0;
    float cos_p = ctx.n == Normal3(0.0f) ? 1.0f : std::max(0.0f, dot(ctx.n, ls.wi));
    return ls.radiance.luminance() * cos_p;
  }
};

// `textures` must outlive the light.
inline ProjectorLightSource make_projector_light(const ProjectorLight& desc, const TextureSet* textures) {
  ProjectorLightSource p;
  p.to_world = desc.to_world;
  p.position = desc.to_world.point(Point3(0.0f));
  p.scale = desc.scale;
  if (desc.irradiance >= 0) {
    if (!textures || size_t(desc.irradiance) >= textures->size())
      throw SceneError(fmt::format("projector: texture {} does not exist", desc.irradiance));
    p.textures = textures;
    p.texture = desc.irradiance;
  }
  if (!(desc.fov_degrees > 0 && desc.fov_degrees < 180))
    throw SceneError(fmt::format("projector: the field of view must lie in (0, 180) degrees, not {}", desc.fov_degrees));
  auto [w, h] = textures && p.texture >= 0 ? textures->resolution(p.texture) : std::pair<int, int>{1, 1};
  // The fov spans the image's wider axis (the description's convention; Mitsuba's fov_axis is
  // converted by the reader); the other follows from the aspect ratio.
  const float t = std::tan(radians(desc.fov_degrees) / 2);
  p.tan_x = w >= h ? t : t * float(w) / float(h);
  p.tan_y = w >= h ? t * float(h) / float(w) : t;
  // Sampling weights over the image's texels: the largest luminance among each texel's centre and
  // its neighbours' (bilinear lookups reach halfway into them), with a floor so that every part of
  // the frustum keeps a positive density (unbiased whatever the texture is).
  const int nu = std::min(w, 1024), nv = std::min(h, 1024);
  std::vector<float> centre(size_t(nu) * size_t(nv));
  double sum = 0;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      float v = std::max(0.0f, p.image({(i + 0.5f) / float(nu), (j + 0.5f) / float(nv)}).luminance());
      centre[size_t(j) * size_t(nu) + size_t(i)] = v;
      sum += v;
    }
  p.mean_luminance = float(sum / double(centre.size()));
  std::vector<float> weights(centre.size());
  double wsum = 0;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      float m = 0;
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          int x = std::clamp(i + di, 0, nu - 1), y = std::clamp(j + dj, 0, nv - 1);
          m = std::max(m, centre[size_t(y) * size_t(nu) + size_t(x)]);
        }
      weights[size_t(j) * size_t(nu) + size_t(i)] = m;
      wsum += m;
    }
  float floor = wsum > 0 ? float(1e-3 * wsum / double(weights.size())) : 1.0f;
  for (float& wt : weights) wt = std::max(wt, floor);
  p.distribution = std::make_shared<const Distribution2D>(weights, nu, nv);
  return p;
}

}  // namespace candela
