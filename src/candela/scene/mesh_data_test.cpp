// How the scene holds its meshes: moved out of the description (Scene::MeshData::Take) and shared
// with Embree in place, or in Embree's compact BVH, the image is the one the default gives; and
// the ray log (geometry/ray_log.h) sees exactly the rays the renderer counts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "candela/testing/render_helpers.h"

namespace candela {
namespace {

// A bumpy grid with normals and uvs, n x n quads over [-1, 1]^2 at height h(x, z).
TriangleMesh bumpy_grid(int n) {
  TriangleMesh m;
  auto h = [](float x, float z) { return 0.15f * std::sin(4 * x) * std::cos(3 * z); };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      float x = -1 + 2 * float(i) / float(n), z = -1 + 2 * float(j) / float(n);
      m.positions.push_back({x, h(x, z), z});
      float dx = 0.6f * std::cos(4 * x) * std::cos(3 * z), dz = -0.45f * std::sin(4 * x) * std::sin(3 * z);
      m.normals.push_back(normalize(Vec3(-dx, 1, -dz)));
      m.uvs.push_back({float(i) / float(n), float(j) / float(n)});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  return m;
}

SceneDesc mesh_scene() {
  SceneDesc d = testing::empty_scene(testing::look_at_camera({0, 2.5f, -4}, {0, 0.2f, 0}, 45), 40, 30, 8, 5);
  d.settings.seed = 3;
  d.materials.push_back(DiffuseMaterial{RGB(0.7f, 0.5f, 0.3f)});
  ConductorMaterial metal;
  metal.roughness.u = metal.roughness.v = 0.3f;
  d.materials.push_back(metal);
  ShapeDesc ground{.geometry = MeshShape{bumpy_grid(24)}, .to_world = Transform::scale({2, 1, 2}), .material = 0};
  d.shapes.push_back(ground);
  // A mirroring transform bakes a swapped winding into the shared indices.
  ShapeDesc mirrored{.geometry = MeshShape{bumpy_grid(8)},
                     .to_world = Transform::translate({0.8f, 0.6f, 0}) * Transform::scale({-0.4f, 0.4f, 0.4f}),
                     .material = 1};
  d.shapes.push_back(mirrored);
  // The same mesh inside an object, placed twice.
  ShapeDesc in_object{.geometry = MeshShape{bumpy_grid(6)}, .material = 1};
  d.objects.push_back({{in_object}, "tile"});
  d.instances.push_back({0, Transform::translate({-1, 1, 0.5f}) * Transform::scale(Vec3(0.3f)), std::nullopt});
  d.instances.push_back({0, Transform::translate({-0.3f, 1.2f, 1}) * Transform::scale(Vec3(0.25f)), std::nullopt});
  ShapeDesc light{.geometry = SphereShape{{0, 3, 0}, 0.5f}, .material = -1,
                  .emission = AreaEmission{RGB(10.0f), false}};
  d.shapes.push_back(light);
  d.lights.push_back(SkyLight{RGB(0.3f), RGB(0.3f), RGB(0.1f), {0, 1, 0}});
  return d;
}

Image render_mean(Scene& scene, const SceneDesc& d) {
  Film film(d.film.width, d.film.height);
  RenderOptions options;
  options.progress = false;
  render(scene, d.settings, film, options);
  return film.mean_image();
}

bool same_pixels(const Image& a, const Image& b) {
  return a.rgb.size() == b.rgb.size() && std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

TEST(SceneMeshData, TakingTheMeshesRendersTheSameImageAndEmptiesThem) {
  const SceneDesc original = mesh_scene();
  Scene copied(original);
  Image expected = render_mean(copied, original);

  SceneDesc taken_from = mesh_scene();
  Scene taken(taken_from, Scene::MeshData::Take);
  EXPECT_TRUE(same_pixels(render_mean(taken, taken_from), expected));
  EXPECT_EQ(taken.triangle_count(), copied.triangle_count());
  // The description's meshes were moved into the scene; everything else is left.
  EXPECT_TRUE(std::get<MeshShape>(taken_from.shapes[0].geometry).mesh.positions.empty());
  EXPECT_TRUE(std::get<MeshShape>(taken_from.shapes[1].geometry).mesh.indices.empty());
  EXPECT_TRUE(std::get<MeshShape>(taken_from.objects[0].shapes[0].geometry).mesh.positions.empty());
  EXPECT_EQ(taken_from.shapes.size(), original.shapes.size());
  EXPECT_EQ(taken_from.film.width, original.film.width);
  // Copying leaves them.
  SceneDesc kept = mesh_scene();
  Scene copied_again(kept, Scene::MeshData::Copy);
  EXPECT_EQ(std::get<MeshShape>(kept.shapes[0].geometry).mesh.positions.size(), 25u * 25u);
}

// Embree's compact layout intersects the same triangles, only from indexed vertices: the image
// agrees with the default's within its noise (the float rounding of the two intersectors may
// differ, after which paths go their own ways).
TEST(SceneMeshData, CompactBvhRendersTheSameImage) {
  SceneDesc fast = mesh_scene();
  fast.settings.spp = 64;
  SceneDesc compact = fast;
  compact.settings.bvh = BvhLayout::Compact;
  Film a = testing::render_description(fast), b = testing::render_description(compact);
  int compared = 0;
  double worst = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      RGB ma = a.pixel(x, y).mean(), mb = b.pixel(x, y).mean();
      RGB sa = a.pixel(x, y).standard_error(), sb = b.pixel(x, y).standard_error();
      for (int c = 0; c < 3; ++c) {
        double se = std::sqrt(double(sa[c]) * sa[c] + double(sb[c]) * sb[c]);
        if (se == 0) {
          EXPECT_EQ(ma[c], mb[c]) << "pixel " << x << "," << y;
          continue;
        }
        worst = std::max(worst, std::abs(double(ma[c]) - mb[c]) / se);
        ++compared;
      }
    }
  // 3600 pixel-channels: a difference beyond 6 standard errors has probability ~1e-5 under agreement.
  EXPECT_LT(worst, 6.0);
  EXPECT_GT(compared, 1000);
  // And a wrong layout would show: the image is not empty.
  EXPECT_GT(a.mean_image().rgb[size_t(3 * (15 * a.width() + 20))], 0.0f);
}

TEST(SceneMeshData, RayLogHoldsExactlyTheRaysTheRendererCounts) {
  SceneDesc d = mesh_scene();
  Scene scene(d);
  RayLog log;
  scene.embree().set_ray_log(&log);
  Film film(d.film.width, d.film.height);
  RenderOptions options;
  options.progress = false;
  options.threads = 2;
  RenderStats stats = render(scene, d.settings, film, options);
  scene.embree().set_ray_log(nullptr);
  std::vector<RecordedRay> rays = log.take();
  size_t shadow = 0;
  for (const RecordedRay& r : rays) shadow += r.occlusion;
  EXPECT_EQ(rays.size(), stats.rays.total());
  EXPECT_EQ(shadow, stats.rays.shadow);
  EXPECT_EQ(rays.size() - shadow, stats.rays.camera + stats.rays.bounce);
  EXPECT_EQ(stats.rays.camera, uint64_t(d.film.width) * d.film.height * uint64_t(d.settings.spp));
  // Detached, the log records nothing more.
  render(scene, d.settings, film, options);
  EXPECT_TRUE(log.take().empty());
}

}  // namespace
}  // namespace candela
