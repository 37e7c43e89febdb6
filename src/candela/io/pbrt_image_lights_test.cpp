// Tests of the pbrt-v4 reader's lights shaped by an image: LightSource "goniometric" and "projection".
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/description/scene_desc.h"
#include "candela/io/pbrt_reader.h"
#include "candela/scene/scene.h"
#include "candela/testing/pbrt_reader_helpers.h"
#include "candela/testing/temp_image_file.h"

namespace candela {
namespace {

using namespace candela::testing::pbrt_reader;

TEST(PbrtImageLights, GoniometricParameters) {
  ScratchFile exr("gonio.exr");
  SceneDesc scene = read_lines({"WorldBegin", "Translate 1 2 3", "Rotate -90 1 0 0",
                                "LightSource \"goniometric\" \"string filename\" \"gonio.exr\" \"rgb I\" [ 2 3 4 ] "
                                "\"float scale\" 0.5 \"float power\" 12"});
  ASSERT_EQ(scene.lights.size(), 1u);
  const auto& light = std::get<GoniometricLight>(scene.lights[0]);
  EXPECT_EQ(fs::path(light.filename), scratch_dir() / "gonio.exr");
  EXPECT_EQ(light.intensity, RGB(1.0f, 1.5f, 2.0f));  // I x scale; an RGB I is not normalised
  EXPECT_EQ(light.power, 12);
  // The CTM is the light's frame; its +y (the image's centre) is here the world's -z.
  expect_near(light.to_world.point(Point3(0.0f)), Vec3(1, 2, 3));
  expect_near(light.to_world.vector(Vec3(0, 1, 0)), Vec3(0, 0, -1));
  // No power: 0.
  EXPECT_EQ(std::get<GoniometricLight>(
                read_lines({"WorldBegin", "LightSource \"goniometric\" \"string filename\" \"gonio.exr\""}).lights[0])
                .power,
            0);
}

TEST(PbrtImageLights, GoniometricErrors) {
  expect_error({"WorldBegin", "LightSource \"goniometric\" \"rgb I\" [ 1 1 1 ]"}, 2, "LightSource",
               "\"filename\" is required");
  expect_error({"WorldBegin", "LightSource \"goniometric\" \"string filename\" \"missing.exr\""}, 2,
               "\"string filename\"", "missing.exr");
  ScratchFile exr("gonio.exr");
  expect_error({"WorldBegin", "LightSource \"goniometric\" \"string filename\" \"gonio.exr\" \"float fov\" 3"}, 2,
               "\"float fov\"", "fov");
}

TEST(PbrtImageLights, GoniometricNonSquareImageIsAnErrorAtTheLightSource) {
  Image img(4, 3);
  testing::TempImageFile file(img, "pbrt_gonio_nonsquare");
  const fs::path path = file.path();
  const std::string line = fmt::format("LightSource \"goniometric\" \"string filename\" \"{}\"", path.string());
  SceneDesc scene = read_lines({"WorldBegin", line});
  try {
    Scene built(scene);
    FAIL() << "a non-square goniometric image was accepted";
  } catch (const SceneError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(fmt::format("{}:2", kSceneName)), std::string::npos) << message;
    EXPECT_NE(message.find("square"), std::string::npos) << message;
  }
}

TEST(PbrtImageLights, ProjectionParameters) {
  ScratchFile png("slide.png");
  SceneDesc scene = read_lines({"WorldBegin", "Translate 1 2 3",
                                "LightSource \"projection\" \"string filename\" \"slide.png\" \"float fov\" 40 "
                                "\"float scale\" 3 \"float power\" 5"});
  ASSERT_EQ(scene.lights.size(), 1u);
  const auto& light = std::get<ProjectorLight>(scene.lights[0]);
  EXPECT_EQ(light.fov_degrees, 40);
  EXPECT_EQ(light.fov_axis, ProjectorFovAxis::Smaller);
  EXPECT_EQ(light.radiometry, ProjectorRadiometry::Intensity);
  EXPECT_EQ(light.scale, RGB(3.0f));
  EXPECT_EQ(light.power, 5);
  expect_near(light.to_world.point(Point3(0.0f)), Vec3(1, 2, 3));
  ASSERT_EQ(scene.textures.size(), 1u);
  ASSERT_EQ(light.irradiance, 0);
  const auto& tex = std::get<ImageTexture>(scene.textures[0]);
  EXPECT_EQ(fs::path(tex.filename), scratch_dir() / "slide.png");
  EXPECT_EQ(tex.filter, TextureFilter::Nearest);  // pbrt-v4 looks up the nearest texel
  EXPECT_EQ(tex.wrap, TextureWrap::Clamp);
  // The projector's Mitsuba uv mirrored in both axes (pbrt-v4's orientation; texture t = 1 is the top row).
  EXPECT_EQ(tex.mapping.su, -1);
  EXPECT_EQ(tex.mapping.du, 1);
  EXPECT_EQ(tex.mapping.sv, -1);
  EXPECT_EQ(tex.mapping.dv, 1);
  // The default fov is 90.
  EXPECT_EQ(std::get<ProjectorLight>(
                read_lines({"WorldBegin", "LightSource \"projection\" \"string filename\" \"slide.png\""}).lights[0])
                .fov_degrees,
            90);
}

TEST(PbrtImageLights, ProjectionErrors) {
  ScratchFile png("slide.png");
  expect_error({"WorldBegin", "LightSource \"projection\" \"float fov\" 30"}, 2, "LightSource",
               "\"filename\" is required");
  expect_error({"WorldBegin", "LightSource \"projection\" \"string filename\" \"slide.png\" \"float fov\" 180"}, 2,
               "\"float fov\"", "must be in (0, 180)");
  expect_error({"WorldBegin", "LightSource \"projection\" \"string filename\" \"slide.png\" \"float fov\" -5"}, 2,
               "\"float fov\"", "must be in (0, 180)");
  expect_error({"WorldBegin", "LightSource \"projection\" \"string filename\" \"slide.png\" \"float scale\" -1"}, 2,
               "\"float scale\"", "must not be negative");
  expect_error({"WorldBegin", "LightSource \"projection\" \"string filename\" \"slide.png\" \"rgb I\" [ 1 1 1 ]"}, 2,
               "\"rgb I\"", "I");
}

// pbrt-v4's orientation end to end: a 2 x 2 image with one bright texel (top left in the file),
// projected down the CTM's +z from the origin; pbrt-v4 shows the image's top left at CTM-space +y
// and -x (it flips y in the light's frame and reads row 0 at the top).
TEST(PbrtImageLights, ProjectionShowsTheImagesTopLeftAtPlusYMinusX) {
  Image img(2, 2);
  img.set(0, 0, RGB(8.0f));
  img.set(1, 0, RGB(1.0f));
  img.set(0, 1, RGB(2.0f));
  img.set(1, 1, RGB(4.0f));
  testing::TempImageFile file(img, "pbrt_projection_orientation");
  const std::string line =
      fmt::format("LightSource \"projection\" \"string filename\" \"{}\" \"float fov\" 60", file.path());
  SceneDesc desc = read_lines({"WorldBegin", line});
  Scene scene(desc);
  const Light& light = scene.lights().at(0);
  const float t = std::tan(radians(30)) * 0.5f;
  auto seen = [&](float x, float y) {
    return light_sample_li(light, {Point3(x, y, 1), Normal3(0.0f)}, {}).radiance.r * (x * x + y * y + 1);
  };
  EXPECT_NEAR(seen(-t, t), 8, 1e-4);  // top left
  EXPECT_NEAR(seen(t, t), 1, 1e-4);   // top right
  EXPECT_NEAR(seen(-t, -t), 2, 1e-4);  // bottom left
  EXPECT_NEAR(seen(t, -t), 4, 1e-4);   // bottom right
  EXPECT_EQ(seen(0, 3 * t), 0);       // outside the frustum
}

}  // namespace
}  // namespace candela
