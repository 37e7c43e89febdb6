// Mitsuba 3's own render-regression scenes (../shared/scenes/mitsuba-tests/), read by candela's Mitsuba
// reader and rendered by candela, judged by Mitsuba's protocol (candela/testing/mitsuba_z_test.h)
// against Mitsuba's references (mean of 32,000 spp) and their per-sample variance. docs/conformance.md
// lists every scene with its passing fraction, and the reason for each that does not pass.
//
// Set CANDELA_CONFORMANCE_OUT to a directory to also write each render there (NAME.exr).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <tuple>

#include "candela/film/image_io.h"
#include "candela/base/error.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/mitsuba_z_test.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

enum class Expect {
  Pass,
  // Renders, but does not pass yet: the test reports its pass fraction (docs/conformance.md lists
  // it) and asserts only that it renders.
  KnownFailure,
  // Fails only where the reference's variance image is negative (floored at 1e-4 by the protocol):
  // must pass when each negative variance is replaced by the larger of its magnitude and candela's
  // own per-sample variance there. docs/conformance.md explains why neither alone will do.
  PassWithNegativeVarianceReplaced,
};

struct ConformanceCase {
  const char* folder;
  const char* scene;  // file name without .xml; the reference drops the last "_integrator" part
  Expect zsobol;       // rendered with candela's ZSobol sampler
  Expect independent;  // rendered with the independent sampler the scene names
  Expect expect(SamplerType s) const { return s == SamplerType::ZSobol ? zsobol : independent; }
};

void PrintTo(const ConformanceCase& c, std::ostream* os) { *os << c.scene; }

std::string reference_name(const std::string& scene) { return scene.substr(0, scene.rfind('_')); }

// Each scene is rendered twice: with candela's most efficient sampler, ZSobol, and with the
// independent sampler the scenes name (for which the protocol's z-test is calibrated).
class MitsubaConformance : public ::testing::TestWithParam<std::tuple<ConformanceCase, SamplerType>> {};

const char* sampler_name(SamplerType type) { return type == SamplerType::ZSobol ? "zsobol" : "independent"; }

