#pragma once
// Parameter settings of the principled BSDF that the tests share: the sampling tests (chi-square,
// principled_test.cpp) and the BSDF contract (bsdf_contract_test.cpp) run over the same list.
#include <string>
#include <vector>

#include "candela/materials/principled.h"

namespace candela::testing {

struct PrincipledCase {
  std::string name;
  PrincipledParams params;
};

inline std::vector<PrincipledCase> principled_sampling_cases() {
  std::vector<PrincipledCase> cases;
  PrincipledParams p;
  p.base_color = RGB(0.8f, 0.6f, 0.4f);
  p.roughness = 0.6f;
  cases.push_back({"diffuse and specular", p});
  PrincipledParams metal = p;
  metal.metallic = 1;
  metal.roughness = 0.4f;
  cases.push_back({"metallic", metal});
  PrincipledParams rough = p;
  rough.roughness = 0.95f;
  rough.metallic = 0.5f;
  cases.push_back({"rough half metal", rough});
  PrincipledParams smooth = p;
  smooth.roughness = 0.25f;
  smooth.metallic = 0.8f;
  cases.push_back({"smooth", smooth});
  PrincipledParams aniso = p;
  aniso.roughness = 0.5f;
  aniso.anisotropic = 0.8f;
  aniso.metallic = 0.6f;
  cases.push_back({"anisotropic", aniso});
  PrincipledParams coat = p;
  coat.roughness = 0.5f;
  coat.clearcoat = 1;
  coat.clearcoat_gloss = 0.3f;
  coat.sheen = 1;
  coat.sheen_tint = 0.5f;
  cases.push_back({"clearcoat and sheen", coat});
  PrincipledParams glass = p;
  glass.roughness = 0.45f;
  glass.spec_trans = 0.8f;
  glass.eta = 1.5f;
  glass.clearcoat = 0.5f;
  glass.clearcoat_gloss = 0.1f;
  cases.push_back({"spec_trans", glass});
  PrincipledParams aniso_glass = glass;
  aniso_glass.anisotropic = 0.7f;
  aniso_glass.spec_trans = 1;
  aniso_glass.eta = 1.33f;
  cases.push_back({"anisotropic spec_trans 1", aniso_glass});
  return cases;
}

// The thin model's: both transmissions, a sheen and a tint.
inline PrincipledParams principled_thin_params() {
  PrincipledParams thin;
  thin.spec_trans = 0.5f;
  thin.diff_trans = 1;
  thin.sheen = 0.3f;
  thin.spec_tint = 0.5f;
  return thin;
}

}  // namespace candela::testing
