// The orthographic camera (Mitsuba's: parallel rays from the film rectangle [-1, 1] x
// [-1/aspect, 1/aspect] of camera space, scaled by world_from_camera) and the near clipping plane
// of both projections: rays start on it (Ray::t_min = near / cos), light-tracing connections ignore
// what lies in front of it, and a sphere in front of it disappears from renders.
#include <gtest/gtest.h>

#include <cmath>

#include "candela/camera/camera.h"
#include "candela/sampling/rng.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

CameraDesc orthographic_desc(const Transform& world_from_camera) {
  CameraDesc d;
  d.projection = Projection::Orthographic;
  d.world_from_camera = world_from_camera;
  d.lens_radius = 0.5f;  // ignored: no thin lens on orthographic cameras
  return d;
}

TEST(OrthographicCamera, RaysAreParallelAndCoverTheScaledFilmRectangle) {
  const int w = 80, h = 50;
  const Transform look = Transform::look_at_right_handed({1, 2, 3}, {0, 0, 0}, {0, 1, 0});
  const Transform world_from_camera = look * Transform::scale({3, 3, 2});
  Camera cam(orthographic_desc(world_from_camera), w, h);
  EXPECT_TRUE(cam.is_orthographic());
  EXPECT_TRUE(cam.is_delta_direction());
  const Vec3 forward = normalize(world_from_camera.vector({0, 0, 1}));
  Rng rng(1, 2);
  for (int i = 0; i < 1000; ++i) {
    Vec2 film{rng.next_float() * w, rng.next_float() * h};
    Ray ray = cam.generate_ray(film, {rng.next_float(), rng.next_float()}, 0.5f);
    // Unit and parallel to the camera's axis, whatever the lens sample.
    EXPECT_NEAR(length(ray.direction), 1, 1e-6f);
    EXPECT_NEAR(dot(ray.direction, forward), 1, 1e-6f);
    EXPECT_EQ(ray.t_min, 0);
    // The origin is the film position mapped to [-1, 1] x [1/aspect, -1/aspect], then to the world.
    Point3 expected = world_from_camera.point({2 * film.x / w - 1, (1 - 2 * film.y / h) * float(h) / w, 0});
    EXPECT_NEAR(distance(ray.origin, expected), 0, 1e-4f);
  }
  // The corners of the film: 3 x (+-1, +-1/aspect) around the camera position in world units.
  Point3 eye = look.point(Point3(0.0f));
  Ray top_left = cam.generate_ray({0, 0}, {0.5f, 0.5f}, 0);
  Ray bottom_right = cam.generate_ray({float(w), float(h)}, {0.5f, 0.5f}, 0);
  Transform camera_from_world = look.inverse();
  Point3 tl = camera_from_world.point(top_left.origin), br = camera_from_world.point(bottom_right.origin);
  EXPECT_NEAR(tl.x, -3, 1e-4f);
  EXPECT_NEAR(tl.y, 3.0f * h / w, 1e-4f);
  EXPECT_NEAR(br.x, 3, 1e-4f);
  EXPECT_NEAR(br.y, -3.0f * h / w, 1e-4f);
  EXPECT_NEAR(distance(cam.generate_ray({w / 2.0f, h / 2.0f}, {0, 0}, 0).origin, eye), 0, 1e-4f);
  // No connection reaches it: no importance, no lens sample.
  EXPECT_EQ(cam.importance(top_left.origin, top_left.direction, nullptr), 0);
  EXPECT_FALSE(cam.sample_lens(top_left.origin + top_left.direction * 5, {0.5f, 0.5f}).has_value());
}

TEST(NearClip, CameraRaysStartOnTheNearPlane) {
  const Transform look = Transform::look_at_right_handed({0, 0, -5}, {0, 0, 0}, {0, 1, 0});
  CameraDesc persp;
  persp.world_from_camera = look;
  persp.fov_degrees = 60;
  persp.near_clip = 2;
  Camera cam(persp, 64, 32);
  Rng rng(3, 4);
  for (int i = 0; i < 200; ++i) {
    Ray ray = cam.generate_ray({rng.next_float() * 64, rng.next_float() * 32}, {0.5f, 0.5f}, 0);
    float cos_theta = dot(normalize(ray.direction), Vec3(0, 0, 1));
    EXPECT_NEAR(ray.t_min, 2 / cos_theta, 1e-4f);  // the ray direction is unit: near / cos
    EXPECT_NEAR(ray.at(ray.t_min).z, -3, 1e-4f);
  }
  CameraDesc ortho = orthographic_desc(look * Transform::scale({1, 1, 1.5f}));
  ortho.near_clip = 2;
  Camera o(ortho, 64, 32);
  EXPECT_NEAR(o.generate_ray({10, 10}, {0, 0}, 0).t_min, 3, 1e-5f);  // camera z is scaled by 1.5
  // Light-tracing connections: nothing in front of the near plane is seen, and visibility is
  // tested from the near plane on.
  EXPECT_FALSE(cam.sample_lens({0, 0, -4}, {0.5f, 0.5f}).has_value());
  auto s = cam.sample_lens({0.1f, 0.2f, 0}, {0.5f, 0.5f});
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR(s->p_visible.z, -3, 1e-4f);
  EXPECT_NEAR(s->p.z, -5, 1e-5f);
}

