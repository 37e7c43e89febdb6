// Render-level tests of the materials and lights with analytic answers: small scenes built in
// code, rendered end to end, and pixel regions compared with the exact value. As in furnace_test,
// each comparison allows 4 standard errors estimated from the render itself (the spread of the
// per-pixel estimates over the region) plus a tiny floor for estimators with zero variance.
// Where the exact value varies over the image, the region mean of (rendered - exact) is compared
// with 0; the exact value of a pixel is its average over the pixel's footprint (a midpoint rule on
// a sub-pixel grid, rays from the renderer's own camera), and pixels that straddle a discontinuity
// (a silhouette, a checker edge) are left out.
//
// Paths are long enough (max_depth 64) for the closed furnace spheres: Russian roulette ends most
// of them earlier and reweights the survivors, which keeps the estimate unbiased.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "candela/camera/camera.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

using namespace testing;  // the render helpers: render_description, region_mean, look_at_camera, ...

constexpr int kSize = 32;  // film width and height

using PixelSelection = std::function<bool(int, int)>;

// |mean - expected| <= 4 standard errors + 1e-5 (relative, for zero-variance estimators) + slack
// (the error of a numerically integrated expected value, where there is one).
void expect_within_standard_errors(const MeanEstimate& e, double expected, const std::string& what,
                                   double slack = 0) {
  ASSERT_GT(e.pixels, 0) << what << ": empty region";
  double tolerance = 4 * e.standard_error + 1e-5 * std::max(1.0, std::abs(expected)) + slack;
  EXPECT_NEAR(e.mean, expected, tolerance) << what << ": standard error " << e.standard_error << " over "
                                           << e.pixels << " pixels, "
                                           << (e.mean - expected) / std::max(e.standard_error, 1e-30)
                                           << " standard errors off";
}

// Mean and standard error over the selected pixels of rendered - expected(x, y) in one channel.
MeanEstimate difference_estimate(const Image& img, int channel, const PixelSelection& selected,
                                 const std::function<double(int, int)>& expected) {
  Image diff(img.width, img.height);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (!selected(x, y)) continue;
      float d = float(double(img.at(x, y)[channel]) - expected(x, y));
      diff.set(x, y, RGB(d, d, d));
    }
  return region_mean(diff, channel, selected);
}

// ---------------------------------------------------------------- pixel footprints

constexpr int kSubpixels = 8;  // the midpoint rule's grid is kSubpixels^2 per pixel

// The camera ray through film position (fx, fy), exactly as the renderer generates it (pinhole).
Ray camera_ray(const PerspectiveCamera& camera, float fx, float fy) {
  return camera.generate_ray({fx, fy}, {0.5f, 0.5f}, 0);
}

// The average of f over the rays through pixel (x, y).
double pixel_average(const PerspectiveCamera& camera, int x, int y, const std::function<double(const Ray&)>& f) {
  double sum = 0;
  for (int j = 0; j < kSubpixels; ++j)
    for (int i = 0; i < kSubpixels; ++i)
      sum += f(camera_ray(camera, float(x) + (float(i) + 0.5f) / kSubpixels,
                          float(y) + (float(j) + 0.5f) / kSubpixels));
  return sum / (kSubpixels * kSubpixels);
}

// The fraction of the rays through a closed (kSubpixels + 1)^2 grid over pixel (x, y), edges and
// corners included, for which pred holds: 1 (or 0) classifies the whole pixel exactly when the
// region pred describes is convex (or its complement is), and up to slivers thinner than the grid
// otherwise.
double pixel_fraction(const PerspectiveCamera& camera, int x, int y, const std::function<bool(const Ray&)>& pred) {
  int count = 0;
  for (int j = 0; j <= kSubpixels; ++j)
    for (int i = 0; i <= kSubpixels; ++i)
      count += pred(camera_ray(camera, float(x) + float(i) / kSubpixels, float(y) + float(j) / kSubpixels));
  return double(count) / ((kSubpixels + 1) * (kSubpixels + 1));
}
bool pixel_all(const PerspectiveCamera& camera, int x, int y, const std::function<bool(const Ray&)>& pred) {
  return pixel_fraction(camera, x, y, pred) == 1.0;
}
bool pixel_none(const PerspectiveCamera& camera, int x, int y, const std::function<bool(const Ray&)>& pred) {
  return pixel_fraction(camera, x, y, pred) == 0.0;
}

// Nearest positive distance along the ray to the sphere, or -1 (in double).
double hit_sphere(const Ray& r, const Point3& center, double radius) {
  double ox = double(r.origin.x) - center.x, oy = double(r.origin.y) - center.y, oz = double(r.origin.z) - center.z;
  double dx = r.direction.x, dy = r.direction.y, dz = r.direction.z;
  double a = dx * dx + dy * dy + dz * dz, b = ox * dx + oy * dy + oz * dz;
  double c = ox * ox + oy * oy + oz * oz - radius * radius;
  double disc = b * b - a * c;
  if (disc < 0) return -1;
  double t0 = (-b - std::sqrt(disc)) / a, t1 = (-b + std::sqrt(disc)) / a;
  return t0 > 0 ? t0 : t1 > 0 ? t1 : -1;
}

// Where the ray meets the plane y = 0 (the ray must go down).
struct GroundPoint {
  double x, z;
};
GroundPoint ground_point(const Ray& r) {
  double t = -double(r.origin.y) / r.direction.y;
  return {r.origin.x + t * r.direction.x, r.origin.z + t * r.direction.z};
}