TEST_P(MitsubaConformance, PassesMitsubasRenderTest) {
  const ConformanceCase& c = std::get<0>(GetParam());
  const SamplerType sampler = std::get<1>(GetParam());
  const Expect expect = c.expect(sampler);
  // A known failure asserts nothing but that it renders, and its renders are among the longest of the
  // suite (100 s of CI's time): they run when asked, to update docs/conformance.md's pass fractions.
  if (expect == Expect::KnownFailure && !std::getenv("CANDELA_CONFORMANCE_KNOWN_FAILURES"))
    GTEST_SKIP() << "a known failure (docs/conformance.md); CANDELA_CONFORMANCE_KNOWN_FAILURES=1 renders it";
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(CANDELA_SHARED_DIR) / "scenes/mitsuba-tests/tests/scenes" / c.folder;
  const fs::path file = dir / (std::string(c.scene) + ".xml");
  SceneDesc desc;
  try {
    desc = read_scene_file(file);
  } catch (const SceneError& e) {
    if (expect != Expect::KnownFailure) throw;
    std::printf("CONFORMANCE %s %s FAIL (cannot be read: %s)\n", c.scene, sampler_name(sampler), e.what());
    return;
  }
  const std::string ref = (dir / "refs" / reference_name(c.scene)).string();
  Image reference = read_image(ref + "_ref_rgb.exr");
  Image variance = read_image(ref + "_ref_rgb_var.exr");
  ASSERT_EQ(desc.film.width, reference.width);
  ASSERT_EQ(desc.film.height, reference.height);
  desc.settings.spp = testing::mitsuba_test_spp(desc.film.width, desc.film.height);
  desc.settings.seed = 1;
  // The protocol fixes the spp and judges the noise against Mitsuba's independent samples; any
  // unbiased way of placing them may be used.
  desc.settings.sampler.type = sampler;
  Image image = testing::render_description(desc).mean_image();
  if (const char* out = std::getenv("CANDELA_CONFORMANCE_OUT"))
    write_image(fs::path(out) / (std::string(c.scene) + "_" + sampler_name(sampler) + ".exr"), image);

  const int spp = desc.settings.spp;
  testing::MitsubaZTestResult r = testing::mitsuba_z_test(image, reference, variance, spp);
  Image absolute = variance;
  for (float& v : absolute.rgb) v = std::abs(v);
  testing::MitsubaZTestResult abs_var =
      testing::mitsuba_z_test(image, reference, testing::replace_negative_variance(variance, absolute), spp);
  int negative = 0;
  for (float v : variance.rgb) negative += v < 0;
  std::printf("CONFORMANCE %s %s %s %.5f (%d pixel-channels, %d spp, alpha %.3g; reference variance < 0 in %.2f%%; "
              "with |var| %.5f)\n",
              c.scene, sampler_name(sampler), r.passed() ? "pass" : "FAIL", r.passing_fraction, r.pixel_channels, spp, r.alpha,
              100.0 * negative / double(variance.rgb.size()), abs_var.passing_fraction);
  if (expect == Expect::Pass) {
    EXPECT_TRUE(r.passed()) << c.scene << ": " << r.passing_fraction << " pass";
  } else {
    // What a negative variance should have been is unknown. Two estimates: its magnitude, and
    // candela's own per-sample variance, measured by an independent render (another seed) with
    // independent samples, each uniform over its pixel as Mitsuba's are. As long as candela is at
    // least as efficient per sample as Mitsuba, the latter is at most Mitsuba's true variance. (A
    // bidirectional render splats part of its samples elsewhere: its pixel sums do not hold the
    // variance, and only the magnitude is used.)
    Image substitute = absolute;
    if (desc.settings.integrator == "path" || desc.settings.integrator == "volpath") {
      SceneDesc independent = desc;
      independent.settings.sampler.type = SamplerType::Independent;
      independent.settings.seed = 2;
      Film film = testing::render_description(independent);
      Image own = film.variance_of_mean_image();
      for (int y = 0; y < own.height; ++y)
        for (int x = 0; x < own.width; ++x) {
          RGB v = own.at(x, y) * float(film.pixel(x, y).count), magnitude = absolute.at(x, y);
          substitute.set(x, y, {std::max(v.r, magnitude.r), std::max(v.g, magnitude.g), std::max(v.b, magnitude.b)});
        }
    }
    testing::MitsubaZTestResult replaced =
        testing::mitsuba_z_test(image, reference, testing::replace_negative_variance(variance, substitute), spp);
    std::printf("CONFORMANCE %s %s with each negative variance replaced by max(|var|, candela's): %.5f\n", c.scene,
                sampler_name(sampler), replaced.passing_fraction);
    if (expect == Expect::PassWithNegativeVarianceReplaced) {
      EXPECT_TRUE(replaced.passed()) << c.scene << ": " << replaced.passing_fraction
                                     << " pass with negative variances replaced";
    }
  }
}

