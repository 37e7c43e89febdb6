#pragma once
// Diffuse area lights on shapes: one TriangleLight per emissive triangle (meshes and boxes become
// triangles), RectangleLight, SphereLight, PartialSphereLight, DiskLight and CylinderLight for those shapes. Radiance is constant over the
// surface (or a texture at the point's (u, v) times it) and emitted on the side of `n` (both sides if two_sided).
#include "candela/geometry/quadric_uv.h"
#include "candela/lights/light_sample.h"
#include "candela/math/frame.h"
#include "candela/sampling/warp.h"
#include "candela/textures/texture.h"

namespace candela {

// A textured emitter (AreaEmission::texture): the radiance times the texture at the point's (u, v).
// Light selection (power, importance) uses the untextured radiance: it only steers the choice.
struct EmissionTexture {
  const TextureSet* textures = nullptr;
  int texture = -1;
  RGB operator()(const RGB& radiance, Vec2 uv, const Point3& p) const {
    if (texture < 0) return radiance;
    ColorInput input;
    input.texture = texture;
    return radiance * textures->eval(input, TextureEvalContext{p, uv, {}});
  }
};

// Converts an area density at p_light into a solid-angle density seen from p.
inline float area_to_solid_angle_pdf(float pdf_area, const Point3& p, const Point3& p_light, const Normal3& n_light) {
  Vec3 d = p_light - p;
  float dist2 = length_squared(d);
  float cos_l = std::abs(dot(n_light, d)) / std::sqrt(dist2);
  return cos_l > 0 ? pdf_area * dist2 / cos_l : 0.0f;
}

// Estimated irradiance at ctx from a flat emitter: L times its projected solid angle, measured from
// its centroid (at most pi).
inline float flat_light_importance(const Point3& centroid, const Normal3& n, float area, const RGB& radiance,
                                   bool two_sided, const LightSampleContext& ctx) {
  Vec3 d = centroid - ctx.p;
  float d2 = std::max(length_squared(d), 1e-12f);
  Vec3 w = d / std::sqrt(d2);
  float cos_l = two_sided ? std::abs(dot(n, w)) : std::max(0.0f, -dot(n, w));
  float cos_p = ctx.n == Normal3(0.0f) ? 1.0f : std::max(0.0f, dot(ctx.n, w));
  return radiance.luminance() * std::min(kPi, area * cos_l * cos_p / d2);
}

// The densities of a flat emitter (members n, area, two_sided) drawn uniformly by area with
// cosine-weighted emission: Triangle, Rectangle and Disk lights.
template <class FlatLight>
EmissionPdf flat_light_pdf_le(const FlatLight& light, const Vec3& w) {
  return {1 / light.area, cosine_emission_pdf(light.n, light.two_sided, w)};
}
template <class FlatLight>
float flat_light_pdf_li(const FlatLight& light, const LightSampleContext& ctx, const Point3& p) {
  return area_to_solid_angle_pdf(1 / light.area, ctx.p, p, light.n);
}

// The power of a diffuse emitter of constant radiance and the given area.
inline float uniform_emitter_power(const RGB& radiance, float area, bool two_sided) {
  return radiance.luminance() * area * kPi * (two_sided ? 2 : 1);
}

// Estimated irradiance at ctx from a sphere whose surface emits `luminance`: that times the projected
// solid angle of the cone the sphere subtends (pi from inside it), for choosing lights by importance.
inline float sphere_irradiance_estimate(const Point3& center, float radius, float luminance,
                                        const LightSampleContext& ctx) {
  const Vec3 d = center - ctx.p;
  const float d2 = length_squared(d);
  if (d2 <= radius * radius * 1.0001f) return luminance * kPi;
  const float sin2 = radius * radius / d2;
  const float cos_p = ctx.n == Normal3(0.0f) ? 1.0f : std::max(0.0f, dot(ctx.n, d / std::sqrt(d2)));
  return luminance * kPi * sin2 * cos_p;
}

// The light sample for a point p drawn uniformly by area on a flat emitter, seen from ctx.
inline LightSample flat_light_sample(const Point3& p, const Normal3& n, float area, const RGB& radiance,
                                     bool two_sided, const LightSampleContext& ctx) {
  Vec3 d = p - ctx.p;
  float dist2 = length_squared(d);
  if (dist2 == 0) return {};
  float dist = std::sqrt(dist2);
  Vec3 wi = d / dist;
  if (!two_sided && dot(n, -wi) <= 0) return {};
  float pdf = area_to_solid_angle_pdf(1 / area, ctx.p, p, n);
  if (pdf <= 0 || !std::isfinite(pdf)) return {};
  return {radiance, wi, dist, pdf, p, n, false};
}

struct TriangleLight {
  static constexpr LightFlags flags = LightFlags::Area;
  Point3 p0, p1, p2;
  Normal3 n;  // unit, the emitting side
  float area;
  RGB radiance;
  bool two_sided;
  // Textured emitters only: the vertices' (u, v) and the texture.
  Vec2 uv0{0, 0}, uv1{1, 0}, uv2{0, 1};
  EmissionTexture emission_texture;

