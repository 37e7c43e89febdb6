#pragma once
// The textured inputs of materials, lights and textures: a constant or a texture. Part of the
// format-neutral scene description (description/scene_desc.h); the texture types are in textures.h.
#include "candela/math/color.h"

namespace candela {

// A material or texture parameter: a constant `value`, or the texture SceneDesc::textures[texture]
// evaluated at the hit point (texture >= 0). Float parameters read a colour texture as the average of
// its channels (as pbrt-v4 does for float image textures).
template <typename T>
struct Textured {
  T value{};
  int texture = -1;
  Textured() = default;
  Textured(T v) : value(v) {}  // NOLINT: a constant converts implicitly
  bool is_constant() const { return texture < 0; }
};
using ColorInput = Textured<RGB>;
using FloatInput = Textured<float>;

}  // namespace candela
