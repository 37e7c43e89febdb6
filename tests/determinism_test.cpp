// The same scene, seed and spp give a bitwise-identical image with 1 thread or 2; a different seed
// gives a different image.
#include <gtest/gtest.h>

#include <cstring>

#include "candela/io/pbrt_reader.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

SceneDesc small_cornell_box(uint64_t seed) {
  SceneDesc desc = read_json_scene(builtin_scene_json(), "cornell-box.json", ".");
  desc.film.width = 48;
  desc.film.height = 40;  // not a multiple of the tile size
  desc.settings.spp = 6;  // not a multiple of the pass size
  desc.settings.seed = seed;
  return desc;
}

TEST(Determinism, OneAndTwoThreadsGiveBitwiseIdenticalImages) {
  Image one = testing::render_description(small_cornell_box(7), 1).mean_image();
  Image two = testing::render_description(small_cornell_box(7), 2).mean_image();
  ASSERT_EQ(one.rgb.size(), two.rgb.size());
  EXPECT_EQ(0, std::memcmp(one.rgb.data(), two.rgb.data(), one.rgb.size() * sizeof(float)));
}

// pbrt-v4's layered BSDFs draw random numbers inside eval() and pdf(), seeded by the hit point and the
// directions (materials/layered.h): still the same image whatever the thread count.
TEST(Determinism, LayeredBsdfsGiveTheSameImageWithOneOrTwoThreads) {
  Warnings warnings;
  SceneDesc desc = read_pbrt_string(
      "LookAt 0 1 4  0 0.5 0  0 1 0\n"
      "Camera \"perspective\" \"float fov\" 40\n"
      "Film \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 30\n"
      "Sampler \"independent\" \"integer pixelsamples\" 6\n"
      "WorldBegin\n"
      "LightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\n"
      "AttributeBegin\n"
      "  Material \"coateddiffuse\" \"rgb reflectance\" [0.2 0.4 0.7] \"float roughness\" 0.1 \"rgb albedo\" [0.5 0.5 0.5]\n"
      "  Translate -0.6 0.5 0\n"
      "  Shape \"sphere\" \"float radius\" 0.5\n"
      "AttributeEnd\n"
      "AttributeBegin\n"
      "  Material \"coatedconductor\" \"float interface.roughness\" 0.05 \"float conductor.roughness\" 0.2\n"
      "  Translate 0.6 0.5 0\n"
      "  Shape \"sphere\" \"float radius\" 0.5\n"
      "AttributeEnd\n",
      "layered.pbrt", ".", warnings);
  Image one = testing::render_description(desc, 1).mean_image();
  Image two = testing::render_description(desc, 2).mean_image();
  ASSERT_EQ(one.rgb.size(), two.rgb.size());
  EXPECT_EQ(0, std::memcmp(one.rgb.data(), two.rgb.data(), one.rgb.size() * sizeof(float)));
}

TEST(Determinism, SeedChangesTheImage) {
  Image a = testing::render_description(small_cornell_box(1), 2).mean_image();
  Image b = testing::render_description(small_cornell_box(2), 2).mean_image();
  EXPECT_NE(0, std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)));
}

}  // namespace
}  // namespace candela
