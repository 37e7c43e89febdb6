// The BSDF contract (bsdf.h), checked for every BSDF of the closed list `Bsdf` under several
// parameter settings each: sample()'s weight is eval() |cos| / pdf() and its density is pdf() for
// the non-delta lobes; non-delta lobes are picked exactly when u_lobe < non_delta_probability(wo);
// and each type behaves as its flags (bsdf_flags.h) say. The list is built per alternative of the
// variant (cases_of<B>), so a BSDF added to `Bsdf` without cases here does not compile.
// (Chi-square tests of sample() against pdf() and the analytic checks stay beside each BSDF.)
// Stochastic BSDFs (BsdfFlags::Stochastic: the layered BSDFs, whose eval() and pdf() are random-walk
// estimates) cannot match weight and eval sample by sample: for them the first check is
// statistical (testing/stochastic_bsdf.h), each sample's pdf is pdf() exactly, and the others
// hold as they are (layered_test.cpp checks the rest).
#include <gtest/gtest.h>

#include <cctype>
#include <functional>
#include <string>
#include <variant>
#include <vector>

#include "candela/base/overloaded.h"
#include "candela/materials/bsdf.h"
#include "candela/materials/rough_coat.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/testing/bsdf_helpers.h"
#include "candela/testing/principled_cases.h"
#include "candela/testing/stochastic_bsdf.h"