// ---------------------------------------------------------------- scenes

// A unit sphere of `material` at the origin seen from z = -4 under a uniform sky (it subtends
// asin(1/4) = 14.5 degrees; the fov is 40).
SceneDesc sphere_under_sky(const MaterialDesc& material, const RGB& sky, int spp) {
  return testing::sphere_under_sky(material, sky, kSize, 40, spp, 64);
}

float angle_from_axis(int x, int y) {
  float t = std::tan(radians(20));
  float sx = (2 * (float(x) + 0.5f) / kSize - 1) * t, sy = (2 * (float(y) + 0.5f) / kSize - 1) * t;
  return std::atan(std::sqrt(sx * sx + sy * sy)) * 180 / kPi;
}
// Regions of sphere_under_sky's image: the middle of the disc (normal incidence up to 20 degrees:
// 4 sin 5 deg = 0.35), a ring further out (incidence up to 44 degrees), the rim (pixels on the
// silhouette, part sphere and part sky), and the background.
bool disc_centre(int x, int y) { return angle_from_axis(x, y) < 5; }
bool disc_ring(int x, int y) { return angle_from_axis(x, y) >= 5 && angle_from_axis(x, y) < 10; }
bool disc_rim(int x, int y) { return angle_from_axis(x, y) >= 10 && angle_from_axis(x, y) < 17; }
bool background(int x, int y) { return angle_from_axis(x, y) >= 17; }

struct NamedRegion {
  const char* name;
  bool (*selected)(int, int);
};
constexpr NamedRegion kFurnaceRegions[] = {
    {"disc centre", disc_centre}, {"disc ring", disc_ring}, {"rim", disc_rim}, {"background", background}};

// Every region of the white furnace renders 1 in every channel.
void expect_invisible_in_white_furnace(const MaterialDesc& material, int spp, const std::string& what) {
  Image img = render_description(sphere_under_sky(material, RGB(1.0f), spp)).mean_image();
  for (const NamedRegion& r : kFurnaceRegions)
    for (int c = 0; c < 3; ++c)
      expect_within_standard_errors(region_mean(img, c, r.selected), 1.0,
                                    what + ", " + r.name + ", channel " + std::to_string(c));
}

// ---------------------------------------------------------------- 1. lossless materials in the white furnace

TEST(MaterialLightRender, DiffuseTransmissionSphereWithUnitAlbedoIsInvisibleInWhiteFurnace) {
  // R + T = 1 per channel: every scattering event keeps all the energy, on one side or the other,
  // so a closed sphere in a uniform sky of radiance 1 is indistinguishable from the sky. A path that
  // enters the sphere leaves it with probability T per bounce (0.3^64 stays inside past max_depth).
  expect_invisible_in_white_furnace(DiffuseTransmissionMaterial{RGB(0.3f), RGB(0.7f)}, 64, "R 0.3, T 0.7");
  // Coloured: lobe choice by the largest channel gives weights other than 1 per channel.
  expect_invisible_in_white_furnace(DiffuseTransmissionMaterial{RGB(0.2f, 0.5f, 0.9f), RGB(0.8f, 0.5f, 0.1f)}, 64,
                                    "coloured R + T = 1");
}

TEST(MaterialLightRender, SmoothCoatedDiffuseWithWhiteBaseIsInvisibleInWhiteFurnace) {
  // Smooth coat, white base (R = 1, specular 1): the coat reflects F(wo), the base returns the rest
  // through the closed-form series of internal bounces, and since 1 - Fdr_ext = eta^2 (1 - Fdr_int)
  // the directional albedo is exactly 1 at every angle. (nonlinear only matters for R < 1.)
  for (float ior : {1.5f, 2.5f})
    for (bool nonlinear : {false, true}) {
      CoatedDiffuseMaterial m;
      m.reflectance = RGB(1.0f);
      m.specular = RGB(1.0f);
      m.ior = ior;
      m.nonlinear = nonlinear;
      expect_invisible_in_white_furnace(m, 64, "coated diffuse ior " + std::to_string(ior) +
                                                   (nonlinear ? " nonlinear" : " linear"));
    }
}

// Fresnel reflectance of a conductor, directly from the complex Fresnel equations in double:
// n = eta + i k, cos_t n = sqrt(n^2 - sin^2), r_s = |(cos - n cos_t) / (cos + n cos_t)|^2,
// r_p = |(n^2 cos - n cos_t) / (n^2 cos + n cos_t)|^2.
double conductor_fresnel(double cos_i, double eta, double k) {
  std::complex<double> n(eta, k);
  double sin2 = 1 - cos_i * cos_i;
  std::complex<double> n_cos_t = std::sqrt(n * n - sin2);
  double rs = std::norm((cos_i - n_cos_t) / (cos_i + n_cos_t));
  double rp = std::norm((n * n * cos_i - n_cos_t) / (n * n * cos_i + n_cos_t));
  return (rs + rp) / 2;
}

