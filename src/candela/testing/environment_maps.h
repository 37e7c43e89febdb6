#pragma once
// A small non-uniform environment map for tests of environment lights: a smooth colour gradient, a
// bright spot (which importance sampling must find) and a black patch (which it must avoid).
#include "candela/film/image.h"
#include "candela/description/scene_desc.h"

namespace candela::testing {

inline Image environment_test_map(EnvironmentMapping mapping) {
  const bool equirect = mapping != EnvironmentMapping::EqualAreaOctahedral;
  const int w = equirect ? 32 : 24, h = equirect ? 16 : 24;  // the octahedral mapping needs a square
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float fx = (x + 0.5f) / w, fy = (y + 0.5f) / h;
      RGB c = RGB(0.3f + 0.7f * fx, 0.2f + 0.8f * fy, 1.0f - 0.6f * fx) * (0.5f + fx * fy);
      if (x >= w / 2 + 3 && x < w / 2 + 5 && y >= h / 4 && y < h / 4 + 2) c += RGB(20.0f, 15.0f, 10.0f);
      if (x >= 4 && x < 8 && y >= h / 2 + 1 && y < h / 2 + 4) c = RGB(0.0f);
      img.set(x, y, c);
    }
  return img;
}

}  // namespace candela::testing