  LightSample sample_li(const LightSampleContext& ctx, Vec2 u) const {
    // Uniform point on the triangle, then converted to solid angle.
    Vec2 b = square_to_uniform_triangle(u);
    Point3 p = p0 * b.x + p1 * b.y + p2 * (1 - b.x - b.y);
    return flat_light_sample(p, n, area, radiance_at(b, p), two_sided, ctx);
  }
  // Emission: a uniform point, a cosine-weighted direction on the emitting side(s).
  LightEmission sample_le(Vec2 u_pos, Vec2 u_dir, const SceneSphere&) const {
    Vec2 b = square_to_uniform_triangle(u_pos);
    Point3 p = p0 * b.x + p1 * b.y + p2 * (1 - b.x - b.y);
    float pdf_dir;
    Vec3 w = sample_cosine_emission(n, two_sided, u_dir, pdf_dir);
    return {radiance_at(b, p), p, w, n, 1 / area, pdf_dir};
  }
  RGB radiance_at(Vec2 b, const Point3& p) const {
    if (emission_texture.texture < 0) return radiance;
    return emission_texture(radiance, uv0 * b.x + uv1 * b.y + uv2 * (1 - b.x - b.y), p);
  }
  EmissionPdf pdf_le(const Point3&, const Normal3&, const Vec3& w, const SceneSphere&) const { return flat_light_pdf_le(*this, w); }
  float pdf_li(const LightSampleContext& ctx, const Vec3&, const Point3& p, const Normal3&) const { return flat_light_pdf_li(*this, ctx, p); }
  float power() const { return uniform_emitter_power(radiance, area, two_sided); }
  float importance(const LightSampleContext& ctx) const {
    return flat_light_importance((p0 + p1 + p2) / 3.0f, n, area, radiance, two_sided, ctx);
  }
};

// A parallelogram corner + s edge_u + t edge_v, (s, t) in [0,1]^2, sampled uniformly by area with
// the 2D sample mapped straight onto it, so stratified samples are stratified over the light (the
// paper's stratified rectangular lights, sec. 4.5).
struct RectangleLight {
  static constexpr LightFlags flags = LightFlags::Area;
  Point3 corner;
  Vec3 edge_u, edge_v;
  Normal3 n;  // unit, the emitting side
  float area;
  RGB radiance;
  bool two_sided;
  EmissionTexture emission_texture;  // textured emitters: the point corner + s edge_u + t edge_v has (u, v) = (s, t)

  LightSample sample_li(const LightSampleContext& ctx, Vec2 u) const {
    Point3 p = corner + edge_u * u.x + edge_v * u.y;
    return flat_light_sample(p, n, area, emission_texture(radiance, u, p), two_sided, ctx);
  }
  LightEmission sample_le(Vec2 u_pos, Vec2 u_dir, const SceneSphere&) const {
    float pdf_dir;
    Vec3 w = sample_cosine_emission(n, two_sided, u_dir, pdf_dir);
    Point3 p = corner + edge_u * u_pos.x + edge_v * u_pos.y;
    return {emission_texture(radiance, u_pos, p), p, w, n, 1 / area, pdf_dir};
  }
  EmissionPdf pdf_le(const Point3&, const Normal3&, const Vec3& w, const SceneSphere&) const { return flat_light_pdf_le(*this, w); }
  float pdf_li(const LightSampleContext& ctx, const Vec3&, const Point3& p, const Normal3&) const { return flat_light_pdf_li(*this, ctx, p); }
  float power() const { return uniform_emitter_power(radiance, area, two_sided); }
  float importance(const LightSampleContext& ctx) const {
    return flat_light_importance(corner + (edge_u + edge_v) * 0.5f, n, area, radiance, two_sided, ctx);
  }
};

// A sphere seen from outside is sampled uniformly in the cone it subtends (every sample hits it);
// from inside, uniformly by area.
struct SphereLight {
  static constexpr LightFlags flags = LightFlags::Area;
  Point3 center;
  float radius;
  RGB radiance;
  bool two_sided;
  bool emits_inward;  // reverse orientation: the emitting side faces the centre
  // Textured emitters: the texture, and the world directions of the sphere's own x, y, z axes
  // (orthonormal: emissive spheres are only moved, turned, mirrored and scaled uniformly), which
  // place its (u, v).
  EmissionTexture emission_texture;
  Vec3 object_x{1, 0, 0}, object_y{0, 1, 0}, object_z{0, 0, 1};

