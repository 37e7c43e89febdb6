// Mitsuba 3's own render-regression scenes (../shared/scenes/mitsuba-tests/), read by candela's Mitsuba
// reader and rendered by candela, judged by Mitsuba's protocol (candela/testing/mitsuba_z_test.h)
// against Mitsuba's references (mean of 32,000 spp) and their per-sample variance. docs/conformance.md
// lists every scene with its passing fractions.
//
// Set CANDELA_CONFORMANCE_OUT to a directory to also write each render there (NAME.exr).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <tuple>

#include "candela/film/image_io.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/mitsuba_z_test.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

struct ConformanceCase {
  const char* folder;
  const char* scene;  // file name without .xml; the reference drops the last "_integrator" part
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
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(CANDELA_SHARED_DIR) / "scenes/mitsuba-tests/tests/scenes" / c.folder;
  const SceneDesc scene = read_scene_file(dir / (std::string(c.scene) + ".xml"));
  const std::string ref = (dir / "refs" / reference_name(c.scene)).string();
  const Image reference = read_image(ref + "_ref_rgb.exr");
  const Image variance = read_image(ref + "_ref_rgb_var.exr");
  ASSERT_EQ(scene.film.width, reference.width);
  ASSERT_EQ(scene.film.height, reference.height);
  SceneDesc desc = scene;
  desc.settings.spp = testing::mitsuba_test_spp(desc.film.width, desc.film.height);
  desc.settings.seed = 1;
  // The protocol fixes the spp and judges the noise against Mitsuba's independent samples; any
  // unbiased way of placing them may be used.
  desc.settings.sampler.type = sampler;
  const Image image = testing::render_description(desc).mean_image();
  if (const char* out = std::getenv("CANDELA_CONFORMANCE_OUT"))
    write_image(fs::path(out) / (std::string(c.scene) + "_" + sampler_name(sampler) + ".exr"), image);

  const testing::MitsubaZTestResult r = testing::mitsuba_z_test(image, reference, variance, desc.settings.spp);
  const testing::ImageMeanAgreement mean = testing::image_mean_agreement(image, reference, variance, desc.settings.spp);
  std::printf("CONFORMANCE %s %s %s %.5f (%d pixel-channels, %d spp, alpha %.3g); image mean z (X Y Z) %.2f %.2f %.2f, "
              "relative difference %.5f %.5f %.5f\n",
              c.scene, sampler_name(sampler), r.passed() ? "pass" : "FAIL", r.passing_fraction, r.pixel_channels,
              desc.settings.spp, r.alpha, mean.z.r, mean.z.g, mean.z.b, mean.relative_difference.r,
              mean.relative_difference.g, mean.relative_difference.b);
  EXPECT_TRUE(r.passed()) << c.scene << ": " << r.passing_fraction << " pass";
  // Mitsuba's protocol passes a bias of a few percent; the image's mean must also agree with the
  // reference's (within 5 standard errors: with candela's noise up to twice Mitsuba's, 3.5 of its
  // own; the ZSobol renders' noise is lower).
  EXPECT_TRUE(mean.agrees()) << c.scene << ": image mean z " << mean.z.r << " " << mean.z.g << " " << mean.z.b
                             << ", relative difference " << mean.relative_difference.r << " "
                             << mean.relative_difference.g << " " << mean.relative_difference.b;
}

// The 33 scenes; docs/conformance.md lists each one's pass fractions.
const ConformanceCase kCases[] = {
    {"bsdf_spheres", "test_arealight_path"},
    {"bsdf_spheres", "test_bumpmap_path"},
    {"bsdf_spheres", "test_constant_path"},
    {"bsdf_spheres", "test_envmap_path"},
    {"bsdf_spheres", "test_normalmap_identity_roughconductor_path"},
    {"bsdf_spheres", "test_normalmap_path"},
    {"bsdf_spheres", "test_normalmap_roughconductor_path"},
    {"bsdf_spheres", "test_pointlight_path"},
    {"bsdf_spheres", "test_roughdielectric_path"},
    {"bsdf_spheres", "test_roughplastic_linear_path"},
    {"bsdf_spheres", "test_roughplastic_nonlinear_path"},
    {"bsdf_spheres", "test_textured_diffuse_path"},
    {"bsdf_spheres", "test_textured_roughconductor_path"},
    {"bsdf_spheres", "test_texturedprincipled1_path"},
    {"bsdf_spheres", "test_texturedprincipled2_path"},
    {"bsdf_spheres", "test_texturedprincipledthin_path"},
    {"instancing", "test_instancing_path"},
    {"mesh_attributes", "test_mesh_attributes_1_face_direct"},
    {"mesh_attributes", "test_mesh_attributes_3_face_direct"},
    {"mesh_attributes", "test_mesh_attributes_3_vertex_direct"},
    {"orthographic_sensor", "test_orthographic_path"},
    {"participating_media", "test_hetero_sigmat_volpath"},
    {"participating_media", "test_homo_area_light_volpath"},
    {"participating_media", "test_homo_dielectric_envmap_volpath"},
    {"participating_media", "test_homo_null_envmap_volpath"},
    {"participating_media", "test_homo_obj_inside_medium_volpath"},
    {"participating_media", "test_homo_roughdielectric_spot_volpath"},
    {"participating_media", "test_surf_area_light_volpath"},
    {"projector", "test_projector_constant_direct"},
    {"projector", "test_projector_textured_direct"},
    {"spot_light", "test_spot_direct"},
    {"various_emitters", "test_various_emitters_ptracer"},
    {"various_shapes", "test_various_shapes_path"},
};

