// The lights Mitsuba 3 scenes need: disk and cylinder area lights (uniform area sampling, checked by
// the analytic irradiance at a point on a disk's axis and inside a tube, and by the solid-angle pdf
// integrating to one over what the point sees), Mitsuba's spot light (its falloff curve, its power,
// its projected texture's orientation) and the projector (irradiance on a plane facing it, power),
// with the emission sampling of all of them against pdf_le (chi-square) and power(); and pbrt-v4's
// partial spheres and cylinders (zmin, zmax, phimax), sampled uniformly over the part kept.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "candela/lights/light.h"
#include "candela/sampling/rng.h"
#include "candela/scene/scene.h"
#include "candela/testing/statistics.h"
#include "candela/testing/temp_image_file.h"

namespace candela {
namespace {

using testing::Estimate;

// The mean of f(u) over n uniform points u of the unit square (seeded by `seed`).
template <typename F>
Estimate estimate(int n, uint64_t seed, F&& f) {
  Rng rng(seed, 5);
  return testing::sample_mean(n, [&] { return double(f(Vec2{rng.next_float(), rng.next_float()})); });
}
void expect_estimate(const Estimate& e, double expected, const std::string& what, double rel = 1e-4) {
  EXPECT_NEAR(e.mean, expected, 4.5 * e.standard_error + rel * std::abs(expected))
      << what << ": " << e.mean << " +- " << e.standard_error;
}

// Irradiance at ctx from light sampling: E[L cos / pdf] (every sample visible in these set-ups).
Estimate irradiance(const Light& light, const LightSampleContext& ctx, int n = 400000) {
  return estimate(n, 17, [&](Vec2 u) {
    LightSample ls = light_sample_li(light, ctx, u);
    if (!(ls.pdf > 0)) return 0.0;
    return double(ls.radiance.luminance()) * std::max(0.0f, dot(ctx.n, ls.wi)) / double(ls.pdf);
  });
}

// The integral over the sphere of directions of pdf_li at the first surface each direction hits
// (uniform directions, scene intersection): 1 when the point sees every point of the light once.
Estimate pdf_integral(const Scene& scene, const Light& light, const Point3& p) {
  return estimate(400000, 23, [&](Vec2 u) {
    Vec3 w = square_to_uniform_sphere(u);
    SurfaceHit hit;
    if (!scene.intersect(Ray{p, w, std::numeric_limits<float>::infinity(), 0}, hit)) return 0.0;
    return double(light_pdf_li(light, {p, Normal3(0.0f)}, w, hit.p, hit.ng)) / double(uniform_sphere_pdf());
  });
}

const SceneSphere kSphere{{0, 0, 0}, 10};

// Chi-square of sample_le's directions (fixed u_pos) against pdf_le, in a frame around `axis`.
double emission_chi_square(const Light& light, Vec2 u_pos, const Vec3& axis, float z_min = -1, int resolution = 12) {
  LightEmission ref = light_sample_le(light, u_pos, {0.37f, 0.61f}, kSphere);
  Frame frame(normalize(axis));
  auto sample = [&](Vec2 u) {
    LightEmission e = light_sample_le(light, u_pos, u, kSphere);
    return e.pdf_dir > 0 ? frame.to_local(e.w) : Vec3(0.0f);
  };
  auto pdf = [&](const Vec3& local) { return light_pdf_le(light, ref.p, ref.n, frame.to_world(local), kSphere).dir; };
  return testing::spherical_chi_square_p_value(sample, pdf, testing::kChiSquareSamples, 71, z_min, 20, 40, resolution);
}

// sample_le's densities are pdf_le's, and radiance |cos| / (pdf_pos pdf_dir) estimates power().
void expect_emission_consistent(const Light& light, const std::string& what) {
  Rng rng(9, 10);
  for (int i = 0; i < 20000; ++i) {
    LightEmission e = light_sample_le(light, {rng.next_float(), rng.next_float()},
                                      {rng.next_float(), rng.next_float()}, kSphere);
    if (!(e.pdf_dir > 0)) continue;
    EmissionPdf pdf = light_pdf_le(light, e.p, e.n, e.w, kSphere);
    ASSERT_NEAR(pdf.pos, e.pdf_pos, 1e-5f * e.pdf_pos) << what;
    ASSERT_NEAR(pdf.dir, e.pdf_dir, 2e-3f * e.pdf_dir) << what;
  }
  Rng r2(11, 12);
  Estimate power = estimate(400000, 29, [&](Vec2 u) {
    LightEmission e = light_sample_le(light, {r2.next_float(), r2.next_float()}, u, kSphere);
    if (!(e.pdf_dir > 0 && e.pdf_pos > 0)) return 0.0;
    double c = e.n == Normal3(0.0f) ? 1.0 : std::abs(dot(e.n, e.w));
    return double(e.radiance.luminance()) * c / (double(e.pdf_pos) * double(e.pdf_dir));
  });
  expect_estimate(power, light_power(light), what + " power", 2e-3);
}

SceneDesc emitter_scene(ShapeGeometry g, const Transform& to_world, bool reverse, RGB L = RGB(2.0f)) {
  SceneDesc d;
  ShapeDesc s;
  s.geometry = std::move(g);
  s.to_world = to_world;
  s.reverse_orientation = reverse;
  s.emission = AreaEmission{L, false};
  d.shapes = {s};
  return d;
}

// ---------------------------------------------------------------- disks and cylinders

TEST(QuadricLights, DiskLightGivesTheAnalyticIrradianceOnItsAxis) {
  const float R = 1.5f, h = 2.0f, L = 2.0f;
  const Transform rot = Transform::translate({0.5f, 1, -1}) * Transform::rotate(40, normalize(Vec3(1, 1, 0)));
  Scene scene(emitter_scene(DiskShape{}, rot * Transform::scale({R, R, 1}), false));
  ASSERT_EQ(scene.lights().size(), 1u);
  const Light& light = scene.lights()[0];
  ASSERT_TRUE(std::holds_alternative<DiskLight>(light));
  Normal3 n = normalize(rot.normal({0, 0, 1}));
  Point3 c = rot.point(Point3(0.0f));
  // In front: pi L R^2 / (R^2 + h^2). Behind a one-sided disk: nothing.
  expect_estimate(irradiance(light, {c + n * h, -n}), kPi * L * R * R / (R * R + h * h), "disk on its axis");
  EXPECT_EQ(irradiance(light, {c - n * h, n}, 1000).mean, 0) << "behind the disk";
  EXPECT_NEAR(light_power(light), L * kPi * R * R * kPi, 1e-3f);
}

TEST(QuadricLights, DiskLightPdfIntegratesToOneUnderASkewedTransform) {
  Matrix4 shear = Matrix4::identity();
  shear.m[0][1] = 0.4;
  Transform T = Transform::rotate(25, normalize(Vec3(1, -1, 2))) * *Transform::from_matrix(shear) *
                Transform::scale({2, 0.6f, 1});
  Scene scene(emitter_scene(DiskShape{}, T, false));
  const Light& light = scene.lights()[0];
  Normal3 n = normalize(T.normal({0, 0, 1}));
  Point3 p = T.point({0.3f, -0.2f, 0}) + n * 1.2f;
  expect_estimate(pdf_integral(scene, light, p), 1.0, "skewed disk", 2e-3);
  // The light's samples are where pdf_li says they are.
  Rng rng(1, 2);
  for (int i = 0; i < 1000; ++i) {
    LightSample ls = light_sample_li(light, {p, Normal3(0.0f)}, {rng.next_float(), rng.next_float()});
    ASSERT_GT(ls.pdf, 0);
    SurfaceHit hit;
    ASSERT_TRUE(scene.intersect(Ray{p, ls.wi, std::numeric_limits<float>::infinity(), 0}, hit));
    EXPECT_NEAR(hit.t, ls.distance, 1e-3f * ls.distance);
    EXPECT_NEAR(light_pdf_li(light, {p, Normal3(0.0f)}, ls.wi, hit.p, hit.ng), ls.pdf, 1e-3f * ls.pdf);
  }
}

TEST(QuadricLights, InwardCylinderLightGivesTheAnalyticIrradianceAtItsCentre) {
  // A tube of radius R from z = -H to H emitting inwards; at the centre, facing +z, the wall covers
  // theta in [atan(R / H), pi / 2]: E = pi L H^2 / (H^2 + R^2).
  const float R = 0.8f, H = 1.5f, L = 3.0f;
  const Transform place = Transform::translate({1, 2, 3}) * Transform::rotate(60, normalize(Vec3(0, 1, 1)));
  Scene scene(emitter_scene(CylinderShape{{0, 0, -H}, {0, 0, H}, R}, place, true, RGB(L)));
  const Light& light = scene.lights()[0];
  ASSERT_TRUE(std::holds_alternative<CylinderLight>(light));
  Point3 c = place.point(Point3(0.0f));
  Vec3 axis = normalize(place.vector({0, 0, 1}));
  expect_estimate(irradiance(light, {c, axis}), kPi * L * H * H / (H * H + R * R), "inside the tube");
  EXPECT_NEAR(light_power(light), L * 2 * kPi * R * 2 * H * kPi, 1e-3f * light_power(light));
  // From any point inside, every point of the wall is seen once.
  Point3 p = place.point({0.3f, -0.2f, 0.7f});
  expect_estimate(pdf_integral(scene, light, p), 1.0, "pdf inside the tube", 2e-3);
  // Outward (not reversed) it lights nothing inside.
  Scene outward(emitter_scene(CylinderShape{{0, 0, -H}, {0, 0, H}, R}, place, false, RGB(L)));
  EXPECT_EQ(irradiance(outward.lights()[0], {c, axis}, 1000).mean, 0);
}

TEST(QuadricLights, DiskAndCylinderEmissionFollowPdfLeAndPower) {
  Scene disk(emitter_scene(DiskShape{}, Transform::rotate(30, {1, 0, 0}) * Transform::scale({1.5f, 0.7f, 1}), false));
  Scene tube(emitter_scene(CylinderShape{{0, 0, 0}, {0, 1, 2}, 0.5f}, Transform::translate({1, 0, 0}), false));
  const Light& dl = disk.lights()[0];
  const Light& tl = tube.lights()[0];
  LightEmission de = light_sample_le(dl, {0.3f, 0.8f}, {0.5f, 0.5f}, kSphere);
  EXPECT_GT(emission_chi_square(dl, {0.3f, 0.8f}, de.n), testing::kChiSquareAlpha);
  LightEmission te = light_sample_le(tl, {0.3f, 0.8f}, {0.5f, 0.5f}, kSphere);
  EXPECT_GT(emission_chi_square(tl, {0.3f, 0.8f}, te.n), testing::kChiSquareAlpha);
  expect_emission_consistent(dl, "disk");
  expect_emission_consistent(tl, "cylinder");
}

// ---------------------------------------------------------------- pbrt-v4's partial spheres and cylinders

SphereShape partial_sphere(float radius, float z_min, float z_max, float phi_max, SphereUv uv = SphereUv::Pbrt) {
  SphereShape s{{0, 0, 0}, radius, uv};
  s.z_min = z_min;
  s.z_max = z_max;
  s.z_min_given = s.z_max_given = true;
  s.phi_max = phi_max;
  return s;
}

TEST(PartialQuadricLights, InwardDomeGivesTheAnalyticIrradianceAtItsCentre) {
  // The upper half of a sphere emitting inwards covers, seen from its centre facing the pole, the
  // whole hemisphere of directions: E = pi L; cut to phi <= 180 degrees, half of it by symmetry.
  const float R = 1.3f, L = 2.5f;
  const Transform place = Transform::translate({1, 2, 3}) * Transform::rotate(60, normalize(Vec3(0, 1, 1))) *
                          Transform::scale(Vec3(1.5f));
  const Point3 c = place.point(Point3(0.0f));
  const Vec3 pole = normalize(place.vector({0, 0, 1}));
  for (float phi_max : {360.0f, 180.0f}) {
    Scene scene(emitter_scene(partial_sphere(R, 0, R, phi_max), place, true, RGB(L)));
    ASSERT_EQ(scene.lights().size(), 1u);
    const Light& light = scene.lights()[0];
    ASSERT_TRUE(std::holds_alternative<PartialSphereLight>(light));
    const float fraction = phi_max / 360;
    expect_estimate(irradiance(light, {c, pole}), kPi * L * fraction, "inside the dome", 2e-3);
    // Area phimax r (zmax - zmin) (Archimedes), in the world (scaled by 1.5).
    const float area = radians(phi_max) * (1.5f * R) * (1.5f * R);
    EXPECT_NEAR(light_power(light), L * area * kPi, 1e-4f * light_power(light));
  }
}

TEST(PartialQuadricLights, PartialSpherePdfIntegratesToOneWhereverItIsSeenFrom) {
  // A band of a sphere (-0.4 <= z <= 0.9 of radius 1.2) cut to 250 degrees, two-sided: from inside,
  // every point of it is seen once along some direction, so pdf_li over the sphere of directions
  // integrates to one. From inside and outside (through the cuts), its samples are where the rays
  // land, with pdf_li's density.
  const Transform place = Transform::translate({0.5f, -1, 2}) * Transform::rotate(-35, normalize(Vec3(1, 0.5f, 0)));
  SceneDesc d = emitter_scene(partial_sphere(1.2f, -0.4f, 0.9f, 250), place, false);
  d.shapes[0].emission->two_sided = true;
  Scene scene(d);
  const Light& light = scene.lights()[0];
  ASSERT_TRUE(std::holds_alternative<PartialSphereLight>(light));
  for (Point3 p : {place.point({0.1f, 0.2f, -0.1f}), place.point({0.5f, -0.5f, 0.7f})})
    expect_estimate(pdf_integral(scene, light, p), 1.0, "partial sphere", 3e-3);
  for (Point3 p : {place.point({0.1f, 0.2f, -0.1f}), place.point({0, 0, 3}), place.point({-2, 1.5f, 0.3f})}) {
    Rng rng(1, 2);
    int checked = 0;
    for (int i = 0; i < 1000; ++i) {
      LightSample ls = light_sample_li(light, {p, Normal3(0.0f)}, {rng.next_float(), rng.next_float()});
      ASSERT_GT(ls.pdf, 0);
      SurfaceHit hit;
      ASSERT_TRUE(scene.intersect(Ray{p, ls.wi, std::numeric_limits<float>::infinity(), 0}, hit));
      // The first surface along the direction is the sample, unless the band hides it behind itself
      // (or, for a ray all but tangent to the sphere, the other root lies just before it). At grazing
      // angles (|cos| < 0.05) where the ray lands is too uncertain in float for a 1e-3 match.
      if (length(hit.p - ls.p_light) < 1e-4f * ls.distance) {
        if (std::abs(dot(ls.n_light, ls.wi)) > 0.05f) {
          EXPECT_NEAR(light_pdf_li(light, {p, Normal3(0.0f)}, ls.wi, hit.p, hit.ng), ls.pdf, 1e-3f * ls.pdf);
          ++checked;
        }
      } else {
        EXPECT_LT(hit.t, ls.distance * (1 + 1e-4f));
      }
    }
    EXPECT_GT(checked, 300);
  }
}

TEST(PartialQuadricLights, PartialSphereAndCylinderEmissionFollowPdfLeAndPower) {
  Scene band(emitter_scene(partial_sphere(0.8f, -0.3f, 0.6f, 200), Transform::rotate(30, {1, 0, 0}), false));
  Scene tube(emitter_scene(CylinderShape{{0, 0, 0}, {0, 1, 2}, 0.5f, 120}, Transform::translate({1, 0, 0}), true));
  const Light& bl = band.lights()[0];
  const Light& tl = tube.lights()[0];
  LightEmission be = light_sample_le(bl, {0.3f, 0.8f}, {0.5f, 0.5f}, kSphere);
  EXPECT_GT(emission_chi_square(bl, {0.3f, 0.8f}, be.n), testing::kChiSquareAlpha);
  LightEmission te = light_sample_le(tl, {0.3f, 0.8f}, {0.5f, 0.5f}, kSphere);
  EXPECT_GT(emission_chi_square(tl, {0.3f, 0.8f}, te.n), testing::kChiSquareAlpha);
  expect_emission_consistent(bl, "partial sphere");
  expect_emission_consistent(tl, "partial cylinder");
  // pbrt-v4's areas: phimax r (zmax - zmin) for both.
  EXPECT_NEAR(light_power(bl), 2.0f * radians(200) * 0.8f * 0.9f * kPi, 1e-4f * light_power(bl));
  EXPECT_NEAR(light_power(tl), 2.0f * radians(120) * 0.5f * std::sqrt(5.0f) * kPi, 1e-4f * light_power(tl));
}

TEST(PartialQuadricLights, InwardPartialCylinderGivesItsShareOfTheTubesIrradiance) {
  // As InwardCylinderLightGivesTheAnalyticIrradianceAtItsCentre, the tube cut to 90 degrees: a
  // quarter of the whole tube's irradiance along the axis (the integrand does not depend on phi).
  const float R = 0.8f, H = 1.5f, L = 3.0f;
  const Transform place = Transform::translate({1, 2, 3}) * Transform::rotate(60, normalize(Vec3(0, 1, 1)));
  Scene scene(emitter_scene(CylinderShape{{0, 0, -H}, {0, 0, H}, R, 90}, place, true, RGB(L)));
  const Light& light = scene.lights()[0];
  ASSERT_TRUE(std::holds_alternative<CylinderLight>(light));
  Point3 c = place.point(Point3(0.0f));
  Vec3 axis = normalize(place.vector({0, 0, 1}));
  expect_estimate(irradiance(light, {c, axis}), 0.25 * kPi * L * H * H / (H * H + R * R), "inside the quarter tube");
  EXPECT_NEAR(light_power(light), L * (kPi / 2) * R * 2 * H * kPi, 1e-4f * light_power(light));
  // Seen from outside, through the cut: every point of the wall once.
  expect_estimate(pdf_integral(scene, light, place.point({-1.5f, -1, 0.4f})), 1.0, "pdf through the cut", 3e-3);
  expect_estimate(pdf_integral(scene, light, place.point({0.2f, 0.3f, -0.5f})), 1.0, "pdf inside", 3e-3);
}

// ---------------------------------------------------------------- Mitsuba's spot light

// Mitsuba 3's spot.cpp falloff, written out: 1 inside the beam, linear in the angle to the cutoff.
double mitsuba_spot_falloff(double theta, double beam, double cutoff) {
  if (theta >= cutoff) return 0;
  if (theta <= beam) return 1;
  return (cutoff - theta) / (cutoff - beam);
}

SpotLight mitsuba_spot_desc() {
  SpotLight s;
  s.position = {0.5f, 1, -2};
  s.direction = normalize(Vec3(0.3f, -1, 0.2f));
  s.intensity = RGB(4.0f, 2.0f, 1.0f);
  s.cone_angle = 35;  // Mitsuba's cutoff_angle
  s.cone_delta = 15;  // beam_width = 20
  s.falloff = SpotFalloff::Linear;
  return s;
}

TEST(MitsubaSpotLight, FalloffIsMitsubasLinearRampInTheAngle) {
  SpotLight desc = mitsuba_spot_desc();
  SpotLightSource spot = make_spot_light(desc);
  Frame f(normalize(desc.direction));
  const double beam = radians(20), cutoff = radians(35);
  for (int i = 0; i <= 400; ++i) {
    double theta = radians(45) * i / 400;
    Vec3 w = f.to_world(Vec3(float(std::sin(theta)), 0, float(std::cos(theta))));
    EXPECT_NEAR(spot.falloff(w), mitsuba_spot_falloff(theta, beam, cutoff), 2e-4) << "theta " << theta;
    // And what a point at distance 2 along w receives: I falloff / d^2.
    LightSample ls = spot.sample_li({desc.position + w * 2, Normal3(0.0f)}, {});
    EXPECT_NEAR(ls.pdf > 0 ? ls.radiance.r : 0.0f, 4 * mitsuba_spot_falloff(theta, beam, cutoff) / 4, 2e-4);
  }
  // Power: I 2 pi (1 - (sin(cutoff) - sin(beam)) / (cutoff - beam)), the ramp integrated in closed form.
  double expected = RGB(4.0f, 2.0f, 1.0f).luminance() * 2 * kPi * (1 - (std::sin(cutoff) - std::sin(beam)) / (cutoff - beam));
  EXPECT_NEAR(light_power(Light(spot)), expected, 1e-4 * expected);
  expect_emission_consistent(Light(spot), "mitsuba spot");
}

TEST(MitsubaSpotLight, ProjectedTextureFollowsMitsubasUv) {
  // A 2x2 checkerboard over the uv square: uv = (1/2 + x / (2 z tan c), 1/2 + y / (2 z tan c)) in
  // the frame x = up x axis, y = axis x x. Pointing along +z with up +y: x is world +x.
  std::vector<TextureDesc> texs{CheckerboardTexture{RGB(1.0f), RGB(0.25f), UVMapping{2, 2, 0, 0}}};
  TextureSet textures(texs);
  SpotLight desc;
  desc.position = {0, 0, 0};
  desc.direction = {0, 0, 1};
  desc.up = {0, 1, 0};
  desc.intensity = RGB(1.0f);
  desc.cone_angle = 40;
  desc.cone_delta = 40;  // beam 0: the ramp all the way
  desc.falloff = SpotFalloff::Linear;
  desc.texture = 0;
  SpotLightSource spot = make_spot_light(desc, &textures);
  const float t = std::tan(radians(40));
  for (float sx : {-1.0f, 1.0f})
    for (float sy : {-1.0f, 1.0f}) {
      // Directions at a quarter of the way to the cone's edge in x and y.
      Vec3 w = normalize(Vec3(sx * 0.25f * t, sy * 0.25f * t, 1));
      Vec2 uv{0.5f + 0.5f * w.x / (w.z * t), 0.5f + 0.5f * w.y / (w.z * t)};
      bool even = (int(std::floor(2 * uv.x)) + int(std::floor(2 * uv.y))) % 2 == 0;
      float falloff = spot.falloff(w);
      EXPECT_NEAR(spot.intensity_towards(w).g, falloff * (even ? 1.0f : 0.25f), 1e-5f) << sx << " " << sy;
    }
  // The power integrates the texture too: the checks average (1 + 0.25) / 2 by symmetry.
  const double cutoff = radians(40);
  double untextured = 2 * kPi * (1 - std::sin(cutoff) / cutoff);
  EXPECT_NEAR(light_power(Light(spot)), untextured * 0.625, 2e-3 * untextured);
  EXPECT_GT(emission_chi_square(Light(spot), {0.5f, 0.5f}, desc.direction, float(std::cos(cutoff)) - 0.05f),
            testing::kChiSquareAlpha);
  expect_emission_consistent(Light(spot), "textured mitsuba spot");
}

// ---------------------------------------------------------------- projector

// A 4 x 3 image with a black texel, read without filtering.
Image projector_image() {
  Image img(4, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) img.set(x, y, RGB(0.5f + x, 1.0f + 0.5f * y, (x == 2 && y == 1) ? 0.0f : 2.0f));
  img.set(1, 2, RGB(0.0f));
  return img;
}

// A set of one texture: the image in `file`, read as linear values.
TextureSet linear_texture(const std::string& file, bool bilinear, TextureWrap wrap) {
  ImageTexture tex;
  tex.filename = file;
  tex.encoding = ColorEncoding::Linear;
  tex.filter = bilinear ? TextureFilter::Bilinear : TextureFilter::Nearest;
  tex.wrap = wrap;
  return TextureSet(std::vector<TextureDesc>{tex});
}

TEST(ProjectorLight, IrradianceOnAPlaneFacingItIsPiTimesScaleTimesTheImage) {
  Image img = projector_image();
  testing::TempImageFile file(img, "projector");
  TextureSet textures = linear_texture(file.path(), false, TextureWrap::Clamp);
  ProjectorLight desc;
  desc.to_world = Transform::translate({1, 2, 3}) * Transform::rotate(50, normalize(Vec3(1, 2, 3)));
  desc.fov_degrees = 70;  // on the wider axis, x; y from the aspect 4 : 3
  desc.irradiance = 0;
  desc.scale = RGB(2.0f, 1.0f, 0.5f);
  ProjectorLightSource p = make_projector_light(desc, &textures);
  const float tan_x = std::tan(radians(35)), tan_y = tan_x * 3 / 4;
  EXPECT_NEAR(p.tan_y, tan_y, 1e-6f);
  const Normal3 facing = normalize(desc.to_world.vector({0, 0, -1}));
  Rng rng(7, 8);
  for (int i = 0; i < 2000; ++i) {
    // A point on the plane z = depth of the projector's space, inside the image or a little outside.
    float depth = 0.5f + 2 * rng.next_float();
    float x = (2 * rng.next_float() - 1) * 1.1f * tan_x * depth, y = (2 * rng.next_float() - 1) * 1.1f * tan_y * depth;
    Point3 q = desc.to_world.point({x, y, depth});
    LightSample ls = p.sample_li({q, facing}, {});
    // Mitsuba's uv, and the texel a candela image texture reads there (t = 0 is the bottom row).
    float u = 0.5f - 0.5f * x / (depth * tan_x), v = 0.5f - 0.5f * y / (depth * tan_y);
    bool inside = u >= 0 && u <= 1 && v >= 0 && v <= 1;
    if (!inside) {
      EXPECT_EQ(ls.pdf, 0) << "outside the image at uv " << u << " " << v;
      continue;
    }
    RGB texel = img.at(std::min(3, int(u * 4)), std::min(2, int((1 - v) * 3)));
    // E = L cos(theta) on the plane facing it; Mitsuba's definition makes E = pi scale image at
    // unit depth and falls off as 1 / depth^2.
    RGB expected = texel * desc.scale * (kPi / (depth * depth));
    if (expected.is_black()) {
      EXPECT_TRUE(!(ls.pdf > 0) || ls.radiance.is_black());
      continue;
    }
    ASSERT_GT(ls.pdf, 0);
    ASSERT_TRUE(ls.is_delta);
    float cos_theta = dot(facing, ls.wi);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(ls.radiance[c] * cos_theta, expected[c], 1e-4f * expected[c] + 1e-6f) << "uv " << u << " " << v;
    EXPECT_NEAR(ls.distance, length(q - p.position), 1e-4f);
  }
  // Power: pi times the image's integral over the unit-depth image plane.
  double mean = 0;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) mean += (img.at(x, y) * desc.scale).luminance() / 12.0;
  EXPECT_NEAR(light_power(Light(p)), kPi * 4 * tan_x * tan_y * mean, 1e-4 * light_power(Light(p)));
}

TEST(ProjectorLight, EmissionIsImportanceSampledWithTheRightDensity) {
  testing::TempImageFile file(projector_image(), "projector");
  TextureSet textures = linear_texture(file.path(), true, TextureWrap::Repeat);
  ProjectorLight desc;
  desc.to_world = Transform::rotate(-30, normalize(Vec3(2, 1, 0)));
  desc.fov_degrees = 50;
  desc.irradiance = 0;
  ProjectorLightSource p = make_projector_light(desc, &textures);
  Vec3 axis = normalize(desc.to_world.vector({0, 0, 1}));
  float z_min = 1 / std::sqrt(1 + p.tan_x * p.tan_x + p.tan_y * p.tan_y);
  EXPECT_GT(emission_chi_square(Light(p), {0.5f, 0.5f}, axis, z_min - 0.02f, 48), testing::kChiSquareAlpha);
  expect_emission_consistent(Light(p), "projector");
  // Without an image: a constant 1 over a square image.
  desc.irradiance = -1;
  ProjectorLightSource plain = make_projector_light(desc, &textures);
  EXPECT_NEAR(plain.tan_x, plain.tan_y, 1e-6f);
  expect_emission_consistent(Light(plain), "untextured projector");
}

}  // namespace
}  // namespace candela
