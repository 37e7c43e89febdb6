// The camera: ray directions for pbrt's and the JSON format's conventions, and thin-lens depth of
// field against the analytic blur of an edge.
#include "candela/camera/camera.h"

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>

#include "candela/film/image_io.h"
#include "candela/io/pbrt_reader.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

TEST(Camera, PinholeRaysCoverTheFieldOfView) {
  CameraDesc d;  // identity: at the origin looking along +z, +x to the image's right
  d.fov_degrees = 90;
  d.fov_axis = FovAxis::Y;
  PerspectiveCamera cam(d, 200, 100);
  Ray top_left = cam.generate_ray({0, 0}, {0.5f, 0.5f}, 0);
  EXPECT_NEAR(top_left.direction.y / top_left.direction.z, 1.0f, 1e-5f);   // tan(45 degrees) at the top edge
  EXPECT_NEAR(top_left.direction.x / top_left.direction.z, -2.0f, 1e-5f);  // aspect 2, image left = -x
  Ray centre = cam.generate_ray({100, 50}, {0.5f, 0.5f}, 0);
  EXPECT_NEAR(centre.direction.z, 1.0f, 1e-6f);
  d.fov_axis = FovAxis::Smaller;  // pbrt: the smaller axis is y here
  EXPECT_NEAR(PerspectiveCamera(d, 200, 100).generate_ray({0, 0}, {}, 0).direction.y /
                  PerspectiveCamera(d, 200, 100).generate_ray({0, 0}, {}, 0).direction.z,
              1.0f, 1e-5f);
}

// A cropped film (pbrt-v4's cropwindow) sees through each pixel what the full image's pixel there
// sees, for perspective and orthographic cameras; its EXR records where it lies.
TEST(Camera, CroppedFilmPixelsSeeWhatTheFullImageSeesThere) {
  for (const char* camera : {"\"perspective\" \"float fov\" 38", "\"orthographic\""}) {
    auto read = [&](const char* crop) {
      return read_pbrt_string(fmt::format("LookAt 0 1 5  0 0.5 0  0 1 0\nCamera {}\nFilm \"rgb\" \"integer "
                                          "xresolution\" 128 \"integer yresolution\" 96 {}\nWorldBegin\n",
                                          camera, crop),
                              "crop.pbrt", ".");
    };
    SceneDesc full = read(""), cropped = read("\"float cropwindow\" [0.25 0.75 0.2 0.8]");
    ASSERT_TRUE(cropped.film.crop);
    PerspectiveCamera full_camera(full.camera, full.film.width, full.film.height);
    PerspectiveCamera crop_camera(cropped.camera, cropped.film.width, cropped.film.height);
    for (Vec2 p : {Vec2{0, 0}, Vec2{0.5f, 0.5f}, Vec2{63.9f, 56.9f}, Vec2{17.3f, 40.1f}}) {
      Ray a = crop_camera.generate_ray(p, {0.5f, 0.5f}, 0);
      Ray b = full_camera.generate_ray({p.x + 32, p.y + 20}, {0.5f, 0.5f}, 0);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(a.origin[c], b.origin[c], 1e-4f) << camera;
        EXPECT_NEAR(a.direction[c], b.direction[c], 1e-5f) << camera;
      }
    }
  }
  Image image(4, 3);
  image.x = 5, image.y = 6, image.full_width = 20, image.full_height = 10;
  const auto file = std::filesystem::temp_directory_path() / fmt::format("candela_crop_{}.exr", getpid());
  write_image(file, image, {});
  auto in = OIIO::ImageInput::open(file.string());
  ASSERT_TRUE(in);
  const OIIO::ImageSpec& spec = in->spec();
  EXPECT_EQ(spec.width, 4);
  EXPECT_EQ(spec.x, 5);
  EXPECT_EQ(spec.y, 6);
  EXPECT_EQ(spec.full_width, 20);
  EXPECT_EQ(spec.full_height, 10);
  in->close();
  std::filesystem::remove(file);
}