  RGB emission_at(const Point3& p) const {
    if (emission_texture.texture < 0) return radiance;
    Vec3 d = p - center;
    return emission_texture(radiance, sphere_uv({dot(d, object_x), dot(d, object_y), dot(d, object_z)}), p);
  }

  bool emits_from(const Normal3& outward, const Vec3& w) const {
    return two_sided || ((dot(outward, w) > 0) != emits_inward);
  }
  bool outside(const Point3& p) const { return length_squared(p - center) > radius * radius * 1.0001f; }
  float cone_cos_max(const Point3& p) const {
    float sin2 = radius * radius / length_squared(p - center);
    return safe_sqrt(1 - sin2);
  }

  LightSample sample_li(const LightSampleContext& ctx, Vec2 u) const {
    Point3 p;
    float pdf;
    if (outside(ctx.p)) {
      // Sample the cone of directions subtended by the sphere, then find the visible point it hits.
      float dc = distance(ctx.p, center);
      float cos_max = cone_cos_max(ctx.p);
      Vec3 local = square_to_uniform_cone(u, cos_max);
      Frame frame(normalize(center - ctx.p));
      Vec3 wi = frame.to_world(local);
      // Nearest intersection of the ray (ctx.p, wi) with the sphere (clamped for grazing samples).
      float b = dc * local.z;
      float disc = std::max(0.0f, radius * radius - dc * dc * (1 - local.z * local.z));
      float t = b - std::sqrt(disc);
      p = ctx.p + wi * t;
      pdf = uniform_cone_pdf(cos_max);
      if (cos_max >= 1) return {};  // too small to see from here in float
    } else {
      p = center + square_to_uniform_sphere(u) * radius;
      pdf = area_to_solid_angle_pdf(1 / (4 * kPi * radius * radius), ctx.p, p, normalize(p - center));
    }
    Normal3 n = normalize(p - center);
    Vec3 d = p - ctx.p;
    float dist = length(d);
    if (dist == 0 || !(pdf > 0) || !std::isfinite(pdf)) return {};
    Vec3 wi = d / dist;
    if (!emits_from(n, -wi)) return {};
    return {emission_at(p), wi, dist, pdf, p, n, false};
  }
  // Emission: a uniform point on the sphere, a cosine-weighted direction on its emitting side(s).
  LightEmission sample_le(Vec2 u_pos, Vec2 u_dir, const SceneSphere&) const {
    Vec3 outward = square_to_uniform_sphere(u_pos);
    Normal3 n = emits_inward ? -outward : outward;
    float pdf_dir;
    Vec3 w = sample_cosine_emission(n, two_sided, u_dir, pdf_dir);
    Point3 p = center + outward * radius;
    return {emission_at(p), p, w, n, 1 / (4 * kPi * radius * radius), pdf_dir};
  }
  EmissionPdf pdf_le(const Point3& p, const Normal3&, const Vec3& w, const SceneSphere&) const {
    Vec3 outward = normalize(p - center);
    return {1 / (4 * kPi * radius * radius), cosine_emission_pdf(emits_inward ? -outward : outward, two_sided, w)};
  }
  float pdf_li(const LightSampleContext& ctx, const Vec3&, const Point3& p, const Normal3&) const {
    if (outside(ctx.p)) return uniform_cone_pdf(cone_cos_max(ctx.p));
    return area_to_solid_angle_pdf(1 / (4 * kPi * radius * radius), ctx.p, p, normalize(p - center));
  }
  float power() const { return uniform_emitter_power(radiance, 4 * kPi * radius * radius, two_sided); }
  float importance(const LightSampleContext& ctx) const {
    return sphere_irradiance_estimate(center, radius, radiance.luminance(), ctx);
  }
};

// A partial sphere (description/shapes.h: SphereShape::partial): the points center + radius (sin theta
// (cos phi axis_x + sin phi axis_y) + cos theta axis_z) with z = radius cos theta in [z_min, z_max] and
// phi in [0, phi_max], axis_x, axis_y, axis_z orthonormal (emissive spheres are only moved, turned,
// mirrored and scaled uniformly). Sampled uniformly by area: z uniform in [z_min, z_max] (Archimedes:
// a sphere's zones of equal height have equal area) and phi uniform in [0, phi_max]; area =
// phi_max radius (z_max - z_min). Whole spheres are SphereLights, which sample the cone they subtend.
struct PartialSphereLight {
  static constexpr LightFlags flags = LightFlags::Area;
  Point3 center;
  Vec3 axis_x, axis_y, axis_z;  // unit: the world directions of the sphere's own axes
  float radius;
  float z_min, z_max;  // heights above the centre along axis_z, within [-radius, radius]
  float phi_max;       // radians
  float area;
  RGB radiance;
  bool two_sided;
  bool emits_inward;  // reverse orientation: the emitting side faces the centre
  // Textured emitters: the texture, and the (u, v) the hits have (pbrt-v4's of the part kept, or
  // Mitsuba's (phi / 2 pi, theta / pi)).
  EmissionTexture emission_texture;
  bool pbrt_uv = false;
  float theta_z_min = kPi, theta_z_max = 0;

