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
  const RGB base(0.8f, 0.6f, 0.4f);
  return {
      {"diffuse and specular", {.base_color = base, .roughness = 0.6f}},
      {"metallic", {.base_color = base, .roughness = 0.4f, .metallic = 1}},
      {"rough half metal", {.base_color = base, .roughness = 0.95f, .metallic = 0.5f}},
      {"smooth", {.base_color = base, .roughness = 0.25f, .metallic = 0.8f}},
      {"anisotropic", {.base_color = base, .roughness = 0.5f, .anisotropic = 0.8f, .metallic = 0.6f}},
      {"clearcoat and sheen",
       {.base_color = base, .roughness = 0.5f, .sheen = 1, .sheen_tint = 0.5f, .clearcoat = 1,
        .clearcoat_gloss = 0.3f}},
      {"spec_trans",
       {.base_color = base, .roughness = 0.45f, .spec_trans = 0.8f, .clearcoat = 0.5f, .clearcoat_gloss = 0.1f,
        .eta = 1.5f}},
      {"anisotropic spec_trans 1",
       {.base_color = base, .roughness = 0.45f, .anisotropic = 0.7f, .spec_trans = 1, .clearcoat = 0.5f,
        .clearcoat_gloss = 0.1f, .eta = 1.33f}},
  };
}

// The thin model's: both transmissions, a sheen and a tint.
inline PrincipledParams principled_thin_params() {
  return {.spec_tint = 0.5f, .spec_trans = 0.5f, .sheen = 0.3f, .diff_trans = 1};
}

}  // namespace candela::testing
