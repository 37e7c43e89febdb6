#pragma once
// What a surface point scatters with: the BSDF of a material after its wrappers (one-sided, mask,
// blend; scene/description.h) are resolved at the hit. Wrappers nest freely, and every nesting is a
// mixture of at most kMaxComponents BSDFs of the closed list `Bsdf` plus a "null" part:
//   f(wo, wi) = sum_k w_k side_k(wo, wi) f_k(wo, wi)  +  null delta(wi = -wo)
// where side_k is 1, or for one-sided components 1 only when wo and wi are both above the shading
// frame's surface (Mitsuba's BSDFs without "twosided", which test cos theta of both directions), and
// the weights w_k and null sum to 1:
//   mask(opacity o, m)      null += w (1 - o), m gets w o   (Mitsuba's "mask": the surface is absent
//                           with probability 1 - o, a forward delta transmission of weight 1)
//   blend(t, m0, m1)        m0 gets w (1 - t), m1 gets w t (Mitsuba's "blendbsdf")
//   one-sided(m)            m's components become one-sided
// Normal and bump maps do not change the mixture: they tilt the shading frame (material.h), and
// `check_side` then keeps Mitsuba's rule that a direction wi on different sides of the tilted and
// the original shading normal scatters nothing.
//
// Sampling follows the BSDF contract (bsdf.h): u_lobe is divided into the non-delta parts of every
// component (in order), then their delta parts, then the null part, so that non-delta lobes are
// chosen exactly when u_lobe < non_delta_probability(wo). A non-delta direction drawn from component
// k gets the weight and density of the whole mixture, f cos / sum_j w_j pdf_j (so light sampling and
// BSDF sampling use the same densities for MIS); a delta one keeps component k's weight with the
// discrete probability w_k p_k. The null part continues the path straight on (wi = -wo) as a delta
// event with weight 1, so it counts as a scattering event towards max_depth, and shadow rays (which
// stop at every surface) never see through it: as Mitsuba's path tracer counts a mask's null
// interactions. (Mitsuba's mask and blendbsdf report the sampled component's own density from
// sample() but the mixture's from pdf(), so their MIS weights do not sum to one where 0 < o < 1 or
// 0 < t < 1; here both are the mixture's.)
//
// Dispatch is static: a plain material (one two-sided component, no null part, no tilt) takes one
// branch and then the usual single std::visit.
#include <array>
#include <type_traits>
#include <optional>

#include "candela/materials/bsdf.h"

namespace candela {

struct SurfaceBsdf {
  static constexpr int kMaxComponents = 4;
  struct Component {
    Bsdf bsdf = BlackBsdf{};
    float weight = 1;
    bool one_sided = false;
  };
  // Storage for the components: only the first `count` are ever constructed, read or copied, so a
  // plain BSDF (one component) costs one BSDF to build and to copy, not kMaxComponents.
  class Components {
   public:
    Components() {}  // NOLINT: deliberately leaves the slots unconstructed
    Component& operator[](size_t k) { return slots_[k].component; }
    const Component& operator[](size_t k) const { return slots_[k].component; }

   private:
    union Slot {
      Slot() {}  // NOLINT: unconstructed until written
      Component component;
    };
    Slot slots_[kMaxComponents];
  };
  static_assert(std::is_trivially_copyable_v<Component> && std::is_trivially_destructible_v<Component>,
                "components are written into raw slots and copied by assignment");
  Components components;
  int count = 0;
  float null_weight = 0;
  // Normal or bump mapped: the original shading normal in the (tilted) local frame.
  bool check_side = false;
  Vec3 original_normal{0, 0, 1};
  // Mitsuba's shadowing of the tilt (Conty Estevez et al., "A Microfacet-Based Shadowing Function to
  // Solve the Bump Terminator Problem", 2019), on when > 0: alpha^2 = min(tan^2(tilt) / 8, 1), and f
  // is scaled by G(wi) = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta)), theta wi's angle to the original
  // normal. (Only wi, the sampled side, as Mitsuba's bumpmap/normalmap do; densities are unchanged.)
  float terminator_alpha2 = 0;

  SurfaceBsdf() = default;
  SurfaceBsdf(const Bsdf& b) : count(1) { components[0] = {b, 1, false}; }  // NOLINT: a plain BSDF converts implicitly
  SurfaceBsdf(const SurfaceBsdf& o) { *this = o; }
  SurfaceBsdf& operator=(const SurfaceBsdf& o) {
    count = o.count;
    null_weight = o.null_weight;
    check_side = o.check_side;
    original_normal = o.original_normal;
    terminator_alpha2 = o.terminator_alpha2;
    for (int k = 0; k < count; ++k) components[size_t(k)] = o.components[size_t(k)];
    return *this;
  }

