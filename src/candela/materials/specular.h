#pragma once
// Ideal (delta) BSDFs: a mirror and a smooth dielectric interface, plus the absorbing black BSDF.
#include <optional>

#include "candela/materials/bsdf_sample.h"

namespace candela {

// Fresnel reflectance of a smooth dielectric for unpolarised light. cos_i is measured on the side
// wi is on; eta = n_inside / n_outside, with "inside" below the normal.
inline float fresnel_dielectric(float cos_i, float eta) {
  cos_i = std::clamp(cos_i, -1.0f, 1.0f);
  if (cos_i < 0) {
    eta = 1 / eta;
    cos_i = -cos_i;
  }
  float sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return 1;  // total internal reflection
  float cos_t = safe_sqrt(1 - sin2_t);
  float r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return (r_parl * r_parl + r_perp * r_perp) / 2;
}

// Refracts w (pointing away from the surface) through the interface with the normal +z.
// Returns false on total internal reflection. eta_rel receives the relative IOR crossed.
inline bool refract_local(const Vec3& w, float eta, Vec3& wt, float& eta_rel) {
  float cos_i = w.z;
  Vec3 n(0, 0, 1);
  if (cos_i < 0) {  // leaving the inside
    eta = 1 / eta;
    cos_i = -cos_i;
    n = -n;
  }
  float sin2_t = std::max(0.0f, 1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return false;
  float cos_t = safe_sqrt(1 - sin2_t);
  wt = -w / eta + n * (cos_i / eta - cos_t);
  eta_rel = eta;
  return true;
}

inline Vec3 reflect_local(const Vec3& w) { return {-w.x, -w.y, w.z}; }

struct MirrorBsdf {
  RGB reflectance{1.0f};
  RGB eval(const Vec3&, const Vec3&) const { return RGB(0.0f); }
  float pdf(const Vec3&, const Vec3&) const { return 0; }
  std::optional<BsdfSample> sample(const Vec3& wo, float, Vec2) const {
    return BsdfSample{reflect_local(wo), reflectance, 1, true, 1};
  }
  bool has_non_delta() const { return false; }
  float non_delta_probability() const { return 0; }
};

// Glass: reflects with the Fresnel probability F, else refracts. Radiance is scaled by 1/eta^2 on
// refraction (radiance compresses into the smaller solid angle in the denser medium).
struct GlassBsdf {
  float ior = 1.5f;
  RGB reflectance{1.0f};
  RGB transmittance{1.0f};
  RGB eval(const Vec3&, const Vec3&) const { return RGB(0.0f); }
  float pdf(const Vec3&, const Vec3&) const { return 0; }
  std::optional<BsdfSample> sample(const Vec3& wo, float u_lobe, Vec2) const {
    float f = fresnel_dielectric(wo.z, ior);
    if (u_lobe < f) return BsdfSample{reflect_local(wo), reflectance, f, true, 1};
    Vec3 wt;
    float eta_rel;
    if (!refract_local(wo, ior, wt, eta_rel)) return BsdfSample{reflect_local(wo), reflectance, 1, true, 1};
    return BsdfSample{wt, transmittance / (eta_rel * eta_rel), 1 - f, true, eta_rel};
  }
  bool has_non_delta() const { return false; }
  float non_delta_probability() const { return 0; }
};

struct BlackBsdf {
  RGB eval(const Vec3&, const Vec3&) const { return RGB(0.0f); }
  float pdf(const Vec3&, const Vec3&) const { return 0; }
  std::optional<BsdfSample> sample(const Vec3&, float, Vec2) const { return std::nullopt; }
  bool has_non_delta() const { return false; }
  float non_delta_probability() const { return 0; }
};

}  // namespace candela
