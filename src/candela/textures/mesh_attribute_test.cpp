// Mesh-attribute textures (Mitsuba's mesh_attribute): per-vertex values interpolated with the
// hit's barycentrics, per-face values constant over their triangle, 1 or 3 channels, found through
// Scene::texture_context at real ray hits (also when a mirroring transform reverses the winding).
#include <gtest/gtest.h>

#include "candela/scene/scene.h"
#include "candela/textures/texture.h"

namespace candela {
namespace {

// Two triangles over [0,2] x [0,1] in z = 0: (0,1,2) and (1,3,2).
TriangleMesh attributed_quad() {
  TriangleMesh m;
  m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 1, 0}, {2, 1, 0}};
  m.indices = {0, 1, 2, 1, 3, 2};
  m.attributes.push_back({"color", false, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1}});
  m.attributes.push_back({"weight", false, 1, {0, 1, 2, 3}});
  m.attributes.push_back({"id", true, 1, {5, 7}});
  m.attributes.push_back({"tint", true, 3, {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f}});
  // A face attribute with a vertex attribute's name (Mitsuba's face_color beside vertex_color).
  m.attributes.push_back({"color", true, 3, {0.7f, 0.8f, 0.9f, 0.2f, 0.3f, 0.4f}});
  return m;
}

// The attributes at (x, y), computed from the layout above: barycentrics in the triangle holding it.
struct Expected {
  RGB color;
  float weight, id;
  RGB tint;
};
Expected expected_at(float x, float y) {
  const RGB c[4] = {RGB(1, 0, 0), RGB(0, 1, 0), RGB(0, 0, 1), RGB(1, 1, 1)};
  const float w[4] = {0, 1, 2, 3};
  if (x / 2 + y <= 1) {  // triangle 0: p = v0 + b1 (v1 - v0) + b2 (v2 - v0)
    float b1 = x / 2, b2 = y, b0 = 1 - b1 - b2;
    return {c[0] * b0 + c[1] * b1 + c[2] * b2, w[0] * b0 + w[1] * b1 + w[2] * b2, 5, RGB(0.1f, 0.2f, 0.3f)};
  }
  // Triangle 1 (v1, v3, v2): p = v1 + b1 (v3 - v1) + b2 (v2 - v1).
  float b2 = 1 - x / 2, b1 = y - b2, b0 = 1 - b1 - b2;
  return {c[1] * b0 + c[3] * b1 + c[2] * b2, w[1] * b0 + w[3] * b1 + w[2] * b2, 7, RGB(0.4f, 0.5f, 0.6f)};
}

TEST(MeshAttributeTexture, InterpolatesVertexValuesAndReadsFaceValuesAtHits) {
  std::vector<TextureDesc> descs{MeshAttributeTexture{"color"},      MeshAttributeTexture{"weight"},
                                 MeshAttributeTexture{"id", true},  MeshAttributeTexture{"tint", true},
                                 MeshAttributeTexture{"missing"},   MeshAttributeTexture{"color", true}};
  TextureSet textures(descs);
  auto color = [&](int i, const TextureEvalContext& ctx) {
    ColorInput in;
    in.texture = i;
    return textures.eval(in, ctx);
  };
  for (bool mirrored : {false, true}) {
    SceneDesc d;
    d.textures = descs;
    ShapeDesc s;
    s.geometry = MeshShape{attributed_quad()};
    // Mirroring in z swaps the winding candela bakes in; the values must not notice.
    s.to_world = mirrored ? Transform::scale({1, 1, -1}) : Transform();
    d.shapes = {s};
    Scene scene(d);
    for (float y = 0.05f; y < 1; y += 0.1f)
      for (float x = 0.07f; x < 2; x += 0.15f) {
        SurfaceHit hit;
        ASSERT_TRUE(scene.intersect(Ray{{x, y, 1}, {0, 0, -1}, std::numeric_limits<float>::infinity(), 0}, hit));
        TextureEvalContext ctx = scene.texture_context(hit);
        Expected e = expected_at(x, y);
        std::string what = "at " + std::to_string(x) + ", " + std::to_string(y) + (mirrored ? " mirrored" : "");
        RGB c = color(0, ctx);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], e.color[k], 1e-5f) << what;
        RGB wgt = color(1, ctx);  // one channel reads as grey
        EXPECT_NEAR(wgt.r, e.weight, 1e-5f) << what;
        EXPECT_EQ(wgt.r, wgt.g);
        EXPECT_EQ(wgt.r, wgt.b);
        FloatInput fin;
        fin.texture = 1;
        EXPECT_NEAR(textures.eval(fin, ctx), e.weight, 1e-5f) << what;
        EXPECT_EQ(color(2, ctx).g, e.id) << what;
        EXPECT_EQ(color(3, ctx), e.tint) << what;
        EXPECT_EQ(color(4, ctx), RGB(0.0f)) << what;  // no such attribute
        EXPECT_EQ(color(5, ctx), x / 2 + y <= 1 ? RGB(0.7f, 0.8f, 0.9f) : RGB(0.2f, 0.3f, 0.4f)) << what;
      }
  }
  // Off meshes (no triangle in the context) an attribute is zero.
  EXPECT_EQ(color(0, TextureEvalContext{{0, 0, 0}, {0.5f, 0.5f}}), RGB(0.0f));
}

}  // namespace
}  // namespace candela
