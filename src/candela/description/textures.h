#pragma once
// Texture descriptions, each with its schema (description/schema.h). Part of the format-neutral scene description (description/scene_desc.h).
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
#include "candela/description/schema.h"
#include "candela/description/textured_input.h"

namespace candela {

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
// How an image is looked up between texel centres.
enum class TextureFilter { Bilinear, Nearest };
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
constexpr std::string_view enum_name(TextureFilter v) {
  switch (v) {
    case TextureFilter::Bilinear: return "bilinear";
    case TextureFilter::Nearest: return "nearest";
  }
  return {};
}

// An image read with OpenImageIO, looked up with bilinear filtering (or nearest).
// t = 0 is the *bottom* row of the image (pbrt-v4 and Mitsuba flip v the same way).
struct ImageTexture {
  std::string filename;  // resolved by the reader (absolute or relative to the working directory)
  TextureWrap wrap = TextureWrap::Repeat;
  ColorEncoding encoding = ColorEncoding::Auto;
  TextureFilter filter = TextureFilter::Bilinear;
  float scale = 1;      // texel values are multiplied by this...
  bool invert = false;  // ...and then replaced by 1 - value when set (pbrt's "invert")
  bool luminance = false;  // each texel read as its luminance, grey (Mitsuba's float lookup of an RGB image)
  UVMapping mapping;
};
template <>
struct SchemaOf<ImageTexture> {
  using T = ImageTexture;
  static constexpr Field fields[] = {
      field<&T::filename>("filename", kAnyValue, "image").required_field(),
      enum_field<&T::wrap>("wrap", "what the image is outside [0,1]^2"),
      enum_field<&T::encoding>("encoding", "how texel values become linear"),
      enum_field<&T::filter>("filter", "how the image is looked up between texel centres"),
      field<&T::scale>("scale", kNonNegative, "texel values are multiplied by this"),
      field<&T::invert>("invert", kAnyValue, "each value v becomes 1 - v (after the scale)"),
      field<&T::luminance>("luminance", kAnyValue, "each texel read as its luminance, grey"),
      uv_mapping_field<&T::mapping>(),
  };
  static constexpr TypeSchema schema{.name = "image", .fields = fields, .help = "an image file"};
};

// Alternating tex1/tex2 on the unit squares of (s, t): tex1 where floor(s) + floor(t) is even.
struct CheckerboardTexture {
  ColorInput tex1{RGB(1.0f)}, tex2{RGB(0.0f)};
  UVMapping mapping;
};
template <>
struct SchemaOf<CheckerboardTexture> {
  using T = CheckerboardTexture;
  // A texture may be used in any parameter, so its colours need only be >= 0.
  static constexpr Field fields[] = {
      field<&T::tex1>("tex1", kNonNegative, "where floor(s) + floor(t) is even"),
      field<&T::tex2>("tex2", kNonNegative, "where it is odd"),
      uv_mapping_field<&T::mapping>(),
  };
  static constexpr TypeSchema schema{.name = "checkerboard", .fields = fields, .help = "a checkerboard"};
};

// tex * scale.
struct ScaleTexture {
  ColorInput tex{RGB(1.0f)};
  FloatInput scale{1.0f};
};
template <>
struct SchemaOf<ScaleTexture> {
  using T = ScaleTexture;
  static constexpr Field fields[] = {
      field<&T::tex>("tex", kNonNegative),
      field<&T::scale>("scale", kNonNegative),
  };
  static constexpr TypeSchema schema{.name = "scale", .fields = fields, .help = "tex * scale"};
};

// (1 - amount) * tex1 + amount * tex2.
struct MixTexture {
  ColorInput tex1{RGB(0.0f)}, tex2{RGB(1.0f)};
  FloatInput amount{0.5f};
};
template <>
struct SchemaOf<MixTexture> {
  using T = MixTexture;
  static constexpr Field fields[] = {
      field<&T::tex1>("tex1", kNonNegative),
      field<&T::tex2>("tex2", kNonNegative),
      field<&T::amount>("amount", kUnitInterval, "the weight of tex2"),
  };
  static constexpr TypeSchema schema{.name = "mix", .fields = fields, .help = "(1 - amount) tex1 + amount tex2"};
};

// A value stored on the mesh itself (Mitsuba's mesh_attribute): the TriangleMesh::attributes entry
// of this name and kind, per vertex (interpolated with the hit's barycentrics) or per face (a mesh
// may have both of one name, as Mitsuba's "vertex_color" and "face_color"). Zero on other shapes.
struct MeshAttributeTexture {
  std::string name;  // without the "vertex_" / "face_" prefix
  bool per_face = false;
};
template <>
struct SchemaOf<MeshAttributeTexture> {
  using T = MeshAttributeTexture;
  static constexpr Field fields[] = {
      text_field<&T::name>("name", "the attribute's name, without \"vertex_\" or \"face_\"").required_field(),
      field<&T::per_face>("per_face", kAnyValue, "the per-face attribute of that name (else per vertex)"),
  };
  static constexpr TypeSchema schema{.name = "mesh_attribute", .fields = fields,
                                     .help = "a value stored on the mesh, per vertex or per face"};
};

using TextureDesc = std::variant<ImageTexture, CheckerboardTexture, ScaleTexture, MixTexture, MeshAttributeTexture>;

}  // namespace candela