INSTANTIATE_TEST_SUITE_P(Scenes, MitsubaConformance,
                         ::testing::Combine(::testing::ValuesIn(kCases),
                                            ::testing::Values(SamplerType::ZSobol, SamplerType::Independent)),
                         [](const ::testing::TestParamInfo<std::tuple<ConformanceCase, SamplerType>>& info) {
                           return std::string(std::get<0>(info.param).scene) + "_" +
                                  sampler_name(std::get<1>(info.param));
                         });

// Standard normal numbers, deterministic: Box-Muller on a 64-bit LCG.
class Gaussian {
 public:
  explicit Gaussian(uint64_t seed) : state_(seed) {}
  float operator()() { return float(std::sqrt(-2 * std::log(uniform())) * std::cos(2 * 3.14159265358979 * uniform())); }

 private:
  double uniform() {
    state_ = state_ * 6364136223846793005ull + 1442695040888963407ull;
    return (double(state_ >> 11) + 0.5) / double(1ull << 53);
  }
  uint64_t state_;
};

// The protocol itself: unbiased noise of the reference's variance passes, a 20% bias does not.
TEST(MitsubaZTest, PassesUnbiasedNoiseAndFailsABias) {
  const int w = 48, h = 48, spp = testing::mitsuba_test_spp(w, h);
  Image reference(w, h), variance(w, h), noisy(w, h), biased(w, h);
  Gaussian gaussian(12345);
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

// Mitsuba's per-pixel protocol lets a small bias through (each pixel is judged on its own, at a
// Sidak-corrected level); the image-mean check catches it.
TEST(MitsubaZTest, TheImageMeanCatchesABiasThePerPixelTestPasses) {
  const int w = 48, h = 48, spp = testing::mitsuba_test_spp(w, h);
  Image reference(w, h), variance(w, h), unbiased(w, h), biased(w, h);
  Gaussian gaussian(4242);
  for (size_t i = 0; i < reference.rgb.size(); ++i) {
    reference.rgb[i] = 0.5f;
    variance.rgb[i] = 0.25f;
    const float noise = gaussian() * std::sqrt(0.25f / spp);
    unbiased.rgb[i] = 0.5f + noise;
    biased.rgb[i] = 0.5f * 1.01f + noise;  // 1% too bright
  }
  EXPECT_TRUE(testing::mitsuba_z_test(biased, reference, variance, spp).passed());
  EXPECT_FALSE(testing::image_mean_agreement(biased, reference, variance, spp).agrees());
  EXPECT_TRUE(testing::mitsuba_z_test(unbiased, reference, variance, spp).passed());
  EXPECT_TRUE(testing::image_mean_agreement(unbiased, reference, variance, spp).agrees());
}

// Mitsuba's moment integrator computes the variance in XYZ and writes it through the XYZ-to-RGB
// matrix, whose negative entries make "negative variances" of a valid one. Noise whose XYZ variance
// is the file's, converted, must pass, although the file's red channel is negative everywhere.
TEST(MitsubaZTest, JudgesInXyzWhereTheVarianceWasComputed) {
  const int w = 48, h = 48, spp = testing::mitsuba_test_spp(w, h);
  const RGB xyz_variance(0.01f, 0.2f, 0.01f);
  auto xyz_to_srgb = [](const RGB& c) {
    return RGB(3.240479f * c.r - 1.537150f * c.g - 0.498535f * c.b, -0.969256f * c.r + 1.875991f * c.g + 0.041556f * c.b,
               0.055648f * c.r - 0.204043f * c.g + 1.057311f * c.b);
  };
  Image reference(w, h), variance(w, h), noisy(w, h);
  Gaussian gaussian(777);
  const RGB xyz_mean(0.5f, 0.6f, 0.7f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      reference.set(x, y, xyz_to_srgb(xyz_mean));
      variance.set(x, y, xyz_to_srgb(xyz_variance));
      RGB noise(gaussian() * std::sqrt(xyz_variance.r / spp), gaussian() * std::sqrt(xyz_variance.g / spp),
                gaussian() * std::sqrt(xyz_variance.b / spp));
      noisy.set(x, y, xyz_to_srgb(xyz_mean + noise));
    }
  ASSERT_LT(variance.at(0, 0).r, 0);
  testing::MitsubaZTestResult r = testing::mitsuba_z_test(noisy, reference, variance, spp);
  EXPECT_TRUE(r.passed()) << r.passing_fraction;
}

}  // namespace
}  // namespace candela
