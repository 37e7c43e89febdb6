// The AOV layers a denoised render collects (with_denoise_features) and the denoiser run on a
// film's halves and features (denoise_render).
#include "candela/denoise/denoised_render.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "candela/base/error.h"
#include "candela/film/film.h"

namespace candela {
namespace {

TEST(DenoisedRender, AddsTheFeaturesTheSelectionLacksAndKeepsItsOwn) {
  AovSelection asked = parse_aov_selection("position,albedo,camera_space");
  const AovSelection collected = with_denoise_features(asked);
  EXPECT_EQ(collected.space, AovSpace::Camera);
  for (Aov aov : {Aov::Position, Aov::Albedo, Aov::Halves})
    EXPECT_EQ(std::count(collected.layers.begin(), collected.layers.end(), aov), 1) << aov_name(aov);
  EXPECT_EQ(collected.layers.size(), 3u);
  EXPECT_EQ(with_denoise_features(collected).layers, collected.layers);
  EXPECT_EQ(with_denoise_features({}).layers.size(), std::size(kDenoiseFeatures));
  // pbrt-v4's gbuffer film keeps its own layers alone.
  EXPECT_THROW(with_denoise_features(parse_aov_selection("gbuffer")), UsageError);
}

TEST(DenoisedRender, NeedsTheHalvesLayer) {
  Film film(4, 3);
  AovFilm without_halves(4, 3, std::vector<Aov>{Aov::Albedo, Aov::Normal, Aov::Depth});
  EXPECT_THROW(denoise_render(film, without_halves), InternalError);
}

// A film whose halves agree everywhere (no noise): the denoised image is the raw one, and the
// input handed back is the one denoised.
TEST(DenoisedRender, ANoiselessFilmComesBackUnchanged) {
  const int w = 12, h = 10;
  Film film(w, h);
  AovFilm features(w, h, with_denoise_features({}).layers);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const RGB value(0.1f + 0.05f * float(x), 0.2f, 0.3f + 0.02f * float(y));
      AovSample s;
      s.hit = true;
      s.albedo = RGB(0.5f);
      s.normal = {0, 0, 1};
      s.depth = 2;
      for (int sample = 0; sample < 4; ++sample) {
        film.add_sample(x, y, value, 1.0f, sample % 2 == 0);
        features.add_sample(x, y, s, 1.0f, sample % 2 == 0);
      }
    }
  DenoiseInput input;
  const DenoisedRender denoised = denoise_render(film, features, &input);
  EXPECT_EQ(input.width, w);
  EXPECT_EQ(input.height, h);
  EXPECT_EQ(denoised.result.image.rgb, input.raw().rgb);
  EXPECT_GE(denoised.seconds, 0);
  EXPECT_EQ(denoise_render(input).result.image.rgb, denoised.result.image.rgb);
}

}  // namespace
}  // namespace candela
