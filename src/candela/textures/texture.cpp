#include "candela/textures/texture.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <iterator>
#include <filesystem>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

#include "candela/film/image_io.h"
#include "candela/base/error.h"
#include "candela/base/overloaded.h"
#include "candela/textures/noise.h"

namespace candela {
namespace {

// The (u, v) the mapping's affine map starts from (description/textures.h's TextureProjection).
Vec2 projected_uv(const UVMapping& m, const TextureEvalContext& ctx) {
  if (m.projection == TextureProjection::Surface) return ctx.uv;
  const Point3 p = m.to_world.inverse().point(ctx.p);
  switch (m.projection) {
    case TextureProjection::Surface: break;
    case TextureProjection::Spherical: {
      const Vec3 d = normalize(p);
      float phi = std::atan2(d.y, d.x);
      if (phi < 0) phi += 2 * kPi;
      return {std::acos(std::clamp(d.z, -1.0f, 1.0f)) / kPi, phi / (2 * kPi)};
    }
    case TextureProjection::Cylindrical: return {(kPi + std::atan2(p.y, p.x)) / (2 * kPi), p.z};
    case TextureProjection::Planar: return {dot(p, m.planar_s), dot(p, m.planar_t)};
  }
  return ctx.uv;
}

Vec2 apply_mapping(const UVMapping& m, const TextureEvalContext& ctx) {
  const Vec2 uv = projected_uv(m, ctx);
  return {m.su * uv.x + m.s_from_v * uv.y + m.du, m.t_from_u * uv.x + m.sv * uv.y + m.dv};
}

// floor(x) as an int, kept far inside int's range (and NaN made definite) so that the index
// arithmetic below never overflows; coordinates that large have no precision left anyway.
int floor_index(float x) {
  constexpr float kLimit = float(1 << 30);
  if (!(x > -kLimit)) return -(1 << 30);
  if (!(x < kLimit)) return 1 << 30;
  return int(std::floor(x));
}

// Texel index i of a row or column of n texels, after wrapping; -1 for Black outside the image.
int wrap_index(int i, int n, TextureWrap wrap) {
  if (i >= 0 && i < n) return i;  // the common case, without the divisions below
  switch (wrap) {
    case TextureWrap::Repeat: {
      int r = i % n;
      return r < 0 ? r + n : r;
    }
    case TextureWrap::Clamp:
      return i < 0 ? 0 : n - 1;
    case TextureWrap::Black:
      return -1;
    case TextureWrap::Mirror: {
      // Period 2n: n texels forward, then the same n backwards, so -1 -> 0 and n -> n - 1.
      int period = 2 * n;
      int r = i % period;
      if (r < 0) r += period;
      return r < n ? r : period - 1 - r;
    }
  }
  return -1;
}

// The texel at wrapped indices; -1 (Black outside) reads zero.
RGB texel(const Image& image, int x, int y) { return x < 0 || y < 0 ? RGB(0.0f) : image.at(x, y); }

// The fractional part of a coordinate relative to its floor_index, kept in [0, 1] (NaN -> 0).
float fraction(float x, int x0) {
  float f = x - float(x0);
  return f > 0 ? (f < 1 ? f : 1.0f) : 0.0f;
}

// (s, t) in texture space -> filtered texel value. Image rows run top to bottom while t runs up,
// hence 1 - t; texel (i, j) covers [i, i + 1) x [j, j + 1) in pixel units, its centre at +0.5.
RGB lookup(const Image& image, TextureWrap wrap, bool bilinear, Vec2 st) {
  const int w = image.width, h = image.height;
  float x = st.x * float(w), y = (1 - st.y) * float(h);
  if (!bilinear) return texel(image, wrap_index(floor_index(x), w, wrap), wrap_index(floor_index(y), h, wrap));
  x -= 0.5f;
  y -= 0.5f;
  int x0 = floor_index(x), y0 = floor_index(y);
  float fx = fraction(x, x0), fy = fraction(y, y0);
  // Wrapping each index of the 2x2 footprint separately makes Repeat blend across the seam, Clamp
  // hold the edge texel and Black fade to zero over the outer half texel.
  int xa = wrap_index(x0, w, wrap), xb = wrap_index(x0 + 1, w, wrap);
  int ya = wrap_index(y0, h, wrap), yb = wrap_index(y0 + 1, h, wrap);
  RGB top = (1 - fx) * texel(image, xa, ya) + fx * texel(image, xb, ya);
  RGB bottom = (1 - fx) * texel(image, xa, yb) + fx * texel(image, xb, yb);
  return (1 - fy) * top + fy * bottom;
}

RGB clamp_zero(RGB c) { return {std::max(c.r, 0.0f), std::max(c.g, 0.0f), std::max(c.b, 0.0f)}; }

// Calls f with every texture index a description refers to (-1 for constants), for validation.
template <typename F>
void for_each_reference(const TextureDesc& desc, F&& f) {
  std::visit(overloaded{[&](const CheckerboardTexture& c) {
                          f(c.tex1.texture);
                          f(c.tex2.texture);
                        },
                        [&](const ScaleTexture& s) {
                          f(s.tex.texture);
                          f(s.scale.texture);
                        },
                        [&](const MixTexture& m) {
                          f(m.tex1.texture);
                          f(m.tex2.texture);
                          f(m.amount.texture);
                        },
                        [&](const DotsTexture& d) {
                          f(d.inside.texture);
                          f(d.outside.texture);
                        },
                        [&](const SolidCheckerboardTexture& c) {
                          f(c.tex1.texture);
                          f(c.tex2.texture);
                        },
                        [&](const DirectionMixTexture& m) {
                          f(m.tex1.texture);
                          f(m.tex2.texture);
                        },
                        [](const ImageTexture&) {}, [](const MeshAttributeTexture&) {}, [](const BilerpTexture&) {},
                        [](const FbmTexture&) {}, [](const WrinkledTexture&) {}, [](const MarbleTexture&) {}},
             desc);
}

// A mesh attribute at the hit (Mitsuba's mesh_attribute): per vertex, interpolated with the
// barycentrics; per face, the triangle's value. One channel reads as grey. Zero off meshes and
// where the mesh has no attribute of that name.
RGB eval_mesh_attribute(const MeshAttributeTexture& t, const MeshAttributeContext& m) {
  if (!m.attributes) return RGB(0.0f);
  for (const TriangleMesh::Attribute& a : *m.attributes) {
    if (a.name != t.name || a.per_face != t.per_face) continue;
    const size_t c = size_t(a.channels == 3 ? 3 : 1);
    auto value = [&](size_t element) {
      size_t i = element * c;
      if (i + c > a.values.size()) return RGB(0.0f);
      return c == 3 ? RGB(a.values[i], a.values[i + 1], a.values[i + 2]) : RGB(a.values[i]);
    };
    if (a.per_face) return value(m.face);
    return value(m.vertex[0]) * (1 - m.b1 - m.b2) + value(m.vertex[1]) * m.b1 + value(m.vertex[2]) * m.b2;
  }
  return RGB(0.0f);
}

// Whether (s, t) falls on one of pbrt-v4's polka dots: the cell around the nearest integer point has
// a dot where the noise there is positive, its centre moved by noise.
bool inside_polka_dot(Vec2 st) {
  const float s_cell = std::floor(st.x + 0.5f), t_cell = std::floor(st.y + 0.5f);
  if (!(perlin_noise({s_cell + 0.5f, t_cell + 0.5f, 0.5f}) > 0)) return false;
  constexpr float kRadius = 0.35f, kMaxShift = 0.5f - kRadius;
  const float s_centre = s_cell + kMaxShift * perlin_noise({s_cell + 1.5f, t_cell + 2.8f, 0.5f});
  const float t_centre = t_cell + kMaxShift * perlin_noise({s_cell + 4.5f, t_cell + 9.8f, 0.5f});
  const float ds = st.x - s_centre, dt = st.y - t_centre;
  return ds * ds + dt * dt < kRadius * kRadius;
}

// pbrt-v4's marble colour at t in [0, 1]: a cubic Bezier spline through nine control colours (each
// segment of four), times 1.5.
RGB marble_colour(float t) {
  static constexpr RGB kControl[] = {{.58f, .58f, .6f}, {.58f, .58f, .6f}, {.58f, .58f, .6f},
                                     {.5f, .5f, .5f},   {.6f, .59f, .58f}, {.58f, .58f, .6f},
                                     {.58f, .58f, .6f}, {.2f, .2f, .33f},  {.58f, .58f, .6f}};
  constexpr int kSegments = int(std::size(kControl)) - 3;
  const int first = std::clamp(int(std::floor(t * kSegments)), 0, kSegments - 1);
  const float u = t * kSegments - float(first);
  // De Casteljau's construction on the segment's four control points.
  RGB p[4] = {kControl[first], kControl[first + 1], kControl[first + 2], kControl[first + 3]};
  for (int level = 3; level > 0; --level)
    for (int i = 0; i < level; ++i) p[i] = (1 - u) * p[i] + u * p[i + 1];
  return 1.5f * p[0];
}

// The point in a solid texture's own space.
Point3 texture_space(const Transform& to_world, Point3 p) { return to_world.inverse().point(p); }

}  // namespace

std::pair<int, int> TextureSet::resolution(int index) const {
  if (index < 0 || size_t(index) >= textures_.size()) return {1, 1};
  using Resolution = std::pair<int, int>;
  return std::visit(overloaded{[](const ImageLookup& t) {
                                 return Resolution{std::max(1, t.image->width), std::max(1, t.image->height)};
                               },
                               // not images
                               [](const auto&) { return Resolution{1, 1}; }},
                    textures_[size_t(index)]);
}

std::shared_ptr<const Image> read_texture_image(const ImageTexture& texture) {
  return read_image_shared(texture.filename,
                           texture.encoding == ColorEncoding::Linear ? IntegerEncoding::Linear : IntegerEncoding::SRGB);
}

TextureSet::TextureSet(const std::vector<TextureDesc>& descs, const EntryPlace& place_of) {
  auto name = [&](size_t i) { return place_of ? fmt::format("{}: texture {}", place_of(i), i) : fmt::format("texture {}", i); };
  textures_.reserve(descs.size());
  for (size_t i = 0; i < descs.size(); ++i) {
    for_each_reference(descs[i], [&](int ref) {
      if (ref < 0) return;
      if (size_t(ref) >= descs.size())
        throw SceneError(fmt::format("{}: refers to texture {}, but there are only {} textures", name(i), ref,
                                     descs.size()));
      if (size_t(ref) == i) throw SceneError(fmt::format("{}: refers to itself", name(i)));
      if (size_t(ref) > i)
        throw SceneError(fmt::format("{}: refers to texture {}, which comes after it (a cycle, or dependencies out of order)", name(i),
            ref));
    });

    if (const auto* desc = std::get_if<ImageTexture>(&descs[i])) {
      // Textures of the same file with the same decoding (Auto and SRGB alike) share one image.
      std::shared_ptr<const Image> image;
      try {
        image = read_texture_image(*desc);
      } catch (const std::exception& e) {
        std::error_code ec;
        if (!std::filesystem::exists(desc->filename, ec))
          throw SceneError(fmt::format("{}: image file \"{}\" not found", name(i), desc->filename));
        // read_image's message already names the file.
        throw SceneError(fmt::format("{}: {}", name(i), e.what()));
      }
      textures_.emplace_back(ImageLookup{image, desc->wrap, desc->filter == TextureFilter::Bilinear, desc->scale, desc->invert, desc->luminance, desc->mapping});
    } else {
      std::visit(
          [&](const auto& d) {
            if constexpr (!std::is_same_v<std::decay_t<decltype(d)>, ImageTexture>) textures_.emplace_back(d);
          },
          descs[i]);
    }
  }
}

RGB TextureSet::eval_texture(int index, const TextureEvalContext& ctx) const {
  return std::visit(
      overloaded{
          [&](const ImageLookup& t) {
            RGB v = t.scale * lookup(*t.image, t.wrap, t.bilinear, apply_mapping(t.mapping, ctx));
            if (t.luminance) v = RGB(v.luminance());
            return clamp_zero(t.invert ? RGB(1.0f) - v : v);  // pbrt-v4 clamps negative results too
          },
          [&](const CheckerboardTexture& t) {
            Vec2 st = apply_mapping(t.mapping, ctx);
            // Sum in 64 bits: floor_index's range makes the sum fit, and & 1 is the parity for negatives too.
            bool even = ((int64_t(floor_index(st.x)) + floor_index(st.y)) & 1) == 0;
            return eval(even ? t.tex1 : t.tex2, ctx);
          },
          [&](const ScaleTexture& t) { return eval(t.tex, ctx) * eval(t.scale, ctx); },
          [&](const MeshAttributeTexture& t) { return eval_mesh_attribute(t, ctx.mesh); },
          [&](const BilerpTexture& t) {
            const Vec2 st = apply_mapping(t.mapping, ctx);
            return (1 - st.x) * (1 - st.y) * t.v00 + st.x * (1 - st.y) * t.v10 + (1 - st.x) * st.y * t.v01 +
                   st.x * st.y * t.v11;
          },
          [&](const DotsTexture& t) {
            return eval(inside_polka_dot(apply_mapping(t.mapping, ctx)) ? t.inside : t.outside, ctx);
          },
          [&](const SolidCheckerboardTexture& t) {
            const Point3 p = texture_space(t.to_world, ctx.p);
            const int64_t sum = int64_t(floor_index(p.x)) + floor_index(p.y) + floor_index(p.z);
            return eval((sum & 1) == 0 ? t.tex1 : t.tex2, ctx);
          },
          [&](const FbmTexture& t) { return RGB(fbm(texture_space(t.to_world, ctx.p), t.roughness, t.octaves)); },
          [&](const WrinkledTexture& t) {
            return RGB(turbulence(texture_space(t.to_world, ctx.p), t.roughness, t.octaves));
          },
          [&](const MarbleTexture& t) {
            const Point3 p = t.scale * texture_space(t.to_world, ctx.p);
            const float bands = p.y + t.variation * fbm(p, t.roughness, t.octaves);
            return marble_colour(0.5f + 0.5f * std::sin(bands));
          },
          [&](const DirectionMixTexture& t) {
            const float amount = std::abs(dot(Vec3(ctx.n), t.direction));
            // As mix: a side with weight zero is not evaluated.
            RGB result(0.0f);
            if (amount != 0) result += amount * eval(t.tex1, ctx);
            if (amount != 1) result += (1 - amount) * eval(t.tex2, ctx);
            return result;
          },
          [&](const MixTexture& t) {
            float amount = eval(t.amount, ctx);
            // A side with weight zero is not evaluated (as in pbrt-v4): cheaper, and an infinite value
            // there cannot turn the result into NaN.
            RGB result(0.0f);
            if (amount != 1) result += (1 - amount) * eval(t.tex1, ctx);
            if (amount != 0) result += amount * eval(t.tex2, ctx);
            return result;
          }},
      textures_[size_t(index)]);
}

}  // namespace candela
