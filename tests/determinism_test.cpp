// The same scene, seed and spp give a bitwise-identical image with 1 thread or 2; a different seed
// gives a different image.
#include <gtest/gtest.h>

#include <cstring>

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

TEST(Determinism, SeedChangesTheImage) {
  Image a = testing::render_description(small_cornell_box(1), 2).mean_image();
  Image b = testing::render_description(small_cornell_box(2), 2).mean_image();
  EXPECT_NE(0, std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)));
}

}  // namespace
}  // namespace candela