TEST(Camera, ThinLensRaysMeetOnThePlaneOfFocus) {
  CameraDesc d;
  d.lens_radius = 0.2f;
  d.focus_distance = 3;
  PerspectiveCamera cam(d, 64, 64);
  Ray a = cam.generate_ray({10, 20}, {0.1f, 0.9f}, 0), b = cam.generate_ray({10, 20}, {0.8f, 0.3f}, 0);
  Point3 pa = a.at((3 - a.origin.z) / a.direction.z), pb = b.at((3 - b.origin.z) / b.direction.z);
  EXPECT_NEAR(distance(pa, pb), 0, 1e-4f);
  EXPECT_GT(distance(a.origin, b.origin), 0.05f);
}

// P(x < t R) for x uniform on a disk of radius R: the area fraction of a circular segment.
double disk_fraction_below(double t) {
  t = std::clamp(t, -1.0, 1.0);
  return 0.5 + (t * std::sqrt(1 - t * t) + std::asin(t)) / 3.14159265358979323846;
}

// A black half-plane x < 0 at depth 2 in front of a white sky, seen by a camera at the origin
// looking along +z (identity transform: +x to the image's right) with its fov on the x axis.
SceneDesc half_plane_scene(int width, int height, float fov_degrees, float lens_radius, float focus_distance,
                           int spp) {
  SceneDesc d;
  d.film = {width, height, ""};
  d.camera.fov_axis = FovAxis::X;
  d.camera.fov_degrees = fov_degrees;
  d.camera.lens_radius = lens_radius;
  d.camera.focus_distance = focus_distance;
  d.settings.spp = spp;
  d.materials = {BlackMaterial{}};
  ShapeDesc blocker;
  blocker.geometry = RectangleShape{{-100, -100, 2}, {100, 0, 0}, {0, 200, 0}};
  blocker.material = 0;
  d.shapes = {blocker};
  d.lights = {SkyLight{RGB(1.0f), RGB(1.0f), RGB(1.0f), {0, 1, 0}}};
  return d;
}

TEST(Camera, DepthOfFieldBlursAnEdgeLikeTheLensDisk) {
  // Focus at f = 1, lens radius R. A lens ray through screen position s hits depth z at x = l (1 - z/f) + s z, so the blocker is
  // missed when l < 2 s: the pixel value is P(l < 2 s) averaged over the pixel's s.
  const float R = 0.05f, tan_half = 0.1f;
  const int width = 64;
  SceneDesc d = half_plane_scene(width, 4, 2 * std::atan(tan_half) * 180 / kPi, R, 1, 256);
  Film film = testing::render_description(d);
  Image img = film.mean_image();
  int blurred_columns = 0;
  for (int x = 0; x < width; ++x) {
    double expected = 0;
    const int sub = 64;
    for (int i = 0; i < sub; ++i) {
      double s = (2 * (x + (i + 0.5) / sub) / width - 1) * tan_half;
      expected += disk_fraction_below(2 * s / R) / sub;
    }
    auto column = testing::region_mean(img, 1, [&](int px, int) { return px == x; });
    // Pixel values are independent estimates; the column's spread gives the standard error.
    double se = std::max(column.standard_error, std::sqrt(film.variance_of_mean_image().at(x, 0).g / 4.0));
    EXPECT_NEAR(column.mean, expected, 4 * se + 1e-4) << "column " << x;
    if (expected > 0.02 && expected < 0.98) ++blurred_columns;
  }
  EXPECT_GE(blurred_columns, 12);  // the blur spans about 16 columns
}

TEST(Camera, InFocusPlaneIsSharpWithALens) {
  // Focus on the blocker itself: the lens changes nothing, the edge is a step at the centre.
  SceneDesc d = half_plane_scene(16, 2, 20, 0.3f, 2, 64);
  Image img = testing::render_description(d).mean_image();
  for (int x = 0; x < 16; ++x) EXPECT_NEAR(img.at(x, 0).g, x < 8 ? 0.0f : 1.0f, 1e-6f) << x;
}

}  // namespace
}  // namespace candela