TEST(MaterialLightRender, SmoothWhiteConductorLosesOnlyItsClampedFresnelDeficit) {
  // Artist mode with reflectance 1: conductor_k_from_reflectance clamps r to 0.9999f (k would be
  // infinite), so eta = 1, k = 2 sqrt(r) / sqrt(1 - r) ~ 200 and the mirror reflects F(theta), which
  // is 1 - 1.00e-4 at normal incidence, 1 - 1.06e-4 at 45 degrees and 1 - 1.25e-4 at 60. The sphere is convex, so every
  // camera ray that hits it reflects once into the sky: the pixel is the average of F over the
  // pixel's footprint, the background is 1. The loss is > 10x the tolerance, so "exactly 1" fails.
  const double r = double(0.9999f), k = 2 * std::sqrt(r) / std::sqrt(1 - r);
  ConductorMaterial m;
  m.reflectance = ColorInput(RGB(1.0f));
  SceneDesc d = sphere_under_sky(m, RGB(1.0f), 4);
  Image img = render_description(d).mean_image();
  PerspectiveCamera camera(d.camera, kSize, kSize);
  auto expected_at = [&](const Ray& ray) {
    double t = hit_sphere(ray, {0, 0, 0}, 1);
    if (t < 0) return 1.0;
    double len = std::sqrt(double(length_squared(ray.direction)));
    double px = ray.origin.x + t * ray.direction.x, py = ray.origin.y + t * ray.direction.y,
           pz = ray.origin.z + t * ray.direction.z;  // the unit normal, too
    double cos_i = -(px * ray.direction.x + py * ray.direction.y + pz * ray.direction.z) / len;
    return conductor_fresnel(std::clamp(cos_i, 0.0, 1.0), 1.0, k);
  };
  std::vector<double> expected(kSize * kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) expected[size_t(y * kSize + x)] = pixel_average(camera, x, y, expected_at);
  auto exact = [&](int x, int y) { return expected[size_t(y * kSize + x)]; };
  for (const NamedRegion& region : {kFurnaceRegions[0], kFurnaceRegions[1], kFurnaceRegions[3]})
    for (int c = 0; c < 3; ++c)
      expect_within_standard_errors(difference_estimate(img, c, region.selected, exact), 0.0,
                                    std::string("white conductor, ") + region.name + ", channel " + std::to_string(c));
  // The deficit is there: 1e-4 below the sky at the centre.
  EXPECT_NEAR(region_mean(img, -1, disc_centre).mean, 1 - 1.0e-4, 1e-5);
}

// ---------------------------------------------------------------- 2. rough materials lose energy, never gain it

// Every region's mean <= 1 + 4 standard errors and >= lower_bound; the background is exactly 1.
void expect_loses_but_never_gains(const MaterialDesc& material, double lower_bound, const std::string& what) {
  Image img = render_description(sphere_under_sky(material, RGB(1.0f), 64)).mean_image();
  for (const NamedRegion& r : kFurnaceRegions) {
    MeanEstimate e = region_mean(img, -1, r.selected);
    std::string label = what + ", " + r.name;
    EXPECT_LE(e.mean, 1.0 + 4 * e.standard_error + 1e-5) << label << ": standard error " << e.standard_error;
    EXPECT_GE(e.mean, lower_bound) << label;
  }
  expect_within_standard_errors(region_mean(img, -1, background), 1.0, what + ", background");
}

// The single-scattering directional albedo of a GGX conductor (eta 1 + i k) for wo = (0, sin, mu)
// in the local frame (in the plane of the frame's second axis, v), computed independently of the
// renderer in double: the midpoint rule over the hemisphere of wi of
//   f cos(theta_i) = D(wm) F(wo . wm) G2(wo, wi) / (4 mu),
// D(m) = 1 / (pi ax ay (m_x^2 / ax^2 + m_y^2 / ay^2 + m_z^2)^2), height-correlated Smith
// G2 = 1 / (1 + Lambda(wo) + Lambda(wi)), Lambda(w) = (sqrt(1 + (ax^2 w_x^2 + ay^2 w_y^2) / w_z^2) - 1) / 2.
double ggx_conductor_albedo(double mu, double ax, double ay, double k, int n_theta, int n_phi) {
  const double wo[3] = {0, std::sqrt(std::max(0.0, 1 - mu * mu)), mu};
  auto lambda = [&](const double* w) {
    return (std::sqrt(1 + (ax * ax * w[0] * w[0] + ay * ay * w[1] * w[1]) / (w[2] * w[2])) - 1) / 2;
  };
  const double lambda_o = lambda(wo);
  double sum = 0;
  for (int i = 0; i < n_theta; ++i) {
    double theta = kPi / 2 * (i + 0.5) / n_theta;
    for (int j = 0; j < n_phi; ++j) {
      double phi = 2 * kPi * (j + 0.5) / n_phi;
      double wi[3] = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
      double m[3] = {wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]};
      double len = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
      for (double& c : m) c /= len;
      double e = m[0] * m[0] / (ax * ax) + m[1] * m[1] / (ay * ay) + m[2] * m[2];
      double D = 1 / (kPi * ax * ay * e * e);
      double F = conductor_fresnel(wo[0] * m[0] + wo[1] * m[1] + wo[2] * m[2], 1.0, k);
      double G = 1 / (1 + lambda_o + lambda(wi));
      sum += D * F * G / (4 * mu) * std::sin(theta);
    }
  }
  return sum * (kPi / 2 / n_theta) * (2 * kPi / n_phi);
}

// The albedo above tabulated over mu in [0.7, 1] and interpolated linearly.
class AlbedoTable {
 public:
  AlbedoTable(double ax, double ay, double k) {
    for (int i = 0; i < kNodes; ++i) values_[i] = ggx_conductor_albedo(mu(i), ax, ay, k, 96, 256);
  }
  double operator()(double m) const {
    double x = std::clamp((m - kMuMin) / (1 - kMuMin) * (kNodes - 1), 0.0, double(kNodes - 1));
    int i = std::min(int(x), kNodes - 2);
    return values_[i] + (x - i) * (values_[i + 1] - values_[i]);
  }