// The 33 scenes, with what each sampler achieves in this checkout; docs/conformance.md explains each.
const ConformanceCase kCases[] = {
    {"bsdf_spheres", "test_arealight_path", Expect::PassWithNegativeVarianceReplaced, Expect::PassWithNegativeVarianceReplaced},
    {"bsdf_spheres", "test_bumpmap_path", Expect::Pass, Expect::Pass},
    {"bsdf_spheres", "test_constant_path", Expect::Pass, Expect::PassWithNegativeVarianceReplaced},
    {"bsdf_spheres", "test_envmap_path", Expect::PassWithNegativeVarianceReplaced, Expect::PassWithNegativeVarianceReplaced},
    {"bsdf_spheres", "test_normalmap_identity_roughconductor_path", Expect::PassWithNegativeVarianceReplaced, Expect::PassWithNegativeVarianceReplaced},
    {"bsdf_spheres", "test_normalmap_path", Expect::Pass, Expect::Pass},
    {"bsdf_spheres", "test_normalmap_roughconductor_path", Expect::PassWithNegativeVarianceReplaced, Expect::KnownFailure},
    {"bsdf_spheres", "test_pointlight_path", Expect::Pass, Expect::Pass},
    {"bsdf_spheres", "test_roughdielectric_path", Expect::PassWithNegativeVarianceReplaced, Expect::PassWithNegativeVarianceReplaced},
    {"bsdf_spheres", "test_roughplastic_linear_path", Expect::PassWithNegativeVarianceReplaced, Expect::PassWithNegativeVarianceReplaced},
    {"bsdf_spheres", "test_roughplastic_nonlinear_path", Expect::PassWithNegativeVarianceReplaced, Expect::PassWithNegativeVarianceReplaced},
    {"bsdf_spheres", "test_textured_diffuse_path", Expect::Pass, Expect::Pass},
    {"bsdf_spheres", "test_textured_roughconductor_path", Expect::PassWithNegativeVarianceReplaced, Expect::PassWithNegativeVarianceReplaced},
    {"bsdf_spheres", "test_texturedprincipled1_path", Expect::PassWithNegativeVarianceReplaced, Expect::KnownFailure},
    {"bsdf_spheres", "test_texturedprincipled2_path", Expect::PassWithNegativeVarianceReplaced, Expect::KnownFailure},
    {"bsdf_spheres", "test_texturedprincipledthin_path", Expect::PassWithNegativeVarianceReplaced, Expect::PassWithNegativeVarianceReplaced},
    {"instancing", "test_instancing_path", Expect::Pass, Expect::PassWithNegativeVarianceReplaced},
    {"mesh_attributes", "test_mesh_attributes_1_face_direct", Expect::Pass, Expect::PassWithNegativeVarianceReplaced},
    {"mesh_attributes", "test_mesh_attributes_3_face_direct", Expect::Pass, Expect::PassWithNegativeVarianceReplaced},
    {"mesh_attributes", "test_mesh_attributes_3_vertex_direct", Expect::Pass, Expect::PassWithNegativeVarianceReplaced},
    {"orthographic_sensor", "test_orthographic_path", Expect::Pass, Expect::Pass},
    {"participating_media", "test_hetero_sigmat_volpath", Expect::KnownFailure, Expect::KnownFailure},
    {"participating_media", "test_homo_area_light_volpath", Expect::Pass, Expect::Pass},
    {"participating_media", "test_homo_dielectric_envmap_volpath", Expect::Pass, Expect::PassWithNegativeVarianceReplaced},
    {"participating_media", "test_homo_null_envmap_volpath", Expect::Pass, Expect::KnownFailure},
    {"participating_media", "test_homo_obj_inside_medium_volpath", Expect::Pass, Expect::Pass},
    {"participating_media", "test_homo_roughdielectric_spot_volpath", Expect::Pass, Expect::Pass},
    {"participating_media", "test_surf_area_light_volpath", Expect::PassWithNegativeVarianceReplaced, Expect::KnownFailure},
    {"projector", "test_projector_constant_direct", Expect::Pass, Expect::Pass},
    {"projector", "test_projector_textured_direct", Expect::Pass, Expect::PassWithNegativeVarianceReplaced},
    {"spot_light", "test_spot_direct", Expect::PassWithNegativeVarianceReplaced, Expect::PassWithNegativeVarianceReplaced},
    {"various_emitters", "test_various_emitters_ptracer", Expect::PassWithNegativeVarianceReplaced, Expect::PassWithNegativeVarianceReplaced},
    {"various_shapes", "test_various_shapes_path", Expect::Pass, Expect::Pass},
};

INSTANTIATE_TEST_SUITE_P(Scenes, MitsubaConformance,
                         ::testing::Combine(::testing::ValuesIn(kCases),
                                            ::testing::Values(SamplerType::ZSobol, SamplerType::Independent)),
                         [](const ::testing::TestParamInfo<std::tuple<ConformanceCase, SamplerType>>& info) {
                           return std::string(std::get<0>(info.param).scene) + "_" +
                                  sampler_name(std::get<1>(info.param));
                         });

// The protocol itself: unbiased noise of the reference's variance passes, a 20% bias does not.
TEST(MitsubaZTest, PassesUnbiasedNoiseAndFailsABias) {
  const int w = 48, h = 48, spp = testing::mitsuba_test_spp(w, h);
  Image reference(w, h), variance(w, h), noisy(w, h), biased(w, h);
  uint64_t state = 12345;
  auto gaussian = [&] {  // Box-Muller on a 64-bit LCG: deterministic
    auto uniform = [&] {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      return (double(state >> 11) + 0.5) / double(1ull << 53);
    };
    return std::sqrt(-2 * std::log(uniform())) * std::cos(2 * 3.14159265358979 * uniform());
  };
  for (size_t i = 0; i < reference.rgb.size(); ++i) {
    reference.rgb[i] = 0.5f;
    variance.rgb[i] = 0.25f;
    noisy.rgb[i] = float(0.5 + gaussian() * std::sqrt(0.25 / spp));
    biased.rgb[i] = float(0.6 + gaussian() * std::sqrt(0.25 / spp));
  }
  EXPECT_TRUE(testing::mitsuba_z_test(noisy, reference, variance, spp).passed());
  testing::MitsubaZTestResult b = testing::mitsuba_z_test(biased, reference, variance, spp);
  EXPECT_FALSE(b.passed()) << b.passing_fraction;
}

}  // namespace
}  // namespace candela