  // Appends a component (the caller keeps count <= kMaxComponents).
  void add(const Bsdf& b, float weight, bool one_sided) {
    components[size_t(count)] = {b, weight, one_sided};
    ++count;
  }
  bool is_plain() const {
    return count == 1 && null_weight == 0 && !components[0].one_sided && !check_side && components[0].weight == 1;
  }

  RGB eval(const Vec3& wo, const Vec3& wi) const {
    if (is_plain()) return bsdf_eval(components[0].bsdf, wo, wi);
    RGB f(0.0f);
    if (!side_ok(wi)) return f;
    for (int k = 0; k < count; ++k) {
      const Component& c = components[size_t(k)];
      if (c.weight > 0 && faces(c, wo, wi)) f += bsdf_eval(c.bsdf, wo, wi) * c.weight;
    }
    return f * terminator(wi);
  }

  // The adjoint f*(wo, wi) (paths carrying importance; bsdf.h's bsdf_eval_adjoint per component).
  RGB eval_adjoint(const Vec3& wo, const Vec3& wi) const {
    if (is_plain()) return bsdf_eval_adjoint(components[0].bsdf, wo, wi);
    RGB f(0.0f);
    if (!side_ok(wi)) return f;
    for (int k = 0; k < count; ++k) {
      const Component& c = components[size_t(k)];
      if (c.weight > 0 && faces(c, wo, wi)) f += bsdf_eval_adjoint(c.bsdf, wo, wi) * c.weight;
    }
    return f * terminator(wi);
  }

  float pdf(const Vec3& wo, const Vec3& wi) const {
    if (is_plain()) return bsdf_pdf(components[0].bsdf, wo, wi);
    if (!side_ok(wi)) return 0;
    float p = 0;
    for (int k = 0; k < count; ++k) {
      const Component& c = components[size_t(k)];
      if (c.weight > 0 && faces(c, wo, wi)) p += c.weight * bsdf_pdf(c.bsdf, wo, wi);
    }
    return p / total();
  }

  std::optional<BsdfSample> sample(const Vec3& wo, float u_lobe, Vec2 u) const {
    if (is_plain()) return bsdf_sample(components[0].bsdf, wo, u_lobe, u);
    const float t = total();
    float x = u_lobe * t;
    // The non-delta parts of all components, then their delta parts, then the null part.
    for (int pass = 0; pass < 2; ++pass) {
      for (int k = 0; k < count; ++k) {
        const Component& c = components[size_t(k)];
        if (!(c.weight > 0)) continue;
        float nd = component_non_delta(c, wo);
        float share = c.weight * (pass == 0 ? nd : 1 - nd);
        if (x >= share) {
          x -= share;
          continue;
        }
        // The component's own u_lobe, within its non-delta or its delta range.
        float u_c = std::min((pass == 0 ? 0.0f : nd) + x / c.weight, 0x1.fffffep-1f);
        return sample_component(k, wo, u_c, u);
      }
    }
    if (!(null_weight > 0)) return std::nullopt;
    return BsdfSample{-wo, RGB(1.0f), null_weight / t, true, 1, true};
  }

  // What passes straight through towards -wo without scattering (the null part, and the
  // transmission of thin sheets): the factor a shadow ray that crosses the surface carries, where
  // an integrator lets shadow rays see through (Mitsuba's eval_null_transmission).
  RGB pass_through(const Vec3& wo) const {
    RGB sum(null_weight);
    for (int k = 0; k < count; ++k) {
      const Component& c = components[size_t(k)];
      if (const auto* d = std::get_if<DielectricBsdf>(&c.bsdf); d && d->thin && c.weight > 0 && !c.one_sided)
        sum += d->thin_transmission(wo.z) * c.weight;
    }
    return sum / total();
  }