 private:
  static constexpr int kNodes = 13;
  static constexpr double kMuMin = 0.7;
  static double mu(int i) { return kMuMin + (1 - kMuMin) * i / (kNodes - 1); }
  double values_[kNodes];
};

// For the sphere of sphere_under_sky seen from the camera: the average over each pixel of the albedo
// at the cosine of incidence of the rays that hit it (1 for rays that miss). The camera looks at the
// sphere's pole (object -z), so the surface's u direction (dp/du, along the parallels) is
// perpendicular to the plane of incidence everywhere: wo lies in the local (v, n) plane, as
// ggx_conductor_albedo assumes.
std::vector<double> sphere_pixel_averages(const CameraDesc& camera_desc, const std::function<double(double)>& of_mu) {
  PerspectiveCamera camera(camera_desc, kSize, kSize);
  std::vector<double> result(kSize * kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      result[size_t(y * kSize + x)] = pixel_average(camera, x, y, [&](const Ray& ray) {
        double t = hit_sphere(ray, {0, 0, 0}, 1);
        if (t < 0) return 1.0;
        double len = std::sqrt(double(length_squared(ray.direction)));
        double px = ray.origin.x + t * ray.direction.x, py = ray.origin.y + t * ray.direction.y,
               pz = ray.origin.z + t * ray.direction.z;  // the unit normal, too
        return of_mu(std::clamp(-(px * ray.direction.x + py * ray.direction.y + pz * ray.direction.z) / len, 0.0, 1.0));
      });
  return result;
}

TEST(MaterialLightRender, RoughWhiteConductorLosesButNeverGainsEnergyInWhiteFurnace) {
  // Single-scattering GGX loses the light that would scatter between microfacets more than once:
  // at normal incidence alone, the visible normals tilted beyond 45 degrees (a fraction
  // alpha^2 / (1 + alpha^2), 8% at alpha 0.3) reflect below the horizon. Camera rays hit the convex
  // sphere once and what they reflect escapes, so every pixel is the directional albedo E(mu) of
  // its point (averaged over the pixel), which is computed here by quadrature: 0.847-0.877 for
  // alpha 0.3, 0.80-0.82 for alpha 0.1 x 0.5 and 0.5 x 0.1 over the disc (incidence below 44
  // degrees). This checks that bounce rays and shadow rays to the sky combine without bias on a
  // rough conductor. The quadrature and the interpolation in mu agree with a four times finer
  // quadrature to 1.2e-4; slack 5e-4. (The material is grey: channel 1 stands for all three.)
  const double k = 2 * std::sqrt(double(0.9999f)) / std::sqrt(1 - double(0.9999f));
  struct Case {
    float alpha_u, alpha_v;
  };
  for (Case c : {Case{0.3f, 0.3f}, Case{0.1f, 0.5f}, Case{0.5f, 0.1f}}) {
    std::string what = "rough conductor alpha " + std::to_string(c.alpha_u) + " x " + std::to_string(c.alpha_v);
    ConductorMaterial m;
    m.reflectance = ColorInput(RGB(1.0f));
    m.roughness = Roughness{c.alpha_u, c.alpha_v, false};
    SceneDesc d = sphere_under_sky(m, RGB(1.0f), 64);
    Image img = render_description(d).mean_image();
    AlbedoTable albedo(c.alpha_u, c.alpha_v, k);
    std::vector<double> expected = sphere_pixel_averages(d.camera, [&](double mu) { return albedo(mu); });
    auto exact = [&](int x, int y) { return expected[size_t(y * kSize + x)]; };
    for (const NamedRegion& r : kFurnaceRegions) {
      MeanEstimate e = region_mean(img, -1, r.selected);
      EXPECT_LE(e.mean, 1.0 + 4 * e.standard_error + 1e-5) << what << ", " << r.name;
      EXPECT_GE(e.mean, 0.7) << what << ", " << r.name;
    }
    for (const NamedRegion& r : {kFurnaceRegions[0], kFurnaceRegions[1]})
      expect_within_standard_errors(difference_estimate(img, 1, r.selected, exact), 0.0, what + ", " + r.name, 5e-4);
  }
}

TEST(MaterialLightRender, RoughDielectricLosesButNeverGainsEnergyInWhiteFurnace) {
  // A rough glass sphere has no closed form: each rough interface event loses what single
  // scattering misses (12-15% for the conductor above at alpha 0.3), and a path through the sphere
  // meets the interface two or more times (internal reflections), so it renders clearly below 1
  // (measured 0.79-0.85) but never above it. The bound 0.7 catches a lost lobe (reflection only
  // would leave ~0.1) without depending on the exact multiple-scattering answer.
  DielectricMaterial m;
  m.ior = 1.5f;
  m.roughness = Roughness{0.3f, 0.3f, false};
  expect_loses_but_never_gains(m, 0.7, "rough dielectric alpha 0.3");
}

// ---------------------------------------------------------------- 3. interfaces

// A diffuse plane y = 0 of albedo `albedo` under a sky with zenith Z and horizon H, seen from
// straight above at height 6. Material 1 is an interface, for shapes added later.
SceneDesc plane_under_sky(float albedo, const RGB& zenith, const RGB& horizon, int spp) {
  SceneDesc d;
  d.film = {kSize, kSize, ""};
  d.camera = look_at_camera({0, 6, 0}, {0, 0, 0}, 50);
  d.settings.spp = spp;
  d.settings.max_depth = 8;
  d.materials = {DiffuseMaterial{RGB(albedo)}, InterfaceMaterial{}};
  ShapeDesc plane;
  plane.geometry = PlaneShape{{0, 0, 0}, {0, 1, 0}};
  plane.material = 0;
  d.shapes = {plane};
  d.lights = {SkyLight{zenith, horizon, horizon, {0, 1, 0}}};
  return d;
}

// Radiance of a Lambertian plane facing the zenith under the sky above: the irradiance of a sky
// linear in cos(theta) from H to Z is 2 pi integral (H (1 - c) + Z c) c dc = pi (H + 2 Z) / 3.
double sky_lit_plane_radiance(double albedo, double zenith, double horizon) {
  return albedo * (horizon + 2 * zenith) / 3;
}

ShapeDesc interface_sphere(const Point3& center, float radius) {
  ShapeDesc s;
  s.geometry = SphereShape{center, radius};
  s.material = 1;  // InterfaceMaterial in plane_under_sky
  return s;
}

TEST(MaterialLightRender, InterfaceSphereLeavesASkyLitPlaneUnchanged) {
  // An interface sphere between the camera and the plane: camera rays pass through it, and so do
  // the plane's bounce rays, at full weight, while its shadow rays stop at it. Under the sphere
  // (the pixels seen through it) the sphere covers 44% of the cosine-weighted sky (sin^2 of
  // asin(1 / 1.5)), so treating the pass-through as an ordinary MIS-weighted hit, or letting shadow
  // rays through as well as bounces, would be off by ~20%. Both regions must be albedo (H + 2 Z) / 3.
  const float albedo = 0.6f;
  const RGB zenith(1.0f, 0.5f, 0.25f), horizon(0.2f, 0.4f, 0.8f);
  const Point3 center(0, 1.5f, 0);
  const float radius = 1;
  SceneDesc bare = plane_under_sky(albedo, zenith, horizon, 64);
  SceneDesc with_sphere = bare;
  with_sphere.shapes.push_back(interface_sphere(center, radius));
  PerspectiveCamera camera(bare.camera, kSize, kSize);
  auto through = [&](const Ray& r) { return hit_sphere(r, center, radius) > 0; };
  PixelSelection through_sphere = [&](int x, int y) { return pixel_all(camera, x, y, through); };
  PixelSelection beside_sphere = [&](int x, int y) { return pixel_none(camera, x, y, through); };

  Image img = render_description(with_sphere).mean_image();
  Image ref = render_description(bare).mean_image();
  for (int c = 0; c < 3; ++c) {
    double expected = sky_lit_plane_radiance(albedo, zenith[c], horizon[c]);
    std::string channel = ", channel " + std::to_string(c);
    expect_within_standard_errors(region_mean(img, c, through_sphere), expected, "seen through the sphere" + channel);
    expect_within_standard_errors(region_mean(img, c, beside_sphere), expected, "beside the sphere" + channel);
    expect_within_standard_errors(region_mean(ref, c, through_sphere), expected, "no sphere, middle" + channel);
    expect_within_standard_errors(region_mean(ref, c, beside_sphere), expected, "no sphere, outside" + channel);
  }
}

TEST(MaterialLightRender, InterfaceHitsConsumeNoSamplerDimensions) {
  // A small interface sphere around the camera: every camera ray crosses it once, from the inside.
  // Crossing an interface draws no random numbers and adds nothing, so each pixel's path is the one
  // without the sphere, bit for bit, unless one of its bounce or shadow rays happens to meet the
  // sphere (it subtends 0.7% of the plane's cosine-weighted sky: with 16 samples of two rays each,
  // about 20% of the pixels). Under a sky gradient every sample's value depends on its random
  // numbers, so a sampler stream shifted by the interface would change (almost) every pixel.
  const float albedo = 0.6f;
  const RGB zenith(1.0f, 0.5f, 0.25f), horizon(0.2f, 0.4f, 0.8f);
  SceneDesc bare = plane_under_sky(albedo, zenith, horizon, 16);
  SceneDesc with_sphere = bare;
  with_sphere.shapes.push_back(interface_sphere({0, 6, 0}, 0.5f));
  Image img = render_description(with_sphere).mean_image();
  Image ref = render_description(bare).mean_image();
  int identical = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) identical += img.at(x, y) == ref.at(x, y);
  EXPECT_GT(identical, kSize * kSize / 2) << identical << " of " << kSize * kSize << " pixels bitwise identical";
  for (int c = 0; c < 3; ++c)
    expect_within_standard_errors(region_mean(img, c), sky_lit_plane_radiance(albedo, zenith[c], horizon[c]),
                                  "with the sphere around the camera, channel " + std::to_string(c));
}

