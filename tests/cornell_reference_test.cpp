// The Cornell box from ../shared/scenes/cornell-box/cornell-box.pbrt against its converged reference
// (Cycles, 4096 spp): the image mean per channel, relMSE at 64 spp, and the mean of every visible
// surface region (walls, block faces, light), each region found by tracing the pixel-centre ray.
#include <gtest/gtest.h>

#include <map>

#include "candela/film/image_io.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

const std::string kSceneDir = std::string(CANDELA_SHARED_DIR) + "/scenes/cornell-box/";

// Region label of each pixel: which shape (and for the blocks, which face) its centre ray hits;
// -1 where the pixel straddles an edge (a neighbour differs) or sees nothing.
std::vector<int> region_labels(const Scene& scene, int width, int height) {
  std::vector<int> label(size_t(width) * height, -1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      SurfaceHit hit;
      Ray ray = scene.camera().generate_ray({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}, 0);
      if (scene.intersect(ray, hit)) label[size_t(y) * width + x] = int(hit.shape * 100 + hit.primitive / 2);
    }
  std::vector<int> interior(label.size(), -1);
  for (int y = 1; y + 1 < height; ++y)
    for (int x = 1; x + 1 < width; ++x) {
      int l = label[size_t(y) * width + x];
      bool same = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) same = same && label[size_t(y + dy) * width + x + dx] == l;
      if (same) interior[size_t(y) * width + x] = l;
    }
  return interior;
}

// One test, so the 64-spp render (the expensive part) happens once per ctest run.
TEST(CornellBoxReference, AgreesWithConvergedReference) {
  SceneDesc desc = read_scene_file(kSceneDir + "cornell-box.pbrt");
  desc.settings.spp = 64;
  // The reference is Cycles', an RGB renderer's: compare RGB transport (the pbrt-v4 reader's default is
  // spectral, whose blue is 3.5-4% lower here, as pbrt-v4's own: REFERENCE.md).
  desc.settings.spectral = false;
  Scene scene(desc);
  Film film(desc.film.width, desc.film.height);
  RenderOptions options;
  options.progress = false;
  render(scene, desc.settings, film, options);
  Image image = film.mean_image();
  Image reference = read_image(kSceneDir + "reference.exr");
  ASSERT_EQ(image.width, reference.width);
  ASSERT_EQ(image.height, reference.height);

  // The image mean per channel within 1%.
  for (int c = 0; c < 3; ++c) {
    double mean = testing::region_mean(image, c).mean, ref = testing::region_mean(reference, c).mean;
    EXPECT_NEAR(mean / ref, 1.0, 0.01) << "image mean, channel " << c << ": " << mean << " vs reference " << ref;
  }

  // relMSE (eps 0.01) at 64 spp below 0.0075 (pbrt-v4 with independent samples: 0.0050).
  double e = testing::rel_mse(image, reference);
  std::printf("relMSE at 64 spp: %.5f\n", e);
  EXPECT_LT(e, 0.0075);

  // Every visible surface region within 2%: walls, floor, ceiling, light, block faces.
  std::vector<int> labels = region_labels(scene, image.width, image.height);
  std::map<int, int> pixel_count;
  for (int l : labels)
    if (l >= 0) ++pixel_count[l];
  int regions = 0;
  for (const auto& [label, count] : pixel_count) {
    if (count < 200) continue;  // slivers: too few pixels for a stable mean
    ++regions;
    auto in_region = [&](int x, int y) { return labels[size_t(y) * image.width + x] == label; };
    for (int c = 0; c < 3; ++c) {
      auto ours = testing::region_mean(image, c, in_region), ref = testing::region_mean(reference, c, in_region);
      EXPECT_NEAR(ours.mean / ref.mean, 1.0, 0.02)
          << "shape " << label / 100 << " face " << label % 100 << " (" << count << " pixels), channel " << c
          << ": " << ours.mean << " vs reference " << ref.mean;
      if (c == 1)
        std::printf("region shape %d face %d (%d px): green %.4f vs %.4f (ratio %.4f)\n", label / 100, label % 100,
                    count, ours.mean, ref.mean, ours.mean / ref.mean);
    }
  }
  // Light, floor, ceiling, back and side walls, and the visible faces of both blocks.
  EXPECT_GE(regions, 11);
}

}  // namespace
}  // namespace candela