namespace candela {
namespace {

using testing::below;
using testing::direction;
using testing::random_direction;

// One outgoing direction and how many of `samples` draws must be non-delta samples there.
struct Outgoing {
  Vec3 wo;
  int min_checked = 0;
};

struct ContractCase {
  std::string name;
  std::function<Bsdf()> make;  // built when the test runs (some need tables)
  std::vector<Outgoing> wos;
  int samples = 20000;
  // Relative tolerance of weight and density: 1e-4, or 2e-3 where the microfacet masking is a
  // rational approximation (Beckmann) or the density is assembled from several lobes.
  float tolerance = 2e-3f;
  uint64_t seed = 0;        // set by all_cases(): the case's position in the list
  size_t alternative = 0;   // set by all_cases(): the index in `Bsdf` of the B of cases_of<B>
};

std::vector<Outgoing> each(std::initializer_list<Vec3> wos, int min_checked) {
  std::vector<Outgoing> out;
  for (const Vec3& wo : wos) out.push_back({wo, min_checked});
  return out;
}
std::string tag(float v) {
  std::string s = std::to_string(v);
  s.erase(s.find_last_not_of('0') + 1);
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

// The settings of each BSDF. The primary template is for a BSDF without any: it does not compile.
template <typename B>
std::vector<ContractCase> cases_of() {
  static_assert(always_false<B>, "every BSDF of the closed list needs its cases in the contract test");
  return {};
}

template <>
std::vector<ContractCase> cases_of<DiffuseBsdf>() {
  auto wos = each({direction(0), direction(45), direction(85), below(direction(40))}, 19000);
  return {{"diffuse", [] { return Bsdf(DiffuseBsdf{RGB(0.6f, 0.5f, 0.4f)}); }, wos, 20000, 1e-4f},
          {"diffuse black", [] { return Bsdf(DiffuseBsdf{RGB(0.0f)}); }, wos, 20000, 1e-4f}};
}

template <>
std::vector<ContractCase> cases_of<PhongBsdf>() {
  auto phong = [](float d, float s, float t, float exponent) {
    return [=] {
      PhongBsdf p;
      p.diffuse = RGB(0.6f, 0.5f, 0.4f);
      p.specular = RGB(0.9f);
      p.exponent = exponent;
      p.d = d;
      p.s = s;
      p.t = t;
      return Bsdf(p);
    };
  };
  return {{"phong mixture", phong(0.5f, 0.3f, 0.1f, 15), each({direction(35)}, 7000), 10000, 1e-4f},
          {"phong narrow lobe", phong(0, 1, 0, 200), each({direction(0), direction(60)}, 9000), 10000, 1e-4f},
          {"phong diffuse", phong(1, 0, 0, 32), each({direction(20), below(direction(50))}, 9000), 10000, 1e-4f}};
}

template <>
std::vector<ContractCase> cases_of<MirrorBsdf>() {
  auto wos = each({direction(0), direction(60), below(direction(85))}, 0);
  return {{"mirror", [] { return Bsdf(MirrorBsdf{RGB(0.9f)}); }, wos, 2000},
          {"mirror tinted", [] { return Bsdf(MirrorBsdf{RGB(0.2f, 0.5f, 0.8f)}); }, wos, 2000}};
}

template <>
std::vector<ContractCase> cases_of<BlackBsdf>() {
  return {{"black", [] { return Bsdf(BlackBsdf{}); }, each({direction(0), below(direction(60))}, 0), 2000}};
}

template <>
std::vector<ContractCase> cases_of<DielectricBsdf>() {
  std::vector<ContractCase> cases;
  for (float alpha : {0.05f, 0.3f, 0.8f}) {
    cases.push_back({"dielectric ggx " + tag(alpha),
                     [=] {
                       return Bsdf(DielectricBsdf{1.5f, RGB(0.9f, 0.8f, 0.7f), RGB(0.6f, 0.7f, 0.8f),
                                                  TrowbridgeReitz(alpha, alpha)});
                     },
                     each({direction(0), direction(45), direction(85), below(direction(20)), below(direction(60))},
                          8000)});
    cases.push_back({"dielectric beckmann " + tag(alpha),
                     [=] { return Bsdf(DielectricBsdf{1.5f, RGB(1.0f), RGB(1.0f), Beckmann(alpha, alpha)}); },
                     each({direction(0), direction(45), direction(85), below(direction(60))}, 8000)});
  }
  cases.push_back({"dielectric anisotropic",
                   [] { return Bsdf(DielectricBsdf{1.33f, RGB(1.0f), RGB(1.0f), TrowbridgeReitz(0.4f, 0.1f)}); },
                   each({direction(30), below(direction(50))}, 8000)});
  cases.push_back({"dielectric smooth", [] { return Bsdf(DielectricBsdf{}); },
                   each({direction(30), below(direction(50))}, 0), 2000});
  return cases;
}

ConductorBsdf copper(const Microfacet& distribution) {
  return {RGB(0.200438f, 0.924033f, 1.102212f), RGB(3.912949f, 2.452848f, 2.142188f), RGB(1.0f), distribution};
}

template <>
std::vector<ContractCase> cases_of<ConductorBsdf>() {
  std::vector<ContractCase> cases;
  for (float alpha : {0.05f, 0.3f, 0.8f}) {
    cases.push_back({"conductor ggx " + tag(alpha), [=] { return Bsdf(copper(TrowbridgeReitz(alpha, alpha))); },
                     each({direction(0), direction(45), direction(85)}, 10000)});
    cases.push_back({"conductor ggx anisotropic " + tag(alpha),
                     [=] { return Bsdf(copper(TrowbridgeReitz(alpha, alpha * 0.3f))); },
                     each({below(direction(0)), below(direction(45)), below(direction(85))}, 0)});
    cases.push_back({"conductor beckmann " + tag(alpha),
                     [=] {
                       return Bsdf(ConductorBsdf{RGB(0.2f, 0.9f, 1.1f), RGB(3.9f, 2.4f, 2.1f), RGB(1.0f),
                                                 Beckmann(alpha, alpha)});
                     },
                     each({direction(0), direction(45), direction(85), below(direction(60))}, 10000)});
  }
  cases.push_back({"conductor ggx separable",
                   [] { return Bsdf(copper(TrowbridgeReitz(0.3f, 0.15f, MaskingShadowing::Separable))); },
                   each({direction(30), direction(80)}, 10000)});
  cases.push_back({"conductor smooth", [] { return Bsdf(copper(TrowbridgeReitz(0, 0))); },
                   each({direction(30)}, 0), 2000});
  return cases;
}

template <>
std::vector<ContractCase> cases_of<CoatedDiffuseBsdf>() {
  std::vector<ContractCase> cases;
  for (float alpha : {0.0f, 0.05f, 0.3f, 0.8f})
    for (bool nonlinear : {false, true})
      cases.push_back({"coated ggx " + tag(alpha) + (nonlinear ? " nonlinear" : ""),
                       [=] {
                         return Bsdf(CoatedDiffuseBsdf{RGB(0.7f, 0.5f, 0.3f), RGB(1.0f), 1.5f,
                                                       TrowbridgeReitz(alpha, alpha), nonlinear});
                       },
                       each({direction(0), direction(45), direction(85), below(direction(40))}, 4000)});
  for (float alpha : {0.05f, 0.3f, 0.8f})
    cases.push_back({"coated beckmann " + tag(alpha),
                     [=] { return Bsdf(CoatedDiffuseBsdf{RGB(0.5f), RGB(1.0f), 1.5f, Beckmann(alpha, alpha), false}); },
                     each({direction(0), direction(45), direction(85), below(direction(60))}, 10000)});
  // Mitsuba's roughplastic: the rough coat's tables in the diffuse lobe and the lobe selection.
  auto tabulated = each({direction(0), direction(60), direction(87), below(direction(40))}, 4000);
  cases.push_back({"coated tabulated ggx",
                   [] {
                     static const RoughCoatTable table = make_rough_coat_table(TrowbridgeReitz(0.3f, 0.3f), 1.5f);
                     return Bsdf(CoatedDiffuseBsdf{RGB(0.7f, 0.5f, 0.3f), RGB(1.0f), 1.5f, TrowbridgeReitz(0.3f, 0.3f),
                                                   false, &table});
                   },
                   tabulated});
  cases.push_back({"coated tabulated beckmann",
                   [] {
                     static const RoughCoatTable table = make_rough_coat_table(Beckmann(0.05f, 0.05f), 1.49f);
                     return Bsdf(
                         CoatedDiffuseBsdf{RGB(0.5f), RGB(1.0f), 1.49f, Beckmann(0.05f, 0.05f), false, &table});
                   },
                   tabulated});
  return cases;
}

template <>
std::vector<ContractCase> cases_of<DiffuseTransmissionBsdf>() {
  auto wos = each({direction(40), below(direction(40))}, 19000);
  return {{"diffuse transmission",
           [] { return Bsdf(DiffuseTransmissionBsdf{RGB(0.2f, 0.5f, 0.3f), RGB(0.6f, 0.3f, 0.1f)}); }, wos},
          {"diffuse transmission only",
           [] { return Bsdf(DiffuseTransmissionBsdf{RGB(0.0f), RGB(0.6f, 0.3f, 0.1f)}); }, wos}};
}

template <>
std::vector<ContractCase> cases_of<PrincipledBsdf>() {
  std::vector<ContractCase> cases;
  for (const testing::PrincipledCase& c : testing::principled_sampling_cases()) {
    std::vector<Outgoing> wos = {{direction(40), 2500}};
    if (PrincipledBsdf(c.params).has_non_delta_transmission()) wos.push_back({-direction(30), 2500});
    cases.push_back({"principled " + c.name, [p = c.params] { return Bsdf(PrincipledBsdf(p)); }, wos, 5000, 1e-4f});
  }
  return cases;
}

template <>
std::vector<ContractCase> cases_of<PrincipledThinBsdf>() {
  PrincipledParams thin = testing::principled_thin_params(), diffuse = thin, rough = thin;
  diffuse.spec_trans = 0;
  diffuse.diff_trans = 1.4f;
  rough.roughness = 0.9f;
  rough.anisotropic = 0.6f;
  std::vector<Outgoing> wos = {{direction(50), 2500}, {-direction(20), 2500}};
  auto thin_case = [&](const char* name, const PrincipledParams& p) {
    return ContractCase{name, [p] { return Bsdf(PrincipledThinBsdf(p)); }, wos, 5000, 1e-4f};
  };
  return {thin_case("principled thin", thin), thin_case("principled thin diffuse", diffuse),
          thin_case("principled thin rough anisotropic", rough)};
}

// pbrt-v4's layered BSDFs: a dielectric coat over a diffuse base or a conductor, with a slab
// between (layered.h). Smooth and rough coats and bases, an absorbing and a scattering slab.
LayeredDiffuseBsdf layered_diffuse(const Microfacet& coat, float thickness, RGB albedo = RGB(0.0f), float g = 0) {
  LayeredDiffuseBsdf b;
  b.top = CoatInterface{1.5f, coat};
  b.bottom = DiffuseBsdf{RGB(0.7f, 0.5f, 0.3f)};
  b.thickness = thickness;
  b.albedo = albedo;
  b.g = g;
  b.seed = 3;
  return b;
}
LayeredConductorBsdf layered_gold(const Microfacet& coat, const Microfacet& metal, RGB albedo = RGB(0.0f)) {
  LayeredConductorBsdf b;
  b.top = CoatInterface{1.5f, coat};
  b.bottom = ConductorBsdf{RGB(0.143119f, 0.374957f, 1.442479f) / 1.5f, RGB(3.983160f, 2.385721f, 1.603215f) / 1.5f,
                           RGB(1.0f), metal};
  b.thickness = 0.1f;
  b.albedo = albedo;
  b.g = -0.3f;
  b.seed = 5;
  return b;
}

template <>
std::vector<ContractCase> cases_of<LayeredDiffuseBsdf>() {
  auto wos = each({direction(0), direction(60), below(direction(40))}, 30000);
  return {{"layered diffuse smooth", [] { return Bsdf(layered_diffuse(TrowbridgeReitz(0, 0), 0.05f)); }, wos, 100000},
          {"layered diffuse rough", [] { return Bsdf(layered_diffuse(TrowbridgeReitz(0.3f, 0.3f), 0.05f)); }, wos, 100000},
          {"layered diffuse scattering slab",
           [] { return Bsdf(layered_diffuse(TrowbridgeReitz(0.4f, 0.2f), 0.5f, RGB(0.9f, 0.6f, 0.3f), 0.4f)); }, wos,
           100000},
          {"layered diffuse beckmann", [] { return Bsdf(layered_diffuse(Beckmann(0.3f, 0.3f), 0.0f)); },
           each({direction(30), direction(80)}, 30000), 100000}};
}

template <>
std::vector<ContractCase> cases_of<LayeredConductorBsdf>() {
  auto wos = each({direction(0), direction(60), below(direction(40))}, 30000);
  return {{"layered conductor smooth coat", [] { return Bsdf(layered_gold(TrowbridgeReitz(0, 0), TrowbridgeReitz(0.3f, 0.3f))); },
           wos, 100000},
          {"layered conductor rough", [] { return Bsdf(layered_gold(TrowbridgeReitz(0.3f, 0.3f), TrowbridgeReitz(0.4f, 0.4f))); },
           wos, 100000},
          {"layered conductor smooth metal",
           [] { return Bsdf(layered_gold(TrowbridgeReitz(0.3f, 0.3f), TrowbridgeReitz(0, 0))); }, wos, 100000},
          {"layered conductor scattering slab",
           [] { return Bsdf(layered_gold(TrowbridgeReitz(0.3f, 0.3f), TrowbridgeReitz(0.2f, 0.2f), RGB(0.5f, 0.8f, 0.9f))); },
           wos, 100000},
          {"layered conductor all smooth",
           [] { return Bsdf(layered_gold(TrowbridgeReitz(0, 0), TrowbridgeReitz(0, 0))); },
           each({direction(30), below(direction(70))}, 0), 2000}};
}

// pbrt-v4's hair: fibres along x, hit at several offsets h, smooth and rough, tilted scales or not;
// seen from both sides of the shading normal and along the fibre.
HairBsdf contract_hair(float h, const RGB& sigma_a, float beta_m, float beta_n, float alpha) {
  return HairBsdf(h, 1.55f, sigma_a, beta_m, beta_n, alpha);
}

template <>
std::vector<ContractCase> cases_of<HairBsdf>() {
  auto wos = each({direction(0), direction(50), direction(85, 0), below(direction(30, 120)),
                   normalize(Vec3(0.95f, 0.1f, 0.3f))},
                  9900);
  const RGB brown = hair_sigma_a_from_concentration(1.3f, 0);
  return {{"hair brown", [=] { return Bsdf(contract_hair(0.3f, brown, 0.3f, 0.3f, 2)); }, wos, 10000, 1e-4f},
          {"hair white", [] { return Bsdf(contract_hair(-0.8f, RGB(0.0f), 0.3f, 0.6f, 2)); }, wos, 10000, 1e-4f},
          {"hair narrow tilted", [=] { return Bsdf(contract_hair(0.9f, brown * 0.2f, 0.05f, 0.1f, 8)); }, wos, 10000, 1e-4f},
          {"hair rough from colour",
           [] {
             HairBsdf b(-0.2f, 1.55f, RGB(0.0f), 0.8f, 0.9f, 0);
             b.color = RGB(0.8f, 0.6f, 0.3f);
             b.sigma_a_from_color = true;
             b.resolve_color();
             return Bsdf(b);
           },
           wos, 10000, 1e-4f}};
}

// Every alternative's cases, in the variant's order.
template <typename... Bs>
std::vector<ContractCase> cases_of_every(const std::variant<Bs...>*) {
  std::vector<ContractCase> all;
  size_t alternative = 0;
  (
      [&] {
        for (ContractCase& c : cases_of<Bs>()) {
          c.alternative = alternative;
          all.push_back(std::move(c));
        }
        ++alternative;
      }(),
      ...);
  for (size_t i = 0; i < all.size(); ++i) all[i].seed = i;
  return all;
}
std::vector<ContractCase> all_cases() { return cases_of_every(static_cast<const Bsdf*>(nullptr)); }

class BsdfContract : public ::testing::TestWithParam<ContractCase> {};

// The sample weight is f |cos| / pdf and the sampled density is pdf(), for the non-delta samples.
TEST_P(BsdfContract, SampleWeightIsEvalCosOverPdf) {
  const ContractCase& c = GetParam();
  const Bsdf b = c.make();
  if (has(bsdf_flags(b), BsdfFlags::Stochastic)) {
    // Statistically: per cell of wo's hemisphere, the mean sample weight against the mean of eval()
    // (over seeds) integrated over the cell; and each non-delta sample's pdf is pdf() itself.
    for (const Outgoing& o : c.wos) {
      Rng rng(11, 12);
      int checked = 0, pdf_mismatches = 0;
      for (int i = 0; i < 2000; ++i) {
        auto s = bsdf_sample(b, o.wo, rng.next_float(), {rng.next_float(), rng.next_float()});
        if (!s || s->is_delta) continue;
        ++checked;
        if (!(s->pdf > 0) || s->pdf != bsdf_pdf(b, o.wo, s->wi) || !s->weight.is_finite()) ++pdf_mismatches;
      }
      EXPECT_EQ(pdf_mismatches, 0) << "wo.z " << o.wo.z;
      if (o.min_checked == 0) continue;
      EXPECT_GE(checked, o.min_checked * 2000 / c.samples) << "wo.z " << o.wo.z;
      testing::StochasticWeightTest t = testing::stochastic_weight_test(b, o.wo, c.samples, 2000, c.seed);
      EXPECT_GT(t.p_value, testing::kChiSquareAlpha)
          << "wo.z " << o.wo.z << ": " << t.cells << " cells, worst z " << t.worst_z << "; albedo from samples "
          << t.sample_total << ", from eval " << t.eval_total << " +- " << t.total_standard_error;
      EXPECT_NEAR(t.sample_total, t.eval_total, 4 * t.total_standard_error) << "wo.z " << o.wo.z;
    }
    return;
  }
  int failures = 0;
  for (const Outgoing& o : c.wos) {
    Rng rng(11, 12);
    int checked = 0;
    for (int i = 0; i < c.samples; ++i) {
      auto s = bsdf_sample(b, o.wo, rng.next_float(), {rng.next_float(), rng.next_float()});
      if (!s || s->is_delta) continue;
      ++checked;
      float p = bsdf_pdf(b, o.wo, s->wi);
      RGB expected = bsdf_eval(b, o.wo, s->wi) * (std::abs(s->wi.z) / p);
      bool ok = s->weight.is_finite() && std::abs(s->pdf - p) <= c.tolerance * p;
      for (int k = 0; k < 3; ++k) ok = ok && std::abs(s->weight[k] - expected[k]) <= c.tolerance * (1 + expected[k]);
      if (!ok && ++failures <= 5)
        ADD_FAILURE() << "wo " << o.wo.x << " " << o.wo.y << " " << o.wo.z << ", wi.z " << s->wi.z << ": weight "
                      << s->weight[0] << " " << s->weight[1] << " " << s->weight[2] << ", f cos / pdf " << expected[0]
                      << " " << expected[1] << " " << expected[2] << "; pdf " << s->pdf << ", pdf() " << p;
    }
    EXPECT_GE(checked, o.min_checked) << "wo.z " << o.wo.z;
  }
  EXPECT_EQ(failures, 0);
}

// sample() returns a non-delta sample exactly when u_lobe < non_delta_probability(wo), and
// has_non_delta_transmission() says whether a non-delta sample can cross the surface.
TEST_P(BsdfContract, NonDeltaLobesComeFirstInULobe) {
  const ContractCase& c = GetParam();
  const Bsdf b = c.make();
  Rng rng(c.seed, 5);
  bool crossed = false;
  for (int j = 0; j < 4000; ++j) {
    Vec3 wo = random_direction(rng);
    float u_lobe = rng.next_float();
    auto s = bsdf_sample(b, wo, u_lobe, {rng.next_float(), rng.next_float()});
    if (!s) continue;
    EXPECT_EQ(!s->is_delta, u_lobe < bsdf_non_delta_probability(b, wo)) << "wo.z " << wo.z << " u_lobe " << u_lobe;
    if (!s->is_delta && !same_hemisphere(wo, s->wi)) crossed = true;
  }
  EXPECT_EQ(crossed, bsdf_has_non_delta_transmission(b));
}

// What the type's flags say it can do bounds what each instance does; the adjoint scale that
// BsdfFlags::Refraction selects is the sampled refraction's eta'^2.
TEST_P(BsdfContract, BehavesAsItsTypeFlagsSay) {
  const ContractCase& c = GetParam();
  const Bsdf b = c.make();
  const BsdfFlags flags = bsdf_flags(b);
  EXPECT_TRUE(!bsdf_has_non_delta(b) || has(flags, BsdfFlags::NonDelta));
  EXPECT_TRUE(!bsdf_has_non_delta_transmission(b) || has(flags, BsdfFlags::Transmission));
  EXPECT_TRUE(!has(flags, BsdfFlags::Refraction) ||
              (has(flags, BsdfFlags::Transmission) && has(flags, BsdfFlags::NonDelta)));
  Rng rng(c.seed, 9);
  int bad = 0;
  for (int j = 0; j < 4000 && bad < 5; ++j) {
    Vec3 wo = random_direction(rng), wi = random_direction(rng);
    const bool reflected = same_hemisphere(wo, wi);
    if (!has(flags, BsdfFlags::NonDelta) || !has(flags, reflected ? BsdfFlags::Reflection : BsdfFlags::Transmission)) {
      bool zero = bsdf_eval(b, wo, wi) == RGB(0.0f) && bsdf_pdf(b, wo, wi) == 0;
      if (!zero) ++bad;
      EXPECT_TRUE(zero) << "eval or pdf where the flags allow none, wo.z " << wo.z << " wi.z " << wi.z;
    }
    auto s = bsdf_sample(b, wo, rng.next_float(), {rng.next_float(), rng.next_float()});
    if (!s) continue;
    EXPECT_FALSE(is_black(flags));
    EXPECT_TRUE(has(flags, s->is_delta ? BsdfFlags::Delta : BsdfFlags::NonDelta)) << "delta " << s->is_delta;
    const bool crossed = !same_hemisphere(wo, s->wi);
    EXPECT_TRUE(has(flags, crossed ? BsdfFlags::Transmission : BsdfFlags::Reflection)) << "crossed " << crossed;
    if (!s->is_delta && crossed) {
      float scale = bsdf_adjoint_scale(b, wo, s->wi);
      if (!(std::abs(scale - s->eta * s->eta) <= 1e-5f * scale)) ++bad;
      EXPECT_NEAR(scale, s->eta * s->eta, 1e-5f * scale) << "wo.z " << wo.z;
    }
  }
  EXPECT_EQ(bsdf_is_black(b), is_black(flags));
}

std::string case_name(const ::testing::TestParamInfo<ContractCase>& info) {
  std::string name;
  for (char ch : info.param.name) name += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(EveryBsdf, BsdfContract, ::testing::ValuesIn(all_cases()), case_name);

// Each alternative of the variant has cases, and cases_of<B> builds B.
TEST(BsdfContractList, CoversEveryBsdf) {
  std::vector<int> count(std::variant_size_v<Bsdf>, 0);
  for (const ContractCase& c : all_cases()) {
    EXPECT_EQ(c.make().index(), c.alternative) << c.name;
    ++count[c.alternative];
  }
  for (size_t i = 0; i < count.size(); ++i) EXPECT_GE(count[i], 1) << "alternative " << i;
}

}  // namespace
}  // namespace candela