TEST(MaterialLightRender, EmissiveInterfaceSphereEmitsAndLightsAPlane) {
  // An emissive sphere with an interface material hangs above a diffuse plane; no other light.
  // Seen directly it shows its radiance Le and, through it, the plane behind; a two-sided one shows
  // its far half from the inside too: 2 Le. A uniform sphere fully above a point's horizon gives
  // the irradiance of a point source, pi Le r^2 cos(beta) / D^2 (D the distance to the centre),
  // so the plane's radiance is albedo Le r^2 h / D^3 (h the centre's height); doubled when
  // two-sided, the far half's inside shining through the near half (found by bounce rays only:
  // light sampling picks points on the near half, and the bounce ray passes through the near half at
  // full weight after its MIS-weighted emission there).
  const float albedo = 0.5f, r = 0.8f, h = 2.5f;
  const RGB Le(2.0f, 1.0f, 0.5f);
  const Point3 center(0, h, 0);
  for (bool two_sided : {false, true}) {
    SceneDesc d;
    d.film = {kSize, kSize, ""};
    d.camera = look_at_camera({0, 6, 0}, {0, 0, 0}, 50);
    d.settings.spp = 64;
    d.settings.max_depth = 8;
    d.materials = {DiffuseMaterial{RGB(albedo)}, InterfaceMaterial{}};
    ShapeDesc plane;
    plane.geometry = PlaneShape{{0, 0, 0}, {0, 1, 0}};
    plane.material = 0;
    ShapeDesc sphere = interface_sphere(center, r);
    sphere.emission = AreaEmission{Le, two_sided};
    d.shapes = {plane, sphere};
    Image img = render_description(d).mean_image();

    PerspectiveCamera camera(d.camera, kSize, kSize);
    auto through = [&](const Ray& ray) { return hit_sphere(ray, center, r) > 0; };
    PixelSelection through_sphere = [&](int x, int y) { return pixel_all(camera, x, y, through); };
    PixelSelection beside_sphere = [&](int x, int y) { return pixel_none(camera, x, y, through); };
    const double sides = two_sided ? 2 : 1;
    for (int c = 0; c < 3; ++c) {
      auto plane_radiance = [&](const Ray& ray) {
        GroundPoint g = ground_point(ray);
        double D = std::sqrt(g.x * g.x + g.z * g.z + double(h) * h);
        return sides * albedo * Le[c] * r * r * h / (D * D * D);
      };
      auto exact = [&](int x, int y) { return pixel_average(camera, x, y, plane_radiance); };
      auto exact_through = [&](int x, int y) { return sides * Le[c] + exact(x, y); };
      std::string what = std::string(two_sided ? "two-sided" : "one-sided") + ", channel " + std::to_string(c);
      expect_within_standard_errors(difference_estimate(img, c, through_sphere, exact_through), 0.0,
                                    what + ", seen through the sphere");
      expect_within_standard_errors(difference_estimate(img, c, beside_sphere, exact), 0.0,
                                    what + ", plane beside the sphere");
    }
  }
}

