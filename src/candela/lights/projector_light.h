#pragma once
// A point light at the origin of to_world that projects an image along its local +z through a
// pinhole: Mitsuba 3's projector and pbrt-v4's "projection" light. The field of view spans the
// image's wider axis (Mitsuba's, after the reader's conversion) or its shorter one (pbrt-v4's), the
// other axis following from the aspect ratio (tan_y / tan_x = height / width). A local point q
// (q.z > 0) sees the image at Mitsuba's uv
//   uv = (1/2 - q.x / (2 q.z tan_x), 1/2 - q.y / (2 q.z tan_y)),   inside [0,1]^2 only
// (pbrt-v4's image orientation is the reader's business: it mirrors the texture's mapping).
// ProjectorRadiometry::Irradiance, as Mitsuba defines it (projector.cpp's sample_direction):
//   L_i = pi scale irradiance(uv) / (q.z^2 cos(theta)),   theta from the local +z axis,
// i.e. the intensity I = pi scale irradiance(uv) / cos^3(theta): a white Lambertian plane facing it at
// unit distance then shows radiance scale irradiance(uv) (its irradiance is pi scale irradiance(uv)).
// ProjectorRadiometry::Intensity, as pbrt-v4 defines it (ProjectionLight::I): I = scale image(uv),
// with no cos^3 (a facing plane at unit distance gets irradiance scale image(uv) cos^4(theta)).
// Emission rays are importance-sampled by the image (a 2D distribution over its texels, as
// Mitsuba's sample_ray and pbrt-v4's SampleLe), with solid-angle pdf p_uv / (4 tan_x tan_y cos^3 theta)
// (the unit-distance image plane has area 4 tan_x tan_y, and d(omega) = cos^3(theta) dA on it).
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
  ProjectorRadiometry radiometry = ProjectorRadiometry::Irradiance;
  std::shared_ptr<const Distribution2D> distribution;  // over Mitsuba's (u, v), row = v
  // The mean over [0,1]^2 of the luminance of the intensity times cos^3(theta): the power emitted per
  // unit area of the unit-distance image plane (pi scale image for Mitsuba's radiometry).
  float mean_plane_emission = 0;

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
  // How the image becomes intensity at cos(theta) = c from the axis: pi / c^3 (Mitsuba) or 1 (pbrt-v4).
  float intensity_factor(float c) const {
    return radiometry == ProjectorRadiometry::Irradiance ? kPi / (c * c * c) : 1.0f;
  }
  // Intensity along the unit local direction d inside the frustum.
  RGB intensity(const Vec3& local_dir, Vec2 uv) const { return image(uv) * intensity_factor(local_dir.z); }

  LightSample sample_li(const LightSampleContext& ctx, Vec2) const {
    Vec3 q = to_world.inverse().point(ctx.p);
    Vec2 uv;
    if (!local_to_uv(q, uv)) return {};
    Vec3 d = position - ctx.p;
    float dist2 = length_squared(d);
    if (!(dist2 > 0)) return {};
    float dist = std::sqrt(dist2);
    RGB L = image(uv) * (intensity_factor(q.z / std::sqrt(dist2)) / dist2);
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
  // Phi = integral of I over the frustum = integral of I cos^3 over the unit-distance image plane,
  // whose area is 4 tan_x tan_y.
  float power() const { return 4 * tan_x * tan_y * mean_plane_emission; }
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
  p.radiometry = desc.radiometry;
  if (desc.irradiance >= 0) {
    if (!textures || size_t(desc.irradiance) >= textures->size())
      throw SceneError(fmt::format("projector: texture {} does not exist", desc.irradiance));
    p.textures = textures;
    p.texture = desc.irradiance;
  }
  if (!(desc.fov_degrees > 0 && desc.fov_degrees < 180))
    throw SceneError(fmt::format("projector: the field of view must lie in (0, 180) degrees, not {}", desc.fov_degrees));
  auto [w, h] = textures && p.texture >= 0 ? textures->resolution(p.texture) : std::pair<int, int>{1, 1};
  // The fov spans the image's wider or shorter axis (ProjectorFovAxis; Mitsuba's fov_axis is
  // converted to the wider by the reader); the other follows from the aspect ratio.
  const float t = std::tan(radians(desc.fov_degrees) / 2);
  const bool fov_on_x = (w >= h) == (desc.fov_axis == ProjectorFovAxis::Larger);
  p.tan_x = fov_on_x ? t : t * float(w) / float(h);
  p.tan_y = fov_on_x ? t * float(h) / float(w) : t;
  // Power per unit area of the unit-distance image plane over the cells of an nu x nv grid over the
  // image (its texels, up to 1024 a side): the luminance of the image at the cell's centre times pi
  // (Mitsuba's radiometry, where I cos^3 = pi scale image) or times the cell's mean cos^3(theta)
  // (pbrt-v4's). That mean is exact (the cell's solid angle over its area, since d(omega) = cos^3 dA)
  // or, for pbrt-v4's "power" normalisation, cos^3 at the cell's centre as pbrt-v4 evaluates it.
  const int nu = std::min(w, 1024), nv = std::min(h, 1024);
  std::vector<float> centre(size_t(nu) * size_t(nv));
  // Solid angle of the unit-distance plane's rectangle [0, x] x [0, y] (x, y of either sign).
  auto corner_solid_angle = [](double x, double y) { return std::atan(x * y / std::sqrt(1 + x * x + y * y)); };
  auto plane_emission = [&](bool cos3_at_centre) {
    const double cell_w = 2.0 * p.tan_x / nu, cell_h = 2.0 * p.tan_y / nv;
    double sum = 0;
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        const Vec2 uv{(i + 0.5f) / float(nu), (j + 0.5f) / float(nv)};
        double factor = kPi;
        if (p.radiometry == ProjectorRadiometry::Intensity) {
          const double c = p.uv_to_local_direction(uv).z;
          // The cell's corners on the plane (x falls with u and y with v: the sign does not matter).
          const double x0 = -p.tan_x + i * cell_w, x1 = x0 + cell_w, y0 = -p.tan_y + j * cell_h, y1 = y0 + cell_h;
          factor = cos3_at_centre ? c * c * c
                                  : (corner_solid_angle(x1, y1) - corner_solid_angle(x0, y1) -
                                     corner_solid_angle(x1, y0) + corner_solid_angle(x0, y0)) /
                                        (cell_w * cell_h);
        }
        float v = std::max(0.0f, float(factor) * p.image(uv).luminance());
        centre[size_t(j) * size_t(nu) + size_t(i)] = v;
        sum += v;
      }
    return float(sum / double(centre.size()));
  };
  // pbrt-v4's "power": scale the emission so that with scale 1 the projector emits `power` by
  // pbrt-v4's reckoning (texel centres).
  if (desc.power > 0) {
    p.scale = RGB(1.0f);
    const float unit_power = 4 * p.tan_x * p.tan_y * plane_emission(true);
    if (!(unit_power > 0))
      throw SceneError(fmt::format("projector: \"power\" {} cannot be met: the image is black", desc.power));
    p.scale = desc.scale * (desc.power / unit_power);
  }
  p.mean_plane_emission = plane_emission(false);
  // Sampling weights over the image's texels: the largest plane emission among each texel's centre
  // and its neighbours' (bilinear lookups reach halfway into them), with a floor so that every part
  // of the frustum keeps a positive density (unbiased whatever the texture is).
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