// A black sphere between the camera and a uniform sky: the sky's radiance wherever the sphere
// is clipped away, black where it is not.
SceneDesc sphere_before_sky(Projection projection, float near_clip) {
  SceneDesc d;
  d.film = {8, 8, ""};
  d.camera = testing::look_at_camera({0, 0, -5}, {0, 0, 0}, 20);
  d.camera.projection = projection;
  if (projection == Projection::Orthographic)
    d.camera.world_from_camera = d.camera.world_from_camera * Transform::scale({0.5f, 0.5f, 1});
  d.camera.near_clip = near_clip;
  d.settings.spp = 4;
  d.materials = {BlackMaterial{}};
  ShapeDesc s;
  s.geometry = SphereShape{{0, 0, -3}, 1};
  s.material = 0;
  d.shapes = {s};
  d.lights = {SkyLight{RGB(0.75f), RGB(0.75f), RGB(0.75f), {0, 1, 0}}};
  return d;
}

TEST(NearClip, HidesASphereInFrontOfIt) {
  for (Projection projection : {Projection::Perspective, Projection::Orthographic})
    for (const char* integrator : {"path", "bdpt"}) {
      std::string what = std::string(projection == Projection::Perspective ? "perspective " : "orthographic ") +
                         integrator;
      SceneDesc d = sphere_before_sky(projection, 0);
      d.settings.integrator = integrator;
      Image seen = testing::render_description(d).mean_image();
      EXPECT_NEAR(seen.at(4, 4).g, 0, 1e-6f) << what << ": the sphere blocks the sky";
      d.camera.near_clip = 4.5f;  // the sphere spans distances 1 to 3 from the camera
      Image clipped = testing::render_description(d).mean_image();
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) EXPECT_NEAR(clipped.at(x, y).g, 0.75f, 1e-5f) << what << " pixel " << x << " " << y;
    }
}

}  // namespace
}  // namespace candela

namespace candela {
namespace {

// A screen window (pbrt-v4's screenwindow) places the film on the screen: camera space for an
// orthographic camera, camera space at unit distance over tan(fov / 2) for a perspective one. An
// off-centre window shifts the view; the importance of a ray maps back to the pixel it came from.
TEST(ScreenWindow, PlacesTheFilmOnTheScreenOfEitherProjection) {
  const int w = 64, h = 32;
  CameraDesc ortho;
  ortho.projection = Projection::Orthographic;
  ortho.screen_window = std::array<float, 4>{-0.5f, 1.5f, -2, 0};
  Camera flat(ortho, w, h);
  const Ray top_left = flat.generate_ray({0, 0}, {0.5f, 0.5f}, 0);
  const Ray bottom_right = flat.generate_ray({float(w), float(h)}, {0.5f, 0.5f}, 0);
  EXPECT_NEAR(top_left.origin.x, -0.5f, 1e-6f);
  EXPECT_NEAR(top_left.origin.y, 0, 1e-6f);
  EXPECT_NEAR(bottom_right.origin.x, 1.5f, 1e-6f);
  EXPECT_NEAR(bottom_right.origin.y, -2, 1e-6f);

  CameraDesc perspective;
  perspective.fov_degrees = 90;  // tan(fov / 2) = 1: screen space is camera space at unit distance
  perspective.screen_window = std::array<float, 4>{0, 2, -1, 1};
  Camera shifted(perspective, w, h);
  const Ray left = shifted.generate_ray({0, float(h) / 2}, {0.5f, 0.5f}, 0);
  const Ray right = shifted.generate_ray({float(w), float(h) / 2}, {0.5f, 0.5f}, 0);
  EXPECT_NEAR(left.direction.x, 0, 1e-6f);  // the left edge looks straight ahead
  EXPECT_NEAR(right.direction.x / right.direction.z, 2, 1e-5f);
  // A ray through a pixel's centre has its importance at that pixel (light tracing splats there).
  for (Vec2 film : {Vec2{5.5f, 7.5f}, Vec2{60.5f, 30.5f}}) {
    const Ray ray = shifted.generate_ray(film, {0.5f, 0.5f}, 0);
    Vec2 raster;
    ASSERT_GT(shifted.importance(ray.origin, ray.direction, &raster), 0);
    EXPECT_NEAR(raster.x, film.x, 1e-3f);
    EXPECT_NEAR(raster.y, film.y, 1e-3f);
  }
}

}  // namespace
}  // namespace candela
