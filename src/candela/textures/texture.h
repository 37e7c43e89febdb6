#pragma once
// The scene's textures at render time: SceneDesc::textures with their images loaded, evaluated at
// surface points for material parameters (ColorInput / FloatInput).
#include <cstddef>
#include <cstdint>
#include <utility>
#include <memory>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/film/image.h"
#include "candela/math/color.h"
#include "candela/math/vec.h"
#include "candela/description/scene_desc.h"

namespace candela {

// An image texture's file read as the texture decodes it (integer texels sRGB-decoded unless the
// texture says linear), shared with every other holder of the same file (read_image_shared).
// Throws FileContentError naming the file.
std::shared_ptr<const Image> read_texture_image(const ImageTexture& texture);

// The triangle a texture is looked up on, for mesh-attribute textures: the mesh's attributes
// (null off meshes), the triangle's index and vertex indices, and the barycentric weights of its
// vertices 1 and 2 (vertex 0 has 1 - b1 - b2).
struct MeshAttributeContext {
  const std::vector<TriangleMesh::Attribute>* attributes = nullptr;
  uint32_t face = 0;
  uint32_t vertex[3] = {0, 0, 0};
  float b1 = 0, b2 = 0;
};

// Where a texture is looked up: the hit point, the surface's (u, v), on meshes the triangle, and the
// surface's normal (zero where there is no surface: lights' emission profiles).
struct TextureEvalContext {
  Point3 p;
  Vec2 uv;
  MeshAttributeContext mesh;
  Normal3 n{0, 0, 0};
};

// Immutable after construction, so any number of threads may call eval at once. Copies share the
// images.
class TextureSet {
 public:
  TextureSet() = default;
  // Loads every image once (textures naming the same file and decoding share it) and checks that
  // each texture refers only to textures before it, which also rules out cycles. Throws SceneError
  // for a bad reference or an unreadable image (naming the texture and the file).
  explicit TextureSet(const std::vector<TextureDesc>& descs, const EntryPlace& place_of = {});

  // The constant in.value, or texture in.texture; in.texture must be < size() (materials are not
  // checked here).
  RGB eval(const ColorInput& in, const TextureEvalContext& ctx) const {
    return in.texture < 0 ? in.value : eval_texture(in.texture, ctx);
  }
  // A colour texture read as a float gives the average of its channels.
  float eval(const FloatInput& in, const TextureEvalContext& ctx) const {
    return in.texture < 0 ? in.value : eval_texture(in.texture, ctx).average();
  }
  size_t size() const { return textures_.size(); }
  // The image's size in texels when texture `index` is an image; (1, 1) for the other kinds (as
  // Mitsuba's Texture::resolution).
  std::pair<int, int> resolution(int index) const;

 private:
  // An ImageTexture with its image in memory.
  struct ImageLookup {
    std::shared_ptr<const Image> image;
    TextureWrap wrap = TextureWrap::Repeat;
    bool bilinear = true;
    float scale = 1;
    bool invert = false;
    bool luminance = false;
    UVMapping mapping;
  };
  // TextureDesc's kinds with the image in memory in place of the image's description; the others
  // need nothing beyond their descriptions.
  template <typename Desc>
  struct WithImageLoaded;
  template <typename... Others>
  struct WithImageLoaded<std::variant<ImageTexture, Others...>> {
    using type = std::variant<ImageLookup, Others...>;
  };
  using Texture = WithImageLoaded<TextureDesc>::type;

  RGB eval_texture(int index, const TextureEvalContext& ctx) const;

  std::vector<Texture> textures_;
};

}  // namespace candela
