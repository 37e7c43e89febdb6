#pragma once
// A linear RGB float image, row-major, top row first.
#include <vector>

#include "candela/math/color.h"

namespace candela {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // 3 floats per pixel
  // Where it lies in a larger image (FilmDesc::crop): EXR files record it as their data window at
  // (x, y) of a full_width x full_height display window. Zero sizes: the image is the whole.
  int x = 0, y = 0, full_width = 0, full_height = 0;

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3, 0.0f) {}
  RGB at(int x, int y) const {
    const float* p = &rgb[(size_t(y) * width + x) * 3];
    return {p[0], p[1], p[2]};
  }
  void set(int x, int y, const RGB& c) {
    float* p = &rgb[(size_t(y) * width + x) * 3];
    p[0] = c.r;
    p[1] = c.g;
    p[2] = c.b;
  }
};

}  // namespace candela
