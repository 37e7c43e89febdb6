#pragma once
// Materials turn into BSDFs at each hit: a material's parameters may be textures, so the BSDF is
// built from the description with every input evaluated at the hit's (uv, p). Materials without
// textures build their BSDF once, up front (but hair, whose BSDF depends on where across the fibre
// the hit lies: its v).
//
// Wrappers (one-sided, mask, blend: materials/surface_bsdf.h) resolve into a SurfaceBsdf, a mixture
// of at most SurfaceBsdf::kMaxComponents BSDFs; normal and bump maps tilt the shading frame of the
// hit for the whole surface point (shading()). Mitsuba 3's frames: the map's normal n is in the
// hit's shading frame (s, t, n) (normal map: n = 2 rgb - 1; bump map: n = cross(dp/du + n dh/du,
// dp/dv + n dh/dv) of the surface displaced by scale * height, the tangents' normal parts replaced
// by the height's gradient, n turned to the geometric normal's side), and the tilted frame's first
// axis is the old s made orthogonal to it (Mitsuba's PerturbedBSDF). Nested maps apply outermost
// first. One frame per point: a blend whose two sides have different normal or bump maps is a
// SceneError, as is a material (with its wrappers) of more than kMaxComponents BSDFs.
#include <memory>
#include <optional>
#include <vector>

#include "candela/base/error.h"
#include "candela/geometry/surface_hit.h"
#include "candela/materials/bsdf.h"
#include "candela/materials/surface_bsdf.h"
#include "candela/math/frame.h"
#include "candela/description/scene_desc.h"
#include "candela/textures/texture.h"

namespace candela {

// The BSDF at a hit and the shading frame it works in (normal and bump mapped).
struct Shading {
  SurfaceBsdf bsdf;
  Frame frame;
};

class MaterialTable {
 public:
  MaterialTable() = default;
  // `textures` must outlive the table. A default diffuse 0.5 material is appended at index
  // descs.size() (for shapes that name none).
  MaterialTable(const std::vector<MaterialDesc>& descs, const TextureSet& textures, const EntryPlace& place_of = {});

  // Throws SceneError for wrappers that cannot be resolved (see above). A two-sided material gives
  // its front's BSDF here (use shading() to see the side the viewer is on).
  SurfaceBsdf bsdf(uint32_t material, const TextureEvalContext& ctx) const {
    if (const auto* sides = std::get_if<TwoSidedMaterial>(&entries_[material].desc)) material = uint32_t(sides->front);
    return one_side_bsdf(material, ctx);
  }
  // The BSDF and the shading frame at a hit (its ns, ng, dpdu and dpdv; ctx is where the hit's
  // textures are looked up) for light leaving towards the world direction wo.
  Shading shading(uint32_t material, const TextureEvalContext& ctx, const SurfaceHit& hit, const Vec3& wo) const;
  // Whether the material tilts shading normals (normal or bump maps).
  bool perturbs_normals(uint32_t material) const { return !entries_[material].perturbations.empty(); }
  // An interface material has no surface: rays pass through it (pbrt-v4's "interface").
  bool is_interface(uint32_t material) const { return entries_[material].interface; }
  // Whether some light may pass the surface straight on (interfaces, masks, thin sheets): where
  // shadow rays may see through it (SurfaceBsdf::pass_through says how much).
  bool may_pass_through(uint32_t material) const { return entries_[material].may_pass_through; }
  // Whether the BSDF is black whatever the hit (pure emitters, light blockers): paths end there.
  size_t size() const { return entries_.size(); }
  uint32_t default_material() const { return uint32_t(entries_.size() - 1); }

 private:
  struct Entry {
    MaterialDesc desc;
    std::optional<SurfaceBsdf> constant;
    bool interface = false;
    bool may_pass_through = false;
    std::vector<int> perturbations;  // the normal / bump map materials that apply, outermost first
    std::shared_ptr<const RoughCoatTable> coat_table;  // for a tabulated coated diffuse
    bool stochastic = false;  // it or a material it wraps builds a layered BSDF (seeded per hit)
  };
  // The BSDF of a material that is not two-sided: cached when constant.
  SurfaceBsdf one_side_bsdf(uint32_t material, const TextureEvalContext& ctx) const {
    const Entry& e = entries_[material];
    return e.constant ? *e.constant : resolve(material, ctx);
  }
  // The BSDF of a material that is not a wrapper.
  Bsdf build(const Entry& entry, const TextureEvalContext& ctx) const;
  // The mixture a material and its wrappers make.
  SurfaceBsdf resolve(uint32_t material, const TextureEvalContext& ctx) const;
  void collect(int material, float weight, bool one_sided, const TextureEvalContext& ctx, SurfaceBsdf& out) const;
  // Tilts `frame` by the normal or bump map material `map`.
  // Tilts `frame` by one normal or bump map as seen from wo; says whether the map asks for the
  // terminator shadowing (surface_bsdf.h).
  bool perturb(int map, const TextureEvalContext& ctx, const SurfaceHit& hit, const Vec3& wo, Frame& frame) const;

  const TextureSet* textures_ = nullptr;
  std::vector<Entry> entries_;
};

}  // namespace candela
