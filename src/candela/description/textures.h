#pragma once
// Texture descriptions and the textured inputs of materials and lights. Part of the format-neutral scene description (description/scene_desc.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "candela/base/enum_names.h"
#include "candela/base/error.h"
#include "candela/math/color.h"
#include "candela/math/transform.h"
#include "candela/math/vec.h"

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

// Texture coordinates from the surface's (u, v) by an affine map:
//   s = su u + s_from_v v + du,   t = t_from_u u + sv v + dv.
// The cross terms are zero unless the texture is rotated or sheared (glTF's KHR_texture_transform
// rotation, Mitsuba's to_uv, JSON's uv_matrix).
struct UVMapping {
  float su = 1, sv = 1, du = 0, dv = 0;
  float s_from_v = 0, t_from_u = 0;
  bool is_axis_aligned() const { return s_from_v == 0 && t_from_u == 0; }
};

// What happens outside [0,1]^2.
enum class TextureWrap { Repeat, Clamp, Black, Mirror };
// How 8-bit texel values become linear: Auto = sRGB for 8-bit files, linear for float files (EXR, HDR).
enum class ColorEncoding { Auto, Linear, SRGB };
constexpr std::string_view enum_name(TextureWrap v) {
  switch (v) {
    case TextureWrap::Repeat: return "repeat";
    case TextureWrap::Clamp: return "clamp";
    case TextureWrap::Black: return "black";
    case TextureWrap::Mirror: return "mirror";
  }
  return {};
}
constexpr std::string_view enum_name(ColorEncoding v) {
  switch (v) {
    case ColorEncoding::Auto: return "auto";
    case ColorEncoding::Linear: return "linear";
    case ColorEncoding::SRGB: return "srgb";
  }
  return {};
}

// An image read with OpenImageIO, looked up with bilinear filtering (or nearest, `bilinear = false`).
// t = 0 is the *bottom* row of the image (pbrt-v4 and Mitsuba flip v the same way).
struct ImageTexture {
  std::string filename;  // resolved by the reader (absolute or relative to the working directory)
  TextureWrap wrap = TextureWrap::Repeat;
  ColorEncoding encoding = ColorEncoding::Auto;
  bool bilinear = true;
  float scale = 1;      // texel values are multiplied by this...
  bool invert = false;  // ...and then replaced by 1 - value when set (pbrt's "invert")
  bool luminance = false;  // each texel read as its luminance, grey (Mitsuba's float lookup of an RGB image)
  UVMapping mapping;
};

// Alternating tex1/tex2 on the unit squares of (s, t): tex1 where floor(s) + floor(t) is even.
struct CheckerboardTexture {
  ColorInput tex1{RGB(1.0f)}, tex2{RGB(0.0f)};
  UVMapping mapping;
};

// tex * scale.
struct ScaleTexture {
  ColorInput tex{RGB(1.0f)};
  FloatInput scale{1.0f};
};

// (1 - amount) * tex1 + amount * tex2.
struct MixTexture {
  ColorInput tex1{RGB(0.0f)}, tex2{RGB(1.0f)};
  FloatInput amount{0.5f};
};

// A value stored on the mesh itself (Mitsuba's mesh_attribute): the TriangleMesh::attributes entry
// of this name and kind, per vertex (interpolated with the hit's barycentrics) or per face (a mesh
// may have both of one name, as Mitsuba's "vertex_color" and "face_color"). Zero on other shapes.
struct MeshAttributeTexture {
  std::string name;  // without the "vertex_" / "face_" prefix
  bool per_face = false;
};

using TextureDesc = std::variant<ImageTexture, CheckerboardTexture, ScaleTexture, MixTexture, MeshAttributeTexture>;

}  // namespace candela
