#pragma once
// pbrt's graphics state: what the directives of an attribute block set for the shapes, lights and
// materials that follow (the CTMs, the material, the area light, the orientation, the medium
// interface, Attribute defaults), and the open blocks that restore it.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/pbrt/parameters.h"
#include "candela/description/scene_desc.h"

namespace candela::pbrt {

// pbrt keeps two CTMs: the transform at TransformTimes' start time and at its end time. They differ
// only where ActiveTransform made the transform directives change one of them: an animated shape.
struct TransformSet {
  Transform start, end;
  bool is_animated() const { return start != end; }
};

// Which of the two CTMs the transform directives change (ActiveTransform StartTime / EndTime / All).
enum ActiveTransforms : uint8_t { kStartTransform = 1, kEndTransform = 2, kAllTransforms = 3 };

// The current AreaLightSource. With "power", the radiance depends on the area of each shape, so
// it is computed per shape.
struct AreaLightSpec {
  RGB radiance{1.0f};  // L * scale (with an image: scale)
  bool two_sided = false;
  int texture = -1;  // the image ("filename") as a texture in SceneDesc::textures, looked up at the hit's uv
  std::optional<float> power;
  SourceLocation where;
};

// Attribute "shape" | "light" | "material" | "medium" | "texture": default parameters.
enum AttributeTarget { kShapeAttributes, kLightAttributes, kMaterialAttributes, kMediumAttributes,
                       kTextureAttributes, kAttributeTargets };

// pbrt's per-attribute-block state.
struct GraphicsState {
  TransformSet ctm;
  uint8_t active_transforms = kAllTransforms;
  int material = -1;  // -1: pbrt's default material, diffuse 0.5
  std::optional<AreaLightSpec> area_light;
  bool reverse_orientation = false;
  // MediumInterface: the media inside and outside the shapes that follow (indices into
  // SceneDesc::media, -1 = vacuum); the camera sits in the outside one.
  int inside_medium = -1, outside_medium = -1;
  std::vector<Param> attributes[kAttributeTargets];
};

enum class BlockKind { Attribute, Object };

struct OpenBlock {
  BlockKind kind;
  std::string opener;  // the directive that opened it, for messages
  SourceLocation where;
  GraphicsState saved;
};

}  // namespace candela::pbrt