  Normal3 emitting_normal(const Point3& p) const {
    Normal3 out = normalize(p - center);
    return emits_inward ? -out : out;
  }
  // A uniform point, its emitting normal and the radiance it emits.
  Point3 point(Vec2 u, Normal3& n, RGB& emitted) const {
    float z = std::lerp(z_min, z_max, u.x);
    float rho = safe_sqrt(radius * radius - z * z);
    float phi = phi_max * u.y, c = std::cos(phi), s = std::sin(phi);
    Vec3 offset = axis_x * (rho * c) + axis_y * (rho * s) + axis_z * z;
    Point3 p = center + offset;
    n = normalize(offset);
    if (emits_inward) n = -n;
    if (emission_texture.texture < 0) {
      emitted = radiance;
    } else {
      Vec3 local(rho * c, rho * s, z);
      Vec2 uv = pbrt_uv ? partial_sphere_uv(local, phi_max, theta_z_min, theta_z_max) : sphere_uv(local);
      emitted = emission_texture(radiance, uv, p);
    }
    return p;
  }
  LightSample sample_li(const LightSampleContext& ctx, Vec2 u) const {
    Normal3 n;
    RGB emitted;
    Point3 p = point(u, n, emitted);
    return flat_light_sample(p, n, area, emitted, two_sided, ctx);
  }
  LightEmission sample_le(Vec2 u_pos, Vec2 u_dir, const SceneSphere&) const {
    Normal3 n;
    RGB emitted;
    Point3 p = point(u_pos, n, emitted);
    float pdf_dir;
    Vec3 w = sample_cosine_emission(n, two_sided, u_dir, pdf_dir);
    return {emitted, p, w, n, 1 / area, pdf_dir};
  }
  EmissionPdf pdf_le(const Point3& p, const Normal3&, const Vec3& w, const SceneSphere&) const {
    return {1 / area, cosine_emission_pdf(emitting_normal(p), two_sided, w)};
  }
  float pdf_li(const LightSampleContext& ctx, const Vec3&, const Point3& p, const Normal3&) const {
    return area_to_solid_angle_pdf(1 / area, ctx.p, p, emitting_normal(p));
  }
  float power() const { return uniform_emitter_power(radiance, area, two_sided); }
  // The whole sphere's estimate times the fraction of its area kept.
  float importance(const LightSampleContext& ctx) const {
    return sphere_irradiance_estimate(center, radius, radiance.luminance(), ctx) * area /
           (4 * kPi * radius * radius);
  }
};

// A disk (an ellipse under a non-uniform to_world): center + axis_u x + axis_v y over the unit disk,
// sampled uniformly by area (the concentric map is area-preserving up to the constant Jacobian).
struct DiskLight {
  static constexpr LightFlags flags = LightFlags::Area;
  Point3 center;
  Vec3 axis_u, axis_v;  // the images of the unit disk's x and y axes
  Normal3 n;            // unit, the emitting side
  float area;
  RGB radiance;
  bool two_sided;
  EmissionTexture emission_texture;  // textured emitters

