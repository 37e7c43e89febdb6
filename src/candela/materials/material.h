#pragma once
// Materials turn into BSDFs at each hit: a material's parameters may be textures, so the BSDF is
// built from the description with every input evaluated at the hit's (uv, p). Materials without
// textures build their BSDF once, up front.
#include <optional>
#include <vector>

#include "candela/materials/bsdf.h"
#include "candela/scene/description.h"
#include "candela/textures/texture.h"

namespace candela {

class MaterialTable {
 public:
  MaterialTable() = default;
  // `textures` must outlive the table. A default diffuse 0.5 material is appended at index
  // descs.size() (for shapes that name none).
  MaterialTable(const std::vector<MaterialDesc>& descs, const TextureSet& textures);

  Bsdf bsdf(uint32_t material, const TextureEvalContext& ctx) const {
    const Entry& e = entries_[material];
    return e.constant ? *e.constant : build(e.desc, ctx);
  }
  // An interface material has no surface: rays pass through it (pbrt-v4's "interface").
  bool is_interface(uint32_t material) const { return entries_[material].interface; }
  // Whether the BSDF is black whatever the hit (pure emitters, light blockers): paths end there.
  size_t size() const { return entries_.size(); }
  uint32_t default_material() const { return uint32_t(entries_.size() - 1); }

 private:
  struct Entry {
    MaterialDesc desc;
    std::optional<Bsdf> constant;
    bool interface = false;
  };
  Bsdf build(const MaterialDesc& desc, const TextureEvalContext& ctx) const;

  const TextureSet* textures_ = nullptr;
  std::vector<Entry> entries_;
};

}  // namespace candela
