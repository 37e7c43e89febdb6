// Benedikt Bitterli's scenes in pbrt-v4 format (../shared/scenes/bitterli/) rendered by candela's pbrt-v4
// reader and path tracer, against pbrt-v4's own converged renders of the same files
// (pbrt-v4-reference.exr, 4096 spp except veach-bidir at 512, at the resolution the README states).
//
// Two statistics, as docs/bitterli-comparison.md explains:
//  - the clamped mean, mean(min(pixel, 1)) per channel, so visible emitters do not dominate, within 3%.
//    Clamping a noisy pixel removes the energy of its fireflies (a Jensen gap that grows with the noise),
//    so it is taken on 4x4 pixel blocks averaged before clamping: the clamp still cuts the emitters
//    (large bright regions), while the noise that reaches it is that of 16x the spp.
//  - relMSE (eps 0.01) against the reference below a stated bound: the noise of candela at the test's spp
//    (measured over seeds, docs/bitterli-comparison.md) plus that of the reference, with a margin of 2 for
//    the spread of relMSE estimates dominated by rare fireflies.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "candela/film/image_io.h"
#include "candela/io/scene_reader.h"
#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

struct ReferenceCase {
  const char* scene;
  int width, height, spp;
  double relmse_bound;
  double mean_tolerance[3];  // relative, per channel
};

void PrintTo(const ReferenceCase& c, std::ostream* os) { *os << c.scene; }

// mean(min(block mean, 1)) of one channel over `block` x `block` pixel blocks.
double clamped_block_mean(const Image& img, int channel, int block) {
  double sum = 0;
  int blocks = 0;
  for (int by = 0; by + block <= img.height; by += block)
    for (int bx = 0; bx + block <= img.width; bx += block) {
      double b = 0;
      for (int y = by; y < by + block; ++y)
        for (int x = bx; x < bx + block; ++x) b += img.at(x, y)[channel];
      sum += std::min(b / (block * block), 1.0);
      ++blocks;
    }
  return sum / blocks;
}

struct Rendered {
  Image image, reference;
};

Rendered render_case(const ReferenceCase& c, bool spectral = true) {
  const std::string dir = std::string(CANDELA_SHARED_DIR) + "/scenes/bitterli/" + c.scene + "/";
  SceneDesc desc = read_scene_file(dir + "scene-v4.pbrt");
  EXPECT_TRUE(desc.settings.spectral) << "the pbrt-v4 reader renders spectrally by default";
  desc.film.width = c.width;
  desc.film.height = c.height;
  desc.settings.spp = c.spp;
  desc.settings.seed = 1;
  desc.settings.spectral = spectral;
  return {testing::render_description(desc).mean_image(), read_image(dir + "pbrt-v4-reference.exr")};
}

class BitterliReference : public ::testing::TestWithParam<ReferenceCase> {};

TEST_P(BitterliReference, AgreesWithPbrtV4) {
  const ReferenceCase& c = GetParam();
  auto [image, reference] = render_case(c);
  ASSERT_EQ(image.width, reference.width);
  ASSERT_EQ(image.height, reference.height);

  for (int ch = 0; ch < 3; ++ch) {
    double ours = clamped_block_mean(image, ch, 4), ref = clamped_block_mean(reference, ch, 4);
    std::printf("%s channel %d: clamped mean %.5f vs pbrt-v4 %.5f (ratio %.4f)\n", c.scene, ch, ours, ref, ours / ref);
    EXPECT_NEAR(ours / ref, 1.0, c.mean_tolerance[ch]) << c.scene << " channel " << ch;
  }
  double e = testing::rel_mse(image, reference);
  std::printf("%s: relMSE %.5f at %d spp (bound %.4f)\n", c.scene, e, c.spp, c.relmse_bound);
  EXPECT_LT(e, c.relmse_bound) << c.scene;
}

// The same Cornell box with RGB transport: its blue channel is about 6% above pbrt-v4's, which the 3%
// check above must catch (so that check can fail, and spectral transport is what makes it pass).
TEST(BitterliReferenceTransport, RgbTransportDiffersFromPbrtV4) {
  auto [image, reference] = render_case({"cornell-box", 256, 256, 64, 0, {}}, /*spectral=*/false);
  double ratio = clamped_block_mean(image, 2, 4) / clamped_block_mean(reference, 2, 4);
  std::printf("cornell-box, RGB transport: blue clamped-mean ratio %.4f\n", ratio);
  EXPECT_GT(ratio, 1.04);
}

// Bounds and spp: see docs/bitterli-comparison.md for the measurements behind them. In short, relMSE
// of the spectral renders over seeds 1-3 at these spp: cornell-box 0.0029-0.0030 (stable), veach-mis
// 0.058-0.34 (rare fireflies dominate), veach-ajar 0.86-0.93 at 256 spp (stable; noise falling as 1/spp,
// so rendered at 128 spp with twice the bound, for CI's time),
// veach-bidir 0.0095-0.014; the reference's own noise adds spp/4096 of ours. Each bound is about twice
// the largest value seen.
// veach-bidir names pbrt's "bdpt" integrator and is rendered with candela's (the path tracer needed
// 256 spp for relMSE 0.5-2.9).
// The files are rendered spectrally, as pbrt-v4 renders them (the reader's default). With RGB transport
// the Cornell box's blue channel is 6% brighter than pbrt-v4's: the saturated orange light (17, 12, 4)
// times the red and green walls gives a different blue in spectra than in RGB; the test
// RgbTransportDiffersFromPbrtV4 below shows the check can see that.
INSTANTIATE_TEST_SUITE_P(
    Scenes, BitterliReference,
    ::testing::Values(ReferenceCase{"cornell-box", 256, 256, 64, 0.006, {0.03, 0.03, 0.03}},
                      ReferenceCase{"veach-mis", 320, 180, 128, 0.7, {0.03, 0.03, 0.03}},
                      ReferenceCase{"veach-ajar", 320, 180, 128, 3.6, {0.03, 0.03, 0.03}},
                      ReferenceCase{"veach-bidir", 192, 192, 64, 0.05, {0.03, 0.03, 0.03}}),
    [](const ::testing::TestParamInfo<ReferenceCase>& info) {
      std::string name = info.param.scene;
      for (char& ch : name)
        if (ch == '-') ch = '_';
      return name;
    });

}  // namespace
}  // namespace candela