// ---------------------------------------------------------------- 4. textured diffuse

TEST(MaterialLightRender, CheckerboardReflectanceUnderUniformSky) {
  // A lone Lambertian square facing the camera under a uniform sky L sees the sky over its whole
  // hemisphere, so its radiance is albedo * L exactly, check by check. The square spans
  // [-2, 2]^2 in z = 0 with u along +y and v along +x (normal towards the camera at z = -4), and
  // the checker mapping (s, t) = (4 u, 4 v) makes checks of 1 x 1; the view covers +-1.46. Light
  // sampling and bounces both draw cosine-distributed directions here, so with MIS every sample is
  // exactly albedo * L: the estimate has no variance, and the checks must match to float precision.
  const RGB L(1.0f, 0.7f, 0.4f), tex1(0.9f, 0.5f, 0.1f), tex2(0.1f, 0.4f, 0.8f);
  SceneDesc d;
  d.film = {kSize, kSize, ""};
  d.camera = look_at_camera({0, 0, -4}, {0, 0, 0}, 40);
  d.settings.spp = 4;
  d.settings.max_depth = 4;
  CheckerboardTexture checker;
  checker.tex1 = tex1;
  checker.tex2 = tex2;
  checker.mapping = UVMapping{4, 4, 0, 0};
  d.textures = {checker};
  ColorInput reflectance;
  reflectance.texture = 0;
  d.materials = {DiffuseMaterial{reflectance}};
  ShapeDesc square;
  square.geometry = RectangleShape{{-2, -2, 0}, {0, 4, 0}, {4, 0, 0}};
  square.material = 0;
  d.shapes = {square};
  d.lights = {SkyLight{L, L, L, {0, 1, 0}}};
  Image img = render_description(d).mean_image();

  PerspectiveCamera camera(d.camera, kSize, kSize);
  auto even_check = [](const Ray& r) {
    double t = -double(r.origin.z) / r.direction.z;
    double x = r.origin.x + t * r.direction.x, y = r.origin.y + t * r.direction.y;
    double u = (y + 2) / 4, v = (x + 2) / 4;  // the square's uv at the hit
    return ((int64_t(std::floor(4 * u)) + int64_t(std::floor(4 * v))) & 1) == 0;
  };
  PixelSelection in_tex1 = [&](int x, int y) { return pixel_all(camera, x, y, even_check); };
  PixelSelection in_tex2 = [&](int x, int y) { return pixel_none(camera, x, y, even_check); };
  for (int c = 0; c < 3; ++c) {
    std::string channel = ", channel " + std::to_string(c);
    MeanEstimate e1 = region_mean(img, c, in_tex1), e2 = region_mean(img, c, in_tex2);
    EXPECT_GE(e1.pixels, 200);
    EXPECT_GE(e2.pixels, 200);
    expect_within_standard_errors(e1, double(tex1[c]) * L[c], "tex1 checks" + channel);
    expect_within_standard_errors(e2, double(tex2[c]) * L[c], "tex2 checks" + channel);
  }
}

// ---------------------------------------------------------------- 5. distant and spot lights

// A diffuse plane y = 0 seen from straight above, lit by `light` alone.
SceneDesc plane_under_light(const RGB& albedo, const LightDesc& light, float camera_height, float fov, int spp) {
  SceneDesc d;
  d.film = {kSize, kSize, ""};
  d.camera = look_at_camera({0, camera_height, 0}, {0, 0, 0}, fov);
  d.settings.spp = spp;
  d.settings.max_depth = 4;
  d.materials = {DiffuseMaterial{albedo}};
  ShapeDesc plane;
  plane.geometry = PlaneShape{{0, 0, 0}, {0, 1, 0}};
  plane.material = 0;
  d.shapes = {plane};
  d.lights = {light};
  return d;
}