  // A uniform point, and the radiance it emits.
  Point3 point(Vec2 u, RGB& emitted) const {
    Vec2 d = square_to_concentric_disk(u);
    Point3 p = center + axis_u * d.x + axis_v * d.y;
    emitted = emission_texture.texture < 0 ? radiance : emission_texture(radiance, disk_uv(d.x, d.y), p);
    return p;
  }
  LightSample sample_li(const LightSampleContext& ctx, Vec2 u) const {
    RGB emitted;
    Point3 p = point(u, emitted);
    return flat_light_sample(p, n, area, emitted, two_sided, ctx);
  }
  LightEmission sample_le(Vec2 u_pos, Vec2 u_dir, const SceneSphere&) const {
    float pdf_dir;
    Vec3 w = sample_cosine_emission(n, two_sided, u_dir, pdf_dir);
    RGB emitted;
    Point3 p = point(u_pos, emitted);
    return {emitted, p, w, n, 1 / area, pdf_dir};
  }
  EmissionPdf pdf_le(const Point3&, const Normal3&, const Vec3& w, const SceneSphere&) const { return flat_light_pdf_le(*this, w); }
  float pdf_li(const LightSampleContext& ctx, const Vec3&, const Point3& p, const Normal3&) const { return flat_light_pdf_li(*this, ctx, p); }
  float power() const { return uniform_emitter_power(radiance, area, two_sided); }
  float importance(const LightSampleContext& ctx) const {
    return flat_light_importance(center, n, area, radiance, two_sided, ctx);
  }
};

// An open circular tube: base + radius (cos(phi) axis_u + sin(phi) axis_v) + z axis, phi in
// [0, phi_max) (2 pi unless cut: pbrt-v4's partial cylinders), z in [0, 1], with axis_u, axis_v
// orthonormal and axis perpendicular to both (a cylinder, not an elliptic or oblique tube: only then
// is (phi, z) proportional to area). Sampled uniformly by area as Mitsuba does (z from u.x, phi from u.y).
struct CylinderLight {
  static constexpr LightFlags flags = LightFlags::Area;
  Point3 base;
  Vec3 axis_u, axis_v;  // unit, perpendicular to each other and to axis
  Vec3 axis;            // from the base circle's centre to the top circle's
  float radius;
  float area;
  RGB radiance;
  bool two_sided;
  bool emits_inward;  // flipped normals: the emitting side faces the axis
  EmissionTexture emission_texture;  // textured emitters
  float phi_max = 2 * kPi;  // area = phi_max radius |axis|

  Normal3 emitting_normal(const Point3& p) const {
    Vec3 d = p - base;
    Vec3 radial = axis_u * dot(d, axis_u) + axis_v * dot(d, axis_v);
    float len = length(radial);
    Normal3 out = len > 0 ? radial / len : axis_u;
    return emits_inward ? -out : out;
  }
  // A uniform point, its emitting normal and the radiance it emits.
  Point3 point(Vec2 u, Normal3& n, RGB& emitted) const {
    float phi = phi_max * u.y, c = std::cos(phi), s = std::sin(phi);
    Vec3 radial = axis_u * c + axis_v * s;
    n = emits_inward ? -radial : radial;
    Point3 p = base + radial * radius + axis * u.x;
    emitted = emission_texture.texture < 0 ? radiance : emission_texture(radiance, cylinder_uv(c, s, u.x, phi_max), p);
    return p;
  }
  LightSample sample_li(const LightSampleContext& ctx, Vec2 u) const {
    Normal3 n;
    RGB emitted;
    Point3 p = point(u, n, emitted);
    return flat_light_sample(p, n, area, emitted, two_sided, ctx);
  }
  LightEmission sample_le(Vec2 u_pos, Vec2 u_dir, const SceneSphere&) const {
    Normal3 n;
    RGB emitted;
    Point3 p = point(u_pos, n, emitted);
    float pdf_dir;
    Vec3 w = sample_cosine_emission(n, two_sided, u_dir, pdf_dir);
    return {emitted, p, w, n, 1 / area, pdf_dir};
  }
  EmissionPdf pdf_le(const Point3& p, const Normal3&, const Vec3& w, const SceneSphere&) const {
    return {1 / area, cosine_emission_pdf(emitting_normal(p), two_sided, w)};
  }
  float pdf_li(const LightSampleContext& ctx, const Vec3&, const Point3& p, const Normal3&) const {
    return area_to_solid_angle_pdf(1 / area, ctx.p, p, emitting_normal(p));
  }
  float power() const { return uniform_emitter_power(radiance, area, two_sided); }
  // Estimated irradiance at ctx: L times the tube's projected area seen from its centre over d^2.
  float importance(const LightSampleContext& ctx) const {
    Point3 c = base + axis * 0.5f;
    Vec3 d = c - ctx.p;
    float d2 = std::max(length_squared(d), 1e-12f);
    Vec3 w = d / std::sqrt(d2);
    float h = length(axis);
    float along = h > 0 ? std::abs(dot(w, axis)) / h : 0.0f;
    float projected = 2 * radius * h * safe_sqrt(1 - along * along) + kPi * radius * radius * along;
    float cos_p = ctx.n == Normal3(0.0f) ? 1.0f : std::max(0.0f, dot(ctx.n, w));
    return radiance.luminance() * std::min(kPi, projected * cos_p / d2);
  }
};

}  // namespace candela