  bool has_non_delta() const {
    for (int k = 0; k < count; ++k)
      if (components[size_t(k)].weight > 0 && bsdf_has_non_delta(components[size_t(k)].bsdf)) return true;
    return false;
  }
  bool has_non_delta_transmission() const {
    for (int k = 0; k < count; ++k) {
      const Component& c = components[size_t(k)];
      if (c.weight > 0 && !c.one_sided && bsdf_has_non_delta_transmission(c.bsdf)) return true;
    }
    return false;
  }
  float non_delta_probability(const Vec3& wo) const {
    if (is_plain()) return bsdf_non_delta_probability(components[0].bsdf, wo);
    float p = 0;
    for (int k = 0; k < count; ++k) {
      const Component& c = components[size_t(k)];
      if (c.weight > 0) p += c.weight * component_non_delta(c, wo);
    }
    return p / total();
  }
  // Whether every component is reciprocal but for refraction's scale (bsdf_flags.h): else the
  // adjoint is not eval() times a scale, and importance-carrying samples are weighted by eval_adjoint().
  bool is_reciprocal() const {
    for (int k = 0; k < count; ++k)
      if (components[size_t(k)].weight > 0 && has(bsdf_flags(components[size_t(k)].bsdf), BsdfFlags::NonReciprocal))
        return false;
    return true;
  }
  // Scatters nothing whatever the directions (paths end here).
  bool is_black() const {
    if (null_weight > 0) return false;
    for (int k = 0; k < count; ++k)
      if (components[size_t(k)].weight > 0 && !bsdf_is_black(components[size_t(k)].bsdf)) return false;
    return true;
  }

 private:
  float total() const {
    float t = null_weight;
    for (int k = 0; k < count; ++k) t += components[size_t(k)].weight;
    return t > 0 ? t : 1.0f;
  }
  static bool faces(const Component& c, const Vec3& wo, const Vec3& wi) {
    return !c.one_sided || (wo.z > 0 && wi.z > 0);
  }
  bool side_ok(const Vec3& wi) const { return !check_side || dot(wi, original_normal) * wi.z > 0; }
  float terminator(const Vec3& wi) const {
    if (!(terminator_alpha2 > 0)) return 1;
    float cos2 = sqr(dot(wi, original_normal)), sin2 = std::max(0.0f, 1 - cos2);
    if (!(cos2 > 0)) return 0;
    return 2 / (1 + std::sqrt(1 + terminator_alpha2 * sin2 / cos2));
  }
  // A one-sided component seen from the back scatters nothing: all of it counts as its
  // (empty) non-delta part.
  static float component_non_delta(const Component& c, const Vec3& wo) {
    if (c.one_sided && !(wo.z > 0)) return 1;
    return bsdf_non_delta_probability(c.bsdf, wo);
  }

  std::optional<BsdfSample> sample_component(int k, const Vec3& wo, float u_c, Vec2 u) const {
    const Component& c = components[size_t(k)];
    if (c.one_sided && !(wo.z > 0)) return std::nullopt;
    auto bs = bsdf_sample(c.bsdf, wo, u_c, u);
    if (!bs || !faces(c, wo, bs->wi) || !side_ok(bs->wi)) return std::nullopt;
    const float t = total();
    if (bs->is_delta || count == 1) {
      // The component's weight stands: its share of f and of the probability is the same w_k / t.
      bs->pdf *= c.weight / t;
      bs->weight *= terminator(bs->wi);
      return bs;
    }
    // A non-delta direction: the mixture's weight and density (all non-delta parts could have made it).
    float p = pdf(wo, bs->wi);
    if (!(p > 0)) return std::nullopt;
    bs->weight = eval(wo, bs->wi) * (std::abs(bs->wi.z) / p);
    bs->pdf = p;
    return bs;
  }
};

// The contract's free functions, for the surface BSDF.
inline RGB bsdf_eval(const SurfaceBsdf& b, const Vec3& wo, const Vec3& wi) { return b.eval(wo, wi); }
inline float bsdf_pdf(const SurfaceBsdf& b, const Vec3& wo, const Vec3& wi) { return b.pdf(wo, wi); }
inline std::optional<BsdfSample> bsdf_sample(const SurfaceBsdf& b, const Vec3& wo, float u_lobe, Vec2 u) {
  return b.sample(wo, u_lobe, u);
}
inline bool bsdf_has_non_delta(const SurfaceBsdf& b) { return b.has_non_delta(); }
inline bool bsdf_has_non_delta_transmission(const SurfaceBsdf& b) { return b.has_non_delta_transmission(); }
inline float bsdf_non_delta_probability(const SurfaceBsdf& b, const Vec3& wo) { return b.non_delta_probability(wo); }
inline bool bsdf_is_black(const SurfaceBsdf& b) { return b.is_black(); }
inline RGB bsdf_eval_adjoint(const SurfaceBsdf& b, const Vec3& wo, const Vec3& wi) { return b.eval_adjoint(wo, wi); }

}  // namespace candela
