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

// Where the (u, v) a texture's affine map starts from come from: the surface's own, or, as pbrt-v4's
// other 2D mappings, the hit point p in the texture's own space:
//   spherical:   (theta / pi, phi / 2 pi) of the direction from the origin to p (z is theta's axis);
//   cylindrical: ((pi + atan2(p.y, p.x)) / 2 pi, p.z);
//   planar:      (p . planar_s, p . planar_t).
enum class TextureProjection { Surface, Spherical, Cylindrical, Planar };
constexpr std::string_view enum_name(TextureProjection v) {
  switch (v) {
    case TextureProjection::Surface: return "uv";
    case TextureProjection::Spherical: return "spherical";
    case TextureProjection::Cylindrical: return "cylindrical";
    case TextureProjection::Planar: return "planar";
  }
  return {};
}

// Texture coordinates from (u, v) (the surface's, or a projection's) by an affine map:
//   s = su u + s_from_v v + du,   t = t_from_u u + sv v + dv.
// The cross terms are zero unless the texture is rotated or sheared (glTF's KHR_texture_transform
// rotation, Mitsuba's to_uv, JSON's uv_matrix).
struct UVMapping {
  float su = 1, sv = 1, du = 0, dv = 0;
  float s_from_v = 0, t_from_u = 0;
  TextureProjection projection = TextureProjection::Surface;
  Transform to_world;                                 // the projection's space to the world
  Vec3 planar_s{1, 0, 0}, planar_t{0, 1, 0};  // the planar projection's axes
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

// v00 at (s, t) = (0, 0), v10 at (1, 0), v01 at (0, 1), v11 at (1, 1), bilinearly in between (and
// extrapolated beyond): pbrt-v4's "bilerp".
struct BilerpTexture {
  RGB v00{0.0f}, v01{1.0f}, v10{0.0f}, v11{1.0f};
  UVMapping mapping;
};
template <>
struct SchemaOf<BilerpTexture> {
  using T = BilerpTexture;
  static constexpr Field fields[] = {
      field<&T::v00>("v00", kNonNegative, "at (s, t) = (0, 0)"), field<&T::v01>("v01", kNonNegative, "at (0, 1)"),
      field<&T::v10>("v10", kNonNegative, "at (1, 0)"),          field<&T::v11>("v11", kNonNegative, "at (1, 1)"),
      uv_mapping_field<&T::mapping>(),
  };
  static constexpr TypeSchema schema{.name = "bilerp", .fields = fields,
                                     .help = "four colours at the corners of the unit square, bilinearly between"};
};

// Polka dots (pbrt-v4's "dots"): each unit cell of (s, t) around an integer point holds a dot where
// Perlin noise at the cell is positive: a disc of radius 0.35, its centre moved by noise by up to
// 0.15. `inside` on the dots, `outside` elsewhere.
struct DotsTexture {
  ColorInput inside{RGB(1.0f)}, outside{RGB(0.0f)};
  UVMapping mapping;
};
template <>
struct SchemaOf<DotsTexture> {
  using T = DotsTexture;
  static constexpr Field fields[] = {
      field<&T::inside>("inside", kNonNegative, "on the dots"),
      field<&T::outside>("outside", kNonNegative, "between them"),
      uv_mapping_field<&T::mapping>(),
  };
  static constexpr TypeSchema schema{.name = "dots", .fields = fields, .help = "polka dots placed by noise"};
};

// The solid textures below are looked up at the hit point in their own space: `to_world` maps it to
// the world (pbrt-v4: the transform current where the texture is declared).

// A solid checkerboard (pbrt-v4's checkerboard of dimension 3): tex1 in the unit cubes where
// floor(x) + floor(y) + floor(z) is even, tex2 in the others.
struct SolidCheckerboardTexture {
  ColorInput tex1{RGB(1.0f)}, tex2{RGB(0.0f)};
  Transform to_world;
};
template <>
struct SchemaOf<SolidCheckerboardTexture> {
  using T = SolidCheckerboardTexture;
  static constexpr Field fields[] = {
      field<&T::tex1>("tex1", kNonNegative, "where floor(x) + floor(y) + floor(z) is even"),
      field<&T::tex2>("tex2", kNonNegative, "where it is odd"),
      field<&T::to_world>("transform", kAnyValue, "from the texture's space to the world"),
  };
  static constexpr TypeSchema schema{.name = "solid_checkerboard", .fields = fields,
                                     .help = "a checkerboard of unit cubes in space"};
};

// Sums of Perlin noise over octaves (textures/noise.h), a grey value at the point in texture space:
// fractional Brownian motion (pbrt-v4's "fbm": octave i is roughness^i noise(1.99^i p)), or its
// turbulence (pbrt-v4's "wrinkled": the same sum of |noise|).
enum class NoiseSum { Fbm, Turbulence };
template <NoiseSum Sum>
struct NoiseTexture {
  int octaves = 8;
  float roughness = 0.5f;  // each octave's amplitude relative to the one before
  Transform to_world;
};
using FbmTexture = NoiseTexture<NoiseSum::Fbm>;
using WrinkledTexture = NoiseTexture<NoiseSum::Turbulence>;
template <NoiseSum Sum>
inline constexpr Field kNoiseTextureFields[] = {
    field<&NoiseTexture<Sum>::octaves>("octaves", ValueRange{.lo = 1, .hi = 32}),
    field<&NoiseTexture<Sum>::roughness>("roughness", kNonNegative, "each octave's amplitude relative to the last"),
    field<&NoiseTexture<Sum>::to_world>("transform", kAnyValue, "from the texture's space to the world"),
};
template <>
struct SchemaOf<FbmTexture> {
  static constexpr TypeSchema schema{.name = "fbm", .fields = kNoiseTextureFields<NoiseSum::Fbm>,
                                     .help = "fractional Brownian motion: octaves of Perlin noise"};
};
template <>
struct SchemaOf<WrinkledTexture> {
  static constexpr TypeSchema schema{.name = "wrinkled", .fields = kNoiseTextureFields<NoiseSum::Turbulence>,
                                     .help = "turbulence: octaves of the absolute value of Perlin noise"};
};

// Marble (pbrt-v4's "marble"): bands of sin(y + variation * fbm(p)) at p = scale * (the point in
// texture space), coloured through pbrt-v4's spline of greys and a dark blue-grey.
struct MarbleTexture {
  int octaves = 8;
  float roughness = 0.5f, scale = 1, variation = 0.2f;
  Transform to_world;
};
template <>
struct SchemaOf<MarbleTexture> {
  using T = MarbleTexture;
  static constexpr Field fields[] = {
      field<&T::octaves>("octaves", ValueRange{.lo = 1, .hi = 32}),
      field<&T::roughness>("roughness", kNonNegative, "each octave's amplitude relative to the last"),
      field<&T::scale>("scale", kAnyValue, "the point's scale before the pattern"),
      field<&T::variation>("variation", kAnyValue, "how far the noise bends the bands"),
      field<&T::to_world>("transform", kAnyValue, "from the texture's space to the world"),
  };
  static constexpr TypeSchema schema{.name = "marble", .fields = fields, .help = "marble veins from noise"};
};

// a tex1 + (1 - a) tex2 with a = |n . direction| at the surface's normal n (pbrt-v4's "directionmix").
struct DirectionMixTexture {
  ColorInput tex1{RGB(0.0f)}, tex2{RGB(1.0f)};
  Vec3 direction{0, 1, 0};  // unit length
};
template <>
struct SchemaOf<DirectionMixTexture> {
  using T = DirectionMixTexture;
  static constexpr Field fields[] = {
      field<&T::tex1>("tex1", kNonNegative, "where the normal is along the direction"),
      field<&T::tex2>("tex2", kNonNegative, "where it is across it"),
      direction_field<&T::direction>("direction"),
  };
  static constexpr TypeSchema schema{.name = "direction_mix", .fields = fields,
                                     .help = "two textures mixed by the normal's alignment with a direction"};
};

using TextureDesc = std::variant<ImageTexture, CheckerboardTexture, ScaleTexture, MixTexture, MeshAttributeTexture,
                                 BilerpTexture, DotsTexture, SolidCheckerboardTexture, FbmTexture, WrinkledTexture,
                                 MarbleTexture, DirectionMixTexture>;

}  // namespace candela