TEST(MaterialLightRender, DistantLightOnDiffusePlaneIsAlbedoTimesIrradianceCosOverPi) {
  // E is the irradiance on a surface facing the light; arriving at theta from the normal the plane
  // receives E cos(theta) and reflects albedo E cos(theta) / pi. From below the plane's lit side,
  // nothing.
  const RGB albedo(0.8f, 0.5f, 0.2f), E(1.0f, 2.0f, 3.0f);
  for (float theta_deg : {0.0f, 60.0f, 80.0f}) {
    float theta = radians(theta_deg);
    Vec3 travel(std::sin(theta), -std::cos(theta), 0);
    Image img = render_description(plane_under_light(albedo, DistantLight{travel, E}, 6, 50, 4)).mean_image();
    for (int c = 0; c < 3; ++c)
      expect_within_standard_errors(region_mean(img, c), albedo[c] * E[c] * std::cos(double(theta)) / kPi,
                                    "distant light at " + std::to_string(theta_deg) + " degrees, channel " +
                                        std::to_string(c));
  }
  Vec3 from_below(std::sin(radians(60)), std::cos(radians(60)), 0);
  Image img = render_description(plane_under_light(albedo, DistantLight{from_below, E}, 6, 50, 4)).mean_image();
  float brightest = 0;
  for (float v : img.rgb) brightest = std::max(brightest, v);
  EXPECT_EQ(brightest, 0.0f) << "a distant light below the plane";
}

TEST(MaterialLightRender, SpotLightOnDiffusePlaneFollowsInverseSquareAndCone) {
  // A spot light at height h pointing straight down, intensity I on the axis, full strength out to
  // 20 degrees and zero from 30. A plane point at distance D sees it at theta with cos = h / D, and
  // reflects albedo / pi * I(theta) cos(theta) / D^2 = albedo I(theta) h / (pi D^3); at the centre
  // albedo I / (pi h^2). Inside the inner cone I(theta) = I, in the falloff pbrt's smoothstep of
  // cos(theta), outside the outer cone 0.
  const float albedo = 0.5f, h = 2;
  const RGB I(4.0f, 2.0f, 1.0f);
  SpotLight spot;
  spot.position = {0, h, 0};
  spot.direction = {0, -1, 0};
  spot.intensity = I;
  spot.cone_angle = 30;
  spot.cone_delta = 10;
  SceneDesc d = plane_under_light(RGB(albedo), spot, 5, 45, 16);  // the view spans +-2.07 on the plane
  Image img = render_description(d).mean_image();

  PerspectiveCamera camera(d.camera, kSize, kSize);
  const double cos_inner = std::cos(double(radians(20))), cos_outer = std::cos(double(radians(30)));
  auto cos_theta = [&](const Ray& r) {
    GroundPoint g = ground_point(r);
    return h / std::sqrt(g.x * g.x + g.z * g.z + double(h) * h);
  };
  auto unshaped = [&](const Ray& r) {  // the radiance without the cone: albedo I h / (pi D^3), per unit I
    double c = cos_theta(r);
    return albedo * c * c * c / (kPi * h * h);
  };
  auto falloff_t = [&](const Ray& r) {  // 0 at the outer cone, 1 at the inner one
    return std::clamp((cos_theta(r) - cos_outer) / (cos_inner - cos_outer), 0.0, 1.0);
  };
  auto shaped = [&](const Ray& r) {
    double t = falloff_t(r);
    return t * t * (3 - 2 * t) * unshaped(r);
  };
  auto in_inner_cone = [&](const Ray& r) { return cos_theta(r) > cos_inner; };
  auto beyond_outer_cone = [&](const Ray& r) { return cos_theta(r) < cos_outer; };
  PixelSelection inner = [&](int x, int y) { return pixel_all(camera, x, y, in_inner_cone); };
  PixelSelection outside = [&](int x, int y) { return pixel_all(camera, x, y, beyond_outer_cone); };
  PixelSelection falloff = [&](int x, int y) { return !inner(x, y) && !outside(x, y); };
  // The two halves of the falloff ring apart: smoothstep(t) - t is odd about t = 1/2, so a falloff
  // linear in cos(theta) would match the whole ring's mean, but not its halves.
  PixelSelection falloff_inner_half = [&](int x, int y) {
    return falloff(x, y) && pixel_average(camera, x, y, falloff_t) >= 0.5;
  };
  PixelSelection falloff_outer_half = [&](int x, int y) {
    return falloff(x, y) && pixel_average(camera, x, y, falloff_t) < 0.5;
  };
  PixelSelection centre = [](int x, int y) { return (x == 15 || x == 16) && (y == 15 || y == 16); };

  for (int c = 0; c < 3; ++c) {
    std::string channel = ", channel " + std::to_string(c);
    // The four centre pixels: albedo I / (pi h^2) times cos^3, between 1 and its value at their far
    // corners (0.9875: each pixel is 0.129 wide on the plane).
    MeanEstimate centre_mean = region_mean(img, c, centre);
    double on_axis = albedo * I[c] / (kPi * h * h);
    double corner_cos = cos_theta(camera_ray(camera, 15, 15));
    EXPECT_LE(centre_mean.mean, on_axis * (1 + 1e-5)) << "centre" << channel;
    EXPECT_GE(centre_mean.mean, on_axis * corner_cos * corner_cos * corner_cos) << "centre" << channel;
    auto exact = [&](int x, int y) { return I[c] * pixel_average(camera, x, y, shaped); };
    expect_within_standard_errors(difference_estimate(img, c, inner, exact), 0.0, "inside the inner cone" + channel);
    expect_within_standard_errors(difference_estimate(img, c, falloff_inner_half, exact), 0.0,
                                  "inner half of the falloff" + channel);
    expect_within_standard_errors(difference_estimate(img, c, falloff_outer_half, exact), 0.0,
                                  "outer half of the falloff" + channel);
    // The falloff lies between zero and the full-strength value, pixel by pixel.
    int falloff_pixels = 0, outside_pixels = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        float v = img.at(x, y)[c];
        if (outside(x, y)) {
          ++outside_pixels;
          EXPECT_EQ(v, 0.0f) << "outside the outer cone at (" << x << ", " << y << ")" << channel;
        } else if (falloff(x, y)) {
          ++falloff_pixels;
          EXPECT_GE(v, 0.0f) << "falloff at (" << x << ", " << y << ")";
          // Every sample lies in the pixel, where the full-strength radiance is at most its
          // maximum over the pixel (sampled on a grid that includes the edges, plus 0.1%).
          double full = 0;
          for (int j = 0; j <= kSubpixels; ++j)
            for (int i = 0; i <= kSubpixels; ++i)
              full = std::max(full, unshaped(camera_ray(camera, float(x) + float(i) / kSubpixels,
                                                        float(y) + float(j) / kSubpixels)));
          EXPECT_LE(v, 1.001 * I[c] * full) << "falloff at (" << x << ", " << y << ")" << channel;
        }
      }
    EXPECT_GT(falloff_pixels, 50);
    EXPECT_GT(outside_pixels, 100);
  }
}

