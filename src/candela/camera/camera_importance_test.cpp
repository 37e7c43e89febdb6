// The camera as a sensor of importance (for light paths): importance() maps generate_ray's rays back
// to their film positions and has the closed form 1 / (A_film A_lens cos^4), zero off the film and its
// margin; it integrates (times cos) to 1 over the lens and directions; pdf_importance is the density
// of generate_ray's directions (chi-square) and integrates to 1; sample_lens is consistent with both.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "candela/camera/camera.h"
#include "candela/math/frame.h"
#include "candela/math/transform.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/testing/statistics.h"

namespace candela {
namespace {

struct CameraCase {
  std::string name;
  float fov_degrees;
  FovAxis axis;
  int width, height;
  Vec2 margin;
  float lens_radius = 0, focus_distance = 1e6f;
  Transform world_from_camera;
};

std::vector<CameraCase> camera_cases() {
  Transform look = Transform::look_at_right_handed({1, 2, -3}, {0.5f, 1.2f, 2}, {0.1f, 1, 0});
  Transform look2 = Transform::look_at_right_handed({-2, 0.5f, 1}, {3, -1, 2}, {0, 0, 1});
  return {
      {"pinhole, fov y, 120x80", 60, FovAxis::Y, 120, 80, {0, 0}, 0, 1e6f, Transform()},
      {"pinhole, fov x, 90x150, margin", 50, FovAxis::X, 90, 150, {12, 7.5f}, 0, 1e6f, look},
      {"pinhole, smaller axis, 100x64, margin", 70, FovAxis::Smaller, 100, 64, {3, 3}, 0, 1e6f, look2},
      {"thin lens, fov y, 120x80, margin", 55, FovAxis::Y, 120, 80, {10, 6}, 0.15f, 3.5f, look},
      {"thin lens, diagonal, 64x96, margin", 65, FovAxis::Diagonal, 64, 96, {2.5f, 4}, 0.3f, 2, look2},
      {"thin lens, larger axis, 80x50", 45, FovAxis::Larger, 80, 50, {0, 0}, 0.05f, 8, Transform()},
  };
}

PerspectiveCamera make_camera(const CameraCase& c) {
  CameraDesc d;
  d.fov_degrees = c.fov_degrees;
  d.fov_axis = c.axis;
  d.lens_radius = c.lens_radius;
  d.focus_distance = c.focus_distance;
  d.world_from_camera = c.world_from_camera;
  return PerspectiveCamera(d, c.width, c.height, c.margin);
}

// Half the screen window at unit distance, from the definitions of the fov axes (square pixels).
Vec2 tan_half(const CameraCase& c) {
  float t = std::tan(radians(c.fov_degrees) / 2), aspect = float(c.width) / float(c.height);
  FovAxis axis = c.axis;
  if (axis == FovAxis::Smaller) axis = c.width < c.height ? FovAxis::X : FovAxis::Y;
  if (axis == FovAxis::Larger) axis = c.width < c.height ? FovAxis::Y : FovAxis::X;
  switch (axis) {
    case FovAxis::X: return {t, t / aspect};
    case FovAxis::Y: return {t * aspect, t};
    default: {  // the diagonal of the window spans the fov
      float ty = t / std::sqrt(aspect * aspect + 1);
      return {ty * aspect, ty};
    }
  }
}

// The film with its margin, on the plane at unit distance.
float film_area(const CameraCase& c) {
  Vec2 t = tan_half(c);
  return 4 * t.x * t.y * (c.width + 2 * c.margin.x) * (c.height + 2 * c.margin.y) / (float(c.width) * c.height);
}

float lens_area(const CameraCase& c) { return c.lens_radius > 0 ? kPi * c.lens_radius * c.lens_radius : 1.0f; }

// Where the ray from the world point `lens` through the world point `ref` lands on the film,
// computed in camera space: the plane of focus (unit plane for a pinhole) fixes the raster position.
Vec2 project(const CameraCase& c, const Point3& lens, const Point3& ref) {
  Transform cam = c.world_from_camera.inverse();
  Point3 pl = cam.point(lens), pr = cam.point(ref);
  float f = c.lens_radius > 0 ? c.focus_distance : 1.0f;
  Point3 q = pl + (pr - pl) * ((f - pl.z) / (pr.z - pl.z));
  Vec2 t = tan_half(c);
  return {(q.x / f / t.x + 1) * 0.5f * c.width, (1 - q.y / f / t.y) * 0.5f * c.height};
}

bool inside_film(const CameraCase& c, Vec2 r, float slack = 0) {
  return r.x >= -c.margin.x + slack && r.x < c.width + c.margin.x - slack && r.y >= -c.margin.y + slack &&
         r.y < c.height + c.margin.y - slack;
}

TEST(CameraImportance, MapsGeneratedRaysBackToTheirFilmPositions) {
  for (const CameraCase& c : camera_cases()) {
    PerspectiveCamera cam = make_camera(c);
    EXPECT_EQ(cam.margin().x, c.margin.x);
    EXPECT_EQ(cam.margin().y, c.margin.y);
    EXPECT_NEAR(cam.importance_film_pixels(), (c.width + 2 * c.margin.x) * (c.height + 2 * c.margin.y), 1e-3f);
    EXPECT_NEAR(cam.lens_area(), lens_area(c), 1e-6f * lens_area(c));
    const float a_film = film_area(c);
    Rng rng(1, 2);
    for (int i = 0; i < 5000; ++i) {
      // Anywhere on the film or its margin (a little away from the outer edge).
      Vec2 film{-c.margin.x + 1e-3f + rng.next_float() * (c.width + 2 * c.margin.x - 2e-3f),
                -c.margin.y + 1e-3f + rng.next_float() * (c.height + 2 * c.margin.y - 2e-3f)};
      Vec2 lens{rng.next_float(), rng.next_float()};
      Ray ray = cam.generate_ray(film, lens, 0.5f);
      Vec3 w = normalize(ray.direction);
      Vec2 raster{-1e9f, -1e9f};
      float we = cam.importance(ray.origin, w, &raster);
      ASSERT_GT(we, 0) << c.name << " film " << film.x << " " << film.y;
      ASSERT_NEAR(raster.x, film.x, 1e-3f) << c.name;
      ASSERT_NEAR(raster.y, film.y, 1e-3f) << c.name;
      float cos_theta = dot(w, cam.forward());
      float expected = 1 / (a_film * lens_area(c) * std::pow(cos_theta, 4.0f));
      ASSERT_NEAR(we, expected, 1e-4f * expected) << c.name;
      // Without a raster pointer it is the same value.
      ASSERT_EQ(cam.importance(ray.origin, w, nullptr), we);
    }
    // Just outside the film and its margin, on every side: no importance.
    for (int i = 0; i < 2000; ++i) {
      float along = rng.next_float(), out = 0.01f + 30 * rng.next_float();
      Vec2 film;
      switch (i % 4) {
        case 0: film = {-c.margin.x - out, -c.margin.y + along * (c.height + 2 * c.margin.y)}; break;
        case 1: film = {c.width + c.margin.x + out, -c.margin.y + along * (c.height + 2 * c.margin.y)}; break;
        case 2: film = {-c.margin.x + along * (c.width + 2 * c.margin.x), -c.margin.y - out}; break;
        default: film = {-c.margin.x + along * (c.width + 2 * c.margin.x), c.height + c.margin.y + out};
      }
      Ray ray = cam.generate_ray(film, {rng.next_float(), rng.next_float()}, 0);
      ASSERT_EQ(cam.importance(ray.origin, normalize(ray.direction), nullptr), 0)
          << c.name << " film " << film.x << " " << film.y;
      ASSERT_EQ(cam.pdf_importance(ray.origin, normalize(ray.direction)).dir, 0) << c.name;
    }
    // Behind the camera.
    Ray centre = cam.generate_ray({c.width * 0.5f, c.height * 0.5f}, {0.5f, 0.5f}, 0);
    EXPECT_EQ(cam.importance(centre.origin, -normalize(centre.direction), nullptr), 0) << c.name;
  }
}

TEST(CameraImportance, IntegratesToOneOverTheLensAndDirections) {
  for (const CameraCase& c : camera_cases()) {
    PerspectiveCamera cam = make_camera(c);
    Frame frame(cam.forward());
    Rng rng(3, 4);
    const int n = 1000000;
    double sum_we = 0, sum_we2 = 0, sum_pdf = 0, sum_pdf2 = 0;
    for (int i = 0; i < n; ++i) {
      // A uniform point on the lens (density 1 / lens_area) and a uniform direction of the
      // hemisphere in front of it (density 1 / (2 pi)).
      Vec2 d = square_to_concentric_disk({rng.next_float(), rng.next_float()});
      Point3 p = c.world_from_camera.point(Point3(c.lens_radius * d.x, c.lens_radius * d.y, 0));
      Vec3 w = frame.to_world(square_to_uniform_hemisphere({rng.next_float(), rng.next_float()}));
      float cos_theta = dot(w, cam.forward());
      double we = cam.importance(p, w, nullptr);
      PerspectiveCamera::ImportancePdf pdf = cam.pdf_importance(p, w);
      if (we > 0) {
        ASSERT_NEAR(pdf.pos, 1 / lens_area(c), 1e-6f / lens_area(c)) << c.name;
        // The direction density is the importance times cos, over the lens area's density.
        ASSERT_NEAR(pdf.dir, we * cos_theta * lens_area(c), 1e-4 * pdf.dir) << c.name;
      } else {
        ASSERT_EQ(pdf.dir, 0) << c.name;
      }
      double x = we * cos_theta * lens_area(c) * 2 * kPi, y = pdf.dir * 2 * kPi;
      sum_we += x;
      sum_we2 += x * x;
      sum_pdf += y;
      sum_pdf2 += y * y;
    }
    double mean = sum_we / n, se = std::sqrt(std::max(0.0, sum_we2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, 1, 5 * se) << c.name << ": integral of W cos " << mean << " +- " << se;
    double mean_pdf = sum_pdf / n, se_pdf = std::sqrt(std::max(0.0, sum_pdf2 / n - mean_pdf * mean_pdf) / n);
    EXPECT_NEAR(mean_pdf, 1, 5 * se_pdf) << c.name << ": integral of pdf_dir " << mean_pdf << " +- " << se_pdf;
    EXPECT_LT(se, 0.01) << c.name;  // the check above means something
  }
}

TEST(CameraImportance, PdfImportanceIsTheDensityOfGeneratedDirections) {
  // Uniform film samples over the film and its margin, from one lens point: the directions follow
  // pdf_importance(lens_point, w).dir.
  for (const CameraCase& c : camera_cases()) {
    PerspectiveCamera cam = make_camera(c);
    Frame frame(cam.forward());
    const Vec2 lens{0.3f, 0.8f};
    const Point3 origin = cam.generate_ray({0, 0}, lens, 0).origin;
    float z_min = 1;
    for (Vec2 corner : {Vec2{-c.margin.x, -c.margin.y}, Vec2{c.width + c.margin.x, -c.margin.y},
                        Vec2{-c.margin.x, c.height + c.margin.y}, Vec2{c.width + c.margin.x, c.height + c.margin.y}})
      z_min = std::min(z_min, dot(normalize(cam.generate_ray(corner, lens, 0).direction), cam.forward()));
    auto sample = [&](Vec2 u) {
      Vec2 film{-c.margin.x + u.x * (c.width + 2 * c.margin.x), -c.margin.y + u.y * (c.height + 2 * c.margin.y)};
      return frame.to_local(normalize(cam.generate_ray(film, lens, 0).direction));
    };
    auto pdf = [&](const Vec3& local) { return cam.pdf_importance(origin, frame.to_world(local)).dir; };
    // The film's edges cut through the cells: integrate the pdf finely.
    EXPECT_GT(testing::spherical_chi_square_p_value(sample, pdf, testing::kChiSquareSamples, 19,
                                                    std::max(-1.0f, z_min - 0.02f), 20, 40, 64),
              testing::kChiSquareAlpha)
        << c.name;
  }
}

TEST(CameraImportance, SampleLensIsConsistentWithImportance) {
  for (const CameraCase& c : camera_cases()) {
    PerspectiveCamera cam = make_camera(c);
    Transform cam_from_world = c.world_from_camera.inverse();
    Vec2 t = tan_half(c);
    Rng rng(5, 6);
    int valid = 0, checked = 0;
    for (int i = 0; i < 5000; ++i) {
      // A point in front of the camera, mostly within the field of view (some outside it).
      Vec3 dir_cam(t.x * (2.6f * rng.next_float() - 1.3f), t.y * (2.6f * rng.next_float() - 1.3f), 1);
      float depth = 0.5f + 12 * rng.next_float();
      Point3 ref = c.world_from_camera.point(dir_cam * depth);
      Vec2 u{rng.next_float(), rng.next_float()};
      auto s = cam.sample_lens(ref, u);
      // The lens point this u picks, as generate_ray picks it.
      Vec2 d = square_to_concentric_disk(u);
      Point3 lens_point = c.lens_radius > 0
                              ? c.world_from_camera.point(Point3(c.lens_radius * d.x, c.lens_radius * d.y, 0))
                              : c.world_from_camera.point(Point3(0.0f));
      Vec2 expected_raster = project(c, lens_point, ref);
      if (!inside_film(c, expected_raster, -0.01f)) {
        EXPECT_FALSE(s) << c.name << " raster " << expected_raster.x << " " << expected_raster.y;
        continue;
      }
      if (!inside_film(c, expected_raster, 0.01f)) continue;  // too close to the edge to tell
      ++checked;
      ASSERT_TRUE(s) << c.name << " raster " << expected_raster.x << " " << expected_raster.y;
      ++valid;
      // On the lens.
      Point3 pl = cam_from_world.point(s->p);
      ASSERT_NEAR(pl.z, 0, 1e-4f) << c.name;
      ASSERT_LE(pl.x * pl.x + pl.y * pl.y, c.lens_radius * c.lens_radius * (1 + 1e-3f) + 1e-8f) << c.name;
      ASSERT_NEAR(distance(s->p, lens_point), 0, 1e-5f * (1 + length(lens_point))) << c.name;
      // Geometry: the direction and distance from ref to the lens point.
      float dist = distance(ref, s->p);
      ASSERT_NEAR(s->distance, dist, 1e-5f * dist) << c.name;
      ASSERT_NEAR(length(s->wi - (s->p - ref) / dist), 0, 1e-5f) << c.name;
      // The solid-angle pdf of the uniform lens point seen from ref.
      float cos_lens = std::abs(dot(cam.forward(), s->wi));
      float expected_pdf = dist * dist / (cos_lens * lens_area(c));
      ASSERT_NEAR(s->pdf, expected_pdf, 1e-4f * expected_pdf) << c.name;
      // The importance and raster position of the ray leaving the lens towards ref.
      Vec2 raster;
      float we = cam.importance(s->p, -s->wi, &raster);
      ASSERT_NEAR(s->importance, we, 1e-5f * we) << c.name;
      ASSERT_NEAR(s->raster.x, raster.x, 1e-4f) << c.name;
      ASSERT_NEAR(s->raster.y, raster.y, 1e-4f) << c.name;
      ASSERT_NEAR(s->raster.x, expected_raster.x, 2e-3f) << c.name;
      ASSERT_NEAR(s->raster.y, expected_raster.y, 2e-3f) << c.name;
      // generate_ray at that raster position with the same lens sample retraces the ray to ref.
      Ray back = cam.generate_ray(s->raster, u, 0);
      ASSERT_NEAR(distance(back.origin, s->p), 0, 1e-4f * (1 + length(s->p))) << c.name;
      ASSERT_NEAR(length(normalize(back.direction) + s->wi), 0, 1e-4f) << c.name;
    }
    EXPECT_GT(checked, 1500) << c.name;
    EXPECT_EQ(valid, checked) << c.name;
    // Behind the camera: nothing.
    EXPECT_FALSE(cam.sample_lens(c.world_from_camera.point(Point3(0.1f, 0.1f, -2)), {0.5f, 0.5f})) << c.name;
  }
}

}  // namespace
}  // namespace candela
