#pragma once
// Ideal (delta) BSDFs: a mirror and the absorbing black BSDF, with the Fresnel and refraction helpers
// that the dielectric BSDFs (dielectric.h) share.
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
  static constexpr BsdfFlags flags = BsdfFlags::Reflection | BsdfFlags::Delta;
  RGB reflectance{1.0f};
  RGB eval(const Vec3&, const Vec3&) const { return RGB(0.0f); }
  float pdf(const Vec3&, const Vec3&) const { return 0; }
  std::optional<BsdfSample> sample(const Vec3& wo, float, Vec2) const {
    return BsdfSample{reflect_local(wo), reflectance, 1, true, 1};
  }
  bool has_non_delta() const { return false; }
  bool has_non_delta_transmission() const { return false; }
  float non_delta_probability(const Vec3&) const { return 0; }
};

struct BlackBsdf {
  static constexpr BsdfFlags flags = BsdfFlags::None;
  RGB eval(const Vec3&, const Vec3&) const { return RGB(0.0f); }
  float pdf(const Vec3&, const Vec3&) const { return 0; }
  std::optional<BsdfSample> sample(const Vec3&, float, Vec2) const { return std::nullopt; }
  bool has_non_delta() const { return false; }
  bool has_non_delta_transmission() const { return false; }
  float non_delta_probability(const Vec3&) const { return 0; }
};

}  // namespace candela