// ---------------------------------------------------------------- 6. anisotropic roughness

// The luminance-weighted second moments of the pixels brighter than `fraction` of the brightest:
// returns (var_x, var_y, angle of the principal axis from the image x axis in degrees, in (-90, 90]).
struct Moments {
  double var_x, var_y, cov, axis_degrees;
};
Moments highlight_moments(const Image& img, double fraction) {
  double brightest = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) brightest = std::max(brightest, double(img.at(x, y).luminance()));
  double w = 0, mx = 0, my = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      double v = img.at(x, y).luminance();
      if (v < fraction * brightest) continue;
      w += v;
      mx += v * x;
      my += v * y;
    }
  mx /= w;
  my /= w;
  Moments m{0, 0, 0, 0};
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      double v = img.at(x, y).luminance();
      if (v < fraction * brightest) continue;
      m.var_x += v * (x - mx) * (x - mx);
      m.var_y += v * (y - my) * (y - my);
      m.cov += v * (x - mx) * (y - my);
    }
  m.var_x /= w;
  m.var_y /= w;
  m.cov /= w;
  m.axis_degrees = 0.5 * std::atan2(2 * m.cov, m.var_x - m.var_y) * 180 / kPi;
  return m;
}

TEST(MaterialLightRender, AnisotropicRoughnessFollowsTheSurfaceUDirection) {
  // A white rough conductor square (u along world +z, v along world +x; normal +y) under a small
  // sphere light straight above, seen from straight above: the camera's image x axis is world -x
  // (v) and its y axis world -z (u). The highlight is where the half vector can tilt far enough:
  // elongated along the direction with the larger alpha. alpha_u 0.05, alpha_v 0.4 stretches it
  // along v, across the image; swapping the two turns it by 90 degrees, along the image's columns.
  auto render_highlight = [](float alpha_u, float alpha_v) {
    SceneDesc d;
    d.film = {kSize, kSize, ""};
    d.camera = look_at_camera({0, 1.5f, 0}, {0, 0, 0}, 90);
    d.settings.spp = 32;
    d.settings.max_depth = 2;
    ConductorMaterial metal;
    metal.reflectance = ColorInput(RGB(1.0f));
    metal.roughness = Roughness{alpha_u, alpha_v, false};
    d.materials = {metal, BlackMaterial{}};
    ShapeDesc square;
    square.geometry = RectangleShape{{-4, 0, -4}, {0, 0, 8}, {8, 0, 0}};
    square.material = 0;
    ShapeDesc lamp;
    lamp.geometry = SphereShape{{0, 3, 0}, 0.15f};
    lamp.material = 1;
    lamp.emission = AreaEmission{RGB(50.0f), false};
    d.shapes = {square, lamp};
    return render_description(d).mean_image();
  };
  Moments along_v = highlight_moments(render_highlight(0.05f, 0.4f), 0.1);
  Moments along_u = highlight_moments(render_highlight(0.4f, 0.05f), 0.1);
  // Elongated along image x (v), then along image y (u), each by a clear margin.
  EXPECT_GT(along_v.var_x, 4 * along_v.var_y) << "var_x " << along_v.var_x << ", var_y " << along_v.var_y;
  EXPECT_LT(std::abs(along_v.axis_degrees), 10) << along_v.axis_degrees;
  EXPECT_GT(along_u.var_y, 4 * along_u.var_x) << "var_x " << along_u.var_x << ", var_y " << along_u.var_y;
  EXPECT_GT(std::abs(along_u.axis_degrees), 80) << along_u.axis_degrees;
}

}  // namespace
}  // namespace candela
