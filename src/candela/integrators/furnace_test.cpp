// Furnace scenes with analytic answers, rendered by every integrator in the registry
// (integrators/integrator.h): an integrator added there is tested here without a line of its own.
//
// Each scene is rendered with 8 seeds; the estimate is the mean of the 8 image (or region) means and
// its standard error comes from their spread, which is right for every integrator (Metropolis
// chains make neighbouring pixels correlated, so the spread of pixels would understate it). The test
// allows 5 standard errors (Student's t with 7 degrees of freedom: p = 0.0016) plus a floor for
// what the depth limit leaves out and for zero-variance estimators.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

using testing::look_at_camera;
using testing::region_mean;

using Region = std::function<bool(int, int)>;

struct FurnaceCase {
  std::string name;
  SceneDesc scene;
  double expected;
  Region region;        // the pixels whose mean is judged
  double floor = 1e-4;  // relative error allowed beyond the standard errors
  bool at_most = false;  // the answer is an upper bound (energy may be lost, never gained)
};

constexpr int kSeeds = 8;

void expect_analytic(const std::string& integrator, const FurnaceCase& c) {
  SceneDesc d = c.scene;
  d.settings.integrator = integrator;
  d.settings.mlt.bootstrap = 2000;  // the default (1e5 per depth) is for images, not 16 x 16 furnaces
  d.settings.mlt.chains = 64;
  const Scene scene(d);
  std::vector<double> means;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    RenderSettings settings = d.settings;
    settings.seed = seed;
    Film film(d.film.width, d.film.height);
    RenderOptions options;
    options.progress = false;
    render(scene, settings, film, options);
    means.push_back(region_mean(film.mean_image(), -1, c.region).mean);
  }
  double m = 0, v = 0;
  for (double x : means) m += x / kSeeds;
  for (double x : means) v += (x - m) * (x - m) / (kSeeds - 1);
  const double standard_error = std::sqrt(v / kSeeds);
  if (c.at_most)
    EXPECT_LE(m, c.expected + 5 * standard_error) << integrator << ", " << c.name << ": standard error " << standard_error;
  else
    EXPECT_NEAR(m, c.expected, 5 * standard_error + c.floor * c.expected)
        << integrator << ", " << c.name << ": standard error " << standard_error;
}

// A closed diffuse sphere of radius 2 seen from inside, at max depth 30.
SceneDesc closed_sphere(float albedo) {
  SceneDesc d = testing::closed_diffuse_sphere(albedo, 30);
  d.settings.spp = 8;
  return d;
}

// A unit sphere under a uniform sky, filling the middle of a 20-degree view.
SceneDesc sphere_under_sky(const MaterialDesc& material, RGB sky) {
  return testing::sphere_under_sky(material, sky, 16, 20, 8, 30);
}

// Pixels well inside the sphere's silhouette (it subtends 14.5 of the 20 degrees).
bool inside_disk(int x, int y) {
  float sx = 2 * (x + 0.5f) / 16 - 1, sy = 2 * (y + 0.5f) / 16 - 1;
  return sx * sx + sy * sy < 0.5f;
}

std::vector<FurnaceCase> furnace_cases() {
  std::vector<FurnaceCase> cases;
  const Region everywhere = [](int, int) { return true; };
  // L = Le (1 + rho + ... + rho^30): the emission seen after 0..30 bounces. One-sided emitters
  // face inwards.
  const float albedo = 0.6f, Le = 0.5f;
  for (bool two_sided : {true, false}) {
    SceneDesc d = closed_sphere(albedo);
    d.shapes[0].emission = AreaEmission{RGB(Le), two_sided};
    d.shapes[0].reverse_orientation = !two_sided;
    cases.push_back({two_sided ? "emissive closed sphere" : "inward-emitting closed sphere", d,
                     Le * (1 - std::pow(albedo, 31)) / (1 - albedo), everywhere});
  }
  // A point light at the centre: irradiance I / r^2 everywhere, so L = I / (pi r^2) (rho + ... + rho^30).
  {
    const float rho = 0.5f, I = 3.0f, r = 2.0f;
    SceneDesc d = closed_sphere(rho);
    d.lights = {PointLight{{0, 0, 0}, RGB(I)}};
    cases.push_back({"point light in a closed sphere", d, I / (kPi * r * r) * rho * (1 - std::pow(rho, 30)) / (1 - rho),
                     everywhere});
  }
  // Emission plus single scattering at max depth 1: Le (1 + rho).
  {
    SceneDesc d = closed_sphere(0.5f);
    d.shapes[0].emission = AreaEmission{RGB(1.0f), true};
    d.settings.max_depth = 1;
    cases.push_back({"max depth 1", d, 1.5, everywhere});
  }
  // A convex object under a uniform sky: one bounce, then the sky.
  cases.push_back({"diffuse sphere under the sky", sphere_under_sky(DiffuseMaterial{RGB(0.7f)}, RGB(2.0f)), 1.4,
                   inside_disk});
  cases.push_back({"mirror sphere under the sky", sphere_under_sky(MirrorMaterial{RGB(0.25f, 0.5f, 0.75f)}, RGB(2.0f)),
                   1.0, inside_disk});
  // Fresnel reflection and refraction conserve energy, and the 1/eta^2 radiance scaling on the way
  // in cancels on the way out (adjoint transport must not scale importance): the glass is invisible.
  // What lies beyond 30 bounces inside it is under 1e-3.
  cases.push_back({"glass sphere in a white furnace", sphere_under_sky(DielectricMaterial{1.5f, RGB(1.0f), RGB(1.0f)}, RGB(1.0f)),
                   1.0, inside_disk, 2e-3});
  // The paper's material: with s = t = 0 Lambertian with albedo d x diffuse; with t = 1 and white
  // transmission refraction only, lossless; with d = s = 1/2 the normalised Phong lobe loses the
  // part below the surface, so a white mixture may only be darker.
  PhongMaterial diffuse_lobe;
  diffuse_lobe.diffuse = RGB(0.8f);
  diffuse_lobe.d = 0.5f;
  diffuse_lobe.s = diffuse_lobe.t = 0;
  cases.push_back({"paper material, diffuse lobe", sphere_under_sky(diffuse_lobe, RGB(1.0f)), 0.4, inside_disk});
  PhongMaterial transmission;
  transmission.d = transmission.s = 0;
  transmission.t = 1;
  transmission.transmission = RGB(1.0f);
  transmission.ior = 1.33f;
  cases.push_back({"paper material, transmission lobe", sphere_under_sky(transmission, RGB(1.0f)), 1.0, inside_disk, 2e-3});
  PhongMaterial glossy;
  glossy.diffuse = glossy.specular = RGB(1.0f);
  glossy.exponent = 10;
  glossy.d = glossy.s = 0.5f;
  glossy.t = 0;
  cases.push_back({"paper material, white glossy", sphere_under_sky(glossy, RGB(1.0f)), 1.0, inside_disk, 0, true});
  return cases;
}

class EveryIntegrator : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryIntegrator, RendersTheFurnacesAnalyticAnswers) {
  for (const FurnaceCase& c : furnace_cases()) expect_analytic(GetParam(), c);
}

std::vector<std::string> integrator_names_for_tests() {
  std::vector<std::string> names;
  // Every one that renders all light transport (auto chooses one of them; ambient occlusion shows
  // geometry; the light tracer leaves out what the camera sees through delta surfaces, and emitters).
  for (const IntegratorEntry& entry : integrators())
    if (entry.render && !entry.geometric && !entry.partial_transport) names.emplace_back(entry.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryIntegrator, ::testing::ValuesIn(integrator_names_for_tests()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace candela
