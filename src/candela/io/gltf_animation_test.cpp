// Tests of the glTF reader's animation (io/gltf/animation.cpp): Khronos' six animated samples
// (../shared/meshes/gltf-animated: node TRS channels, morph weights, skins) read into
// SceneDesc::animation give, at times on and between keyframes, the vertex positions that an
// independent evaluation of the glTF specification's formulas (written here, straight from the
// file's JSON) gives; step and cubic-spline keyframes in small hand-made files give the values the
// formulas give by hand; broken animation data fails naming its JSON pointer.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "candela/base/error.h"
#include "candela/description/scene_desc.h"
#include "candela/io/gltf_reader.h"

namespace candela::gltf_animation_test {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kAnimated = fs::path(CANDELA_SHARED_DIR) / "meshes/gltf-animated";

fs::path sample(const std::string& name) { return kAnimated / name / (name + ".gltf"); }

SceneDesc load(const fs::path& file) {
  Warnings warnings;
  return read_gltf_scene(file, warnings);
}

// ---------------------------------------------------------------- reference evaluation
// Independent of animation/keyframes.cpp: column-major 4x4 matrices as glTF stores them, and the
// specification's formulas (node hierarchy, linear / spherical / step / cubic Hermite keyframes,
// skin joint matrices, morph weights) applied to the file's JSON.

using P3 = std::array<double, 3>;
struct Mat {
  std::array<double, 16> a{};  // a[column * 4 + row]
  double& at(int r, int c) { return a[size_t(c * 4 + r)]; }
  double at(int r, int c) const { return a[size_t(c * 4 + r)]; }
};

Mat mat_identity() {
  Mat m;
  for (int i = 0; i < 4; ++i) m.at(i, i) = 1;
  return m;
}

Mat operator*(const Mat& x, const Mat& y) {
  Mat m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k) m.at(r, c) += x.at(r, k) * y.at(k, c);
  return m;
}

P3 transform_point(const Mat& m, const P3& p) {
  P3 out;
  for (int r = 0; r < 3; ++r) out[size_t(r)] = m.at(r, 0) * p[0] + m.at(r, 1) * p[1] + m.at(r, 2) * p[2] + m.at(r, 3);
  return out;
}

// T * R * S, the rotation from a unit quaternion (x, y, z, w).
Mat compose(const std::vector<double>& t, const std::vector<double>& q, const std::vector<double>& s) {
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                          {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                          {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
  Mat m = mat_identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.at(i, j) = r[i][j] * s[size_t(j)];
    m.at(i, 3) = t[size_t(i)];
  }
  return m;
}

std::vector<double> normalized(std::vector<double> q) {
  double n = 0;
  for (double v : q) n += v * v;
  n = std::sqrt(n);
  for (double& v : q) v /= n;
  return q;
}

// The specification's spherical linear interpolation (the shorter arc).
std::vector<double> slerp(const std::vector<double>& a, std::vector<double> b, double s) {
  double d = 0;
  for (int i = 0; i < 4; ++i) d += a[size_t(i)] * b[size_t(i)];
  if (d < 0) {
    d = -d;
    for (double& v : b) v = -v;
  }
  std::vector<double> out(4);
  if (d > 0.99999) {
    for (int i = 0; i < 4; ++i) out[size_t(i)] = (1 - s) * a[size_t(i)] + s * b[size_t(i)];
    return normalized(out);
  }
  const double theta = std::acos(d);
  for (int i = 0; i < 4; ++i)
    out[size_t(i)] = (std::sin((1 - s) * theta) * a[size_t(i)] + std::sin(s * theta) * b[size_t(i)]) / std::sin(theta);
  return out;
}

// glTF's cubic Hermite spline between keys k and k + 1: v_k, its out-tangent b_k, v_k+1, its
// in-tangent a_k+1, dt = t_k+1 - t_k, s in [0, 1].
double hermite(double v0, double b0, double v1, double a1, double dt, double s) {
  const double s2 = s * s, s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * v0 + (s3 - 2 * s2 + s) * dt * b0 + (-2 * s3 + 3 * s2) * v1 + (s3 - s2) * dt * a1;
}

std::string base64_decode(const std::string& text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::string out;
  int bits = 0, held = 0;
  for (char c : text) {
    const int v = value(c);
    if (v < 0) continue;  // padding
    held = (held << 6) | v;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += char((held >> bits) & 0xff);
    }
  }
  return out;
}

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class Reference {
 public:
  explicit Reference(const fs::path& file) {
    std::ifstream in(file);
    j_ = Json::parse(in);
    for (const Json& b : j_["buffers"]) {
      const std::string uri = b["uri"];
      buffers_.push_back(uri.starts_with("data:") ? base64_decode(uri.substr(uri.find(',') + 1))
                                                  : read_bytes(file.parent_path() / uri));
    }
    parent_.assign(j_["nodes"].size(), -1);
    for (size_t n = 0; n < j_["nodes"].size(); ++n)
      for (int c : j_["nodes"][n].value("children", std::vector<int>{})) parent_[size_t(c)] = int(n);
  }

  const Json& json() const { return j_; }

  // Accessor i's elements, each its components as doubles.
  std::vector<std::vector<double>> accessor(int i) const {
    const Json& a = j_["accessors"][size_t(i)];
    const Json& view = j_["bufferViews"][size_t(a["bufferView"].get<int>())];
    const std::string type = a["type"];
    const int components = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 16;
    const int kind = a["componentType"];
    const bool normalized = a.value("normalized", false);
    const size_t size = kind == 5120 || kind == 5121 ? 1 : kind == 5122 || kind == 5123 ? 2 : 4;
    const size_t stride = view.value("byteStride", size_t(components) * size);
    const std::string& buffer = buffers_[size_t(view["buffer"].get<int>())];
    const size_t start = view.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0));
    std::vector<std::vector<double>> out(a["count"].get<size_t>(), std::vector<double>(size_t(components)));
    for (size_t e = 0; e < out.size(); ++e)
      for (size_t c = 0; c < size_t(components); ++c) {
        const char* p = buffer.data() + start + e * stride + c * size;
        double v = 0;
        switch (kind) {
          case 5120: { int8_t x; std::memcpy(&x, p, 1); v = normalized ? std::max(x / 127.0, -1.0) : x; break; }
          case 5121: { uint8_t x; std::memcpy(&x, p, 1); v = normalized ? x / 255.0 : x; break; }
          case 5122: { int16_t x; std::memcpy(&x, p, 2); v = normalized ? std::max(x / 32767.0, -1.0) : x; break; }
          case 5123: { uint16_t x; std::memcpy(&x, p, 2); v = normalized ? x / 65535.0 : x; break; }
          case 5125: { uint32_t x; std::memcpy(&x, p, 4); v = x; break; }
          default: { float x; std::memcpy(&x, p, 4); v = x; break; }
        }
        out[e][c] = v;
      }
    return out;
  }

  // Every keyframe time of the file, sorted.
  std::vector<double> key_times() const {
    std::set<double> times;
    for (const Json& anim : j_.value("animations", Json::array()))
      for (const Json& s : anim["samplers"])
        for (const auto& e : accessor(s["input"])) times.insert(e[0]);
    return {times.begin(), times.end()};
  }

  // The value that channel `path` of node n has at time t (the first channel targeting it), or
  // nothing when no channel targets it.
  std::optional<std::vector<double>> animated(int n, const std::string& path, double t) const {
    for (const Json& anim : j_.value("animations", Json::array()))
      for (const Json& channel : anim["channels"]) {
        if (channel["target"]["node"] != n || channel["target"]["path"] != path) continue;
        const Json& sampler = anim["samplers"][size_t(channel["sampler"].get<int>())];
        return sample(sampler, path == "rotation", t);
      }
    return std::nullopt;
  }

  std::vector<double> sample(const Json& sampler, bool rotation, double t) const {
    std::vector<double> times;
    for (const auto& e : accessor(sampler["input"])) times.push_back(e[0]);
    std::vector<double> flat;
    for (const auto& e : accessor(sampler["output"])) flat.insert(flat.end(), e.begin(), e.end());
    const std::string how = sampler.value("interpolation", std::string("LINEAR"));
    const bool cubic = how == "CUBICSPLINE";
    const size_t width = flat.size() / times.size() / (cubic ? 3 : 1);
    // Key k's value, in-tangent and out-tangent.
    auto part = [&](size_t k, size_t which) {
      const size_t at = cubic ? (3 * k + which) * width : k * width;
      return std::vector<double>(flat.begin() + std::ptrdiff_t(at), flat.begin() + std::ptrdiff_t(at + width));
    };
    auto value = [&](size_t k) { return part(k, 1); };
    if (t <= times.front()) return value(0);
    if (t >= times.back()) return value(times.size() - 1);
    size_t k = 0;
    while (!(t >= times[k] && t < times[k + 1])) ++k;
    const double dt = times[k + 1] - times[k], s = (t - times[k]) / dt;
    if (how == "STEP") return value(k);
    if (!cubic) {
      if (rotation) return slerp(value(k), value(k + 1), s);
      std::vector<double> out(width);
      for (size_t i = 0; i < width; ++i) out[i] = (1 - s) * value(k)[i] + s * value(k + 1)[i];
      return out;
    }
    std::vector<double> out(width);
    const std::vector<double> v0 = value(k), b0 = part(k, 2), v1 = value(k + 1), a1 = part(k + 1, 0);
    for (size_t i = 0; i < width; ++i) out[i] = hermite(v0[i], b0[i], v1[i], a1[i], dt, s);
    return rotation ? normalized(out) : out;
  }

  Mat local(int n, double t) const {
    const Json& node = j_["nodes"][size_t(n)];
    if (node.contains("matrix")) {
      Mat m;
      for (int i = 0; i < 16; ++i) m.a[size_t(i)] = node["matrix"][size_t(i)];
      return m;
    }
    std::vector<double> tr = node.value("translation", std::vector<double>{0, 0, 0});
    std::vector<double> q = node.value("rotation", std::vector<double>{0, 0, 0, 1});
    std::vector<double> sc = node.value("scale", std::vector<double>{1, 1, 1});
    if (auto v = animated(n, "translation", t)) tr = *v;
    if (auto v = animated(n, "rotation", t)) q = *v;
    if (auto v = animated(n, "scale", t)) sc = *v;
    return compose(tr, normalized(q), sc);
  }

  Mat global(int n, double t) const { return parent_[size_t(n)] < 0 ? local(n, t) : global(parent_[size_t(n)], t) * local(n, t); }

  // The (node, primitive) pairs of the default scene in depth-first order, as the reader makes shapes.
  std::vector<std::pair<int, int>> drawn() const {
    std::vector<std::pair<int, int>> out;
    std::function<void(int)> visit = [&](int n) {
      const Json& node = j_["nodes"][size_t(n)];
      if (node.contains("mesh"))
        for (size_t p = 0; p < j_["meshes"][size_t(node["mesh"].get<int>())]["primitives"].size(); ++p)
          out.emplace_back(n, int(p));
      for (int c : node.value("children", std::vector<int>{})) visit(c);
    };
    for (int root : j_["scenes"][size_t(j_.value("scene", 0))]["nodes"]) visit(root);
    return out;
  }

  // Primitive p of node n's mesh at time t, its vertices in world space: morphed, then skinned or
  // placed by the node.
  std::vector<P3> vertices(int n, int p, double t) const {
    const Json& node = j_["nodes"][size_t(n)];
    const Json& mesh = j_["meshes"][size_t(node["mesh"].get<int>())];
    const Json& prim = mesh["primitives"][size_t(p)];
    std::vector<P3> out;
    for (const auto& e : accessor(prim["attributes"]["POSITION"])) out.push_back({e[0], e[1], e[2]});
    if (prim.contains("targets")) {
      const size_t targets = prim["targets"].size();
      std::vector<double> w(targets, 0.0);
      if (auto v = animated(n, "weights", t)) w = *v;
      else if (node.contains("weights")) w = node["weights"].get<std::vector<double>>();
      else if (mesh.contains("weights")) w = mesh["weights"].get<std::vector<double>>();
      for (size_t k = 0; k < targets; ++k) {
        if (!prim["targets"][k].contains("POSITION")) continue;
        const auto d = accessor(prim["targets"][k]["POSITION"]);
        for (size_t v = 0; v < out.size(); ++v)
          for (int c = 0; c < 3; ++c) out[v][size_t(c)] += w[k] * d[v][size_t(c)];
      }
    }
    if (!node.contains("skin")) {
      const Mat m = global(n, t);
      for (P3& q : out) q = transform_point(m, q);
      return out;
    }
    const Json& skin = j_["skins"][size_t(node["skin"].get<int>())];
    std::vector<Mat> joint_matrices;
    const auto ibm = skin.contains("inverseBindMatrices") ? accessor(skin["inverseBindMatrices"])
                                                          : std::vector<std::vector<double>>{};
    for (size_t j = 0; j < skin["joints"].size(); ++j) {
      Mat inverse_bind = mat_identity();
      if (!ibm.empty())
        for (int i = 0; i < 16; ++i) inverse_bind.a[size_t(i)] = ibm[j][size_t(i)];
      joint_matrices.push_back(global(skin["joints"][j], t) * inverse_bind);
    }
    std::vector<Mat> skin_matrices(out.size());
    for (int set = 0; prim["attributes"].contains(fmt::format("JOINTS_{}", set)); ++set) {
      const auto joints = accessor(prim["attributes"][fmt::format("JOINTS_{}", set)]);
      const auto weights = accessor(prim["attributes"][fmt::format("WEIGHTS_{}", set)]);
      for (size_t v = 0; v < out.size(); ++v)
        for (size_t i = 0; i < 4; ++i)
          for (size_t e = 0; e < 16; ++e)
            skin_matrices[v].a[e] += weights[v][i] * joint_matrices[size_t(joints[v][i])].a[e];
    }
    for (size_t v = 0; v < out.size(); ++v) out[v] = transform_point(skin_matrices[v], out[v]);
    return out;
  }

 private:
  Json j_;
  std::vector<std::string> buffers_;
  std::vector<int> parent_;
};

// ---------------------------------------------------------------- the description's evaluation

// A shape's vertices in world space at time t, as the description places them.
std::vector<P3> described_vertices(const SceneDesc& scene, const ShapeDesc& shape, float t) {
  const TriangleMesh& mesh = std::get<MeshShape>(shape.geometry).mesh;
  std::vector<Point3> positions = mesh.positions;
  std::vector<Normal3> normals = mesh.normals;
  if (shape.deformation >= 0)
    scene.animation.deform(scene.animation.deformations[size_t(shape.deformation)], t, positions, normals);
  Matrix4 m = shape.to_world.matrix();
  if (shape.animation_node >= 0) m = scene.animation.world_matrix(shape.animation_node, t) * m;
  std::vector<P3> out;
  for (const Point3& p : positions)
    out.push_back({m.m[0][0] * p.x + m.m[0][1] * p.y + m.m[0][2] * p.z + m.m[0][3],
                   m.m[1][0] * p.x + m.m[1][1] * p.y + m.m[1][2] * p.z + m.m[1][3],
                   m.m[2][0] * p.x + m.m[2][1] * p.y + m.m[2][2] * p.z + m.m[2][3]});
  return out;
}

// Times to compare at: before the first key, on the keys' ends, between keys, after the last.
std::vector<double> test_times(const std::vector<double>& keys) {
  std::vector<double> times = {keys.front() - 0.5, 0.0, keys.front(), keys.back(), keys.back() + 1};
  const size_t step = std::max<size_t>(1, keys.size() / 8);
  for (size_t k = 0; k + 1 < keys.size(); k += step) {
    times.push_back(keys[k] + 0.5 * (keys[k + 1] - keys[k]));
    times.push_back(keys[k] + 0.3 * (keys[k + 1] - keys[k]));
  }
  return times;
}

// Compares every vertex of every drawn primitive at several times; the model's size scales the tolerance.
void expect_matches_reference(const std::string& name) {
  const fs::path file = sample(name);
  if (!fs::exists(file)) GTEST_SKIP() << file << " is missing";
  const SceneDesc scene = load(file);
  const Reference ref(file);
  ASSERT_FALSE(scene.animation.empty()) << name;
  EXPECT_TRUE(scene.animation.problem().empty()) << scene.animation.problem();
  const std::vector<std::pair<int, int>> drawn = ref.drawn();
  ASSERT_EQ(scene.shapes.size(), drawn.size()) << name;
  ASSERT_TRUE(scene.instances.empty()) << name;
  double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
  for (const auto& [n, p] : drawn)
    for (const P3& q : ref.vertices(n, p, 0))
      for (size_t c = 0; c < 3; ++c) lo[c] = std::min(lo[c], q[c]), hi[c] = std::max(hi[c], q[c]);
  const double size = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  const double tolerance = 1e-4 * size;
  const std::vector<double> keys = ref.key_times();
  ASSERT_FALSE(keys.empty());
  double largest_motion = 0;
  for (double t : test_times(keys)) {
    for (size_t s = 0; s < drawn.size(); ++s) {
      const std::vector<P3> expected = ref.vertices(drawn[s].first, drawn[s].second, t);
      const std::vector<P3> got = described_vertices(scene, scene.shapes[s], float(t));
      const std::vector<P3> rest = ref.vertices(drawn[s].first, drawn[s].second, keys.front());
      ASSERT_EQ(got.size(), expected.size());
      double worst = 0;
      size_t worst_vertex = 0;
      for (size_t v = 0; v < got.size(); ++v) {
        const double d = std::hypot(got[v][0] - expected[v][0], got[v][1] - expected[v][1], got[v][2] - expected[v][2]);
        if (d > worst) worst = d, worst_vertex = v;
        largest_motion = std::max(largest_motion, std::hypot(expected[v][0] - rest[v][0], expected[v][1] - rest[v][1],
                                                             expected[v][2] - rest[v][2]));
      }
      EXPECT_LE(worst, tolerance) << name << " at t = " << t << ", shape " << s << ", vertex " << worst_vertex
                                  << ": got (" << got[worst_vertex][0] << ", " << got[worst_vertex][1] << ", "
                                  << got[worst_vertex][2] << "), expected (" << expected[worst_vertex][0] << ", "
                                  << expected[worst_vertex][1] << ", " << expected[worst_vertex][2] << ")";
    }
  }
  // The comparison means something only if the model does move.
  EXPECT_GT(largest_motion, 100 * tolerance) << name;
}

TEST(GltfAnimationSamples, BoxAnimatedMatchesTheSpecification) { expect_matches_reference("BoxAnimated"); }
TEST(GltfAnimationSamples, AnimatedTriangleMatchesTheSpecification) { expect_matches_reference("AnimatedTriangle"); }
TEST(GltfAnimationSamples, SimpleMorphMatchesTheSpecification) { expect_matches_reference("SimpleMorph"); }
TEST(GltfAnimationSamples, SimpleSkinMatchesTheSpecification) { expect_matches_reference("SimpleSkin"); }
TEST(GltfAnimationSamples, RiggedSimpleMatchesTheSpecification) { expect_matches_reference("RiggedSimple"); }
TEST(GltfAnimationSamples, RiggedFigureMatchesTheSpecification) { expect_matches_reference("RiggedFigure"); }

void expect_matrix_near(const Matrix4& got, const double (&expected)[3][4], double tolerance, const std::string& what) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      EXPECT_NEAR(got.m[size_t(r)][size_t(c)], expected[r][c], tolerance) << what << " [" << r << "][" << c << "]";
}

TEST(GltfAnimationSamples, BoxAnimatedNodesMoveAsTheirKeyframesSay) {
  const fs::path file = sample("BoxAnimated");
  if (!fs::exists(file)) GTEST_SKIP() << file << " is missing";
  const SceneDesc scene = load(file);
  // Node 0 (translation keys 0, 1.25, 2.5, 3.708 s: y = 0, 2.52, 2.52, 0) holds node 1, which holds
  // node 2 (the inner box, rotation keys 1.25 s: identity, 2.5 s: (1, 0, 0, ~0), half a turn about x).
  // The outer box (node 3) stays put.
  ASSERT_EQ(scene.shapes.size(), 2u);
  EXPECT_EQ(scene.shapes[0].animation_node, -1);  // node 3, first in the scene's list
  EXPECT_EQ(scene.shapes[1].animation_node, 2);
  EXPECT_TRUE(scene.shapes[1].to_world.is_identity());
  EXPECT_TRUE(scene.animation.node_moves(2));
  EXPECT_FALSE(scene.animation.node_moves(3));
  const SceneAnimation& a = scene.animation;
  // Half-way up: translation 2.52 / 2, no rotation yet.
  expect_matrix_near(a.world_matrix(2, 0.625f), {{1, 0, 0, 0}, {0, 1, 0, 1.26}, {0, 0, 1, 0}}, 1e-5, "t = 0.625");
  // Half-way through the turn: the keys' dot product is -4.5e-11 < 0, so the shorter arc goes to
  // -(1, 0, 0, ~0): the midpoint is (-0.7071, 0, 0, -0.7071), +90 degrees about x (y -> z, z -> -y).
  expect_matrix_near(a.world_matrix(2, 1.875f), {{1, 0, 0, 0}, {0, 0, -1, 2.52}, {0, 1, 0, 0}}, 1e-5, "t = 1.875");
  // Coming down (between 2.5 and 3.708 s), the half turn done: y -> -y, z -> -z.
  const double y = 2.52 * (1 - (3.1 - 2.5) / (3.708329916 - 2.5));
  expect_matrix_near(a.world_matrix(2, 3.1f), {{1, 0, 0, 0}, {0, -1, 0, y}, {0, 0, -1, 0}}, 1e-5, "t = 3.1");
}

TEST(GltfAnimationSamples, AnimatedTriangleTurnsAboutZ) {
  const fs::path file = sample("AnimatedTriangle");
  if (!fs::exists(file)) GTEST_SKIP() << file << " is missing";
  const SceneDesc scene = load(file);
  ASSERT_EQ(scene.shapes.size(), 1u);
  EXPECT_EQ(scene.shapes[0].animation_node, 0);
  // Rotation keys every 0.25 s: identity, (0, 0, 0.707, 0.707), (0, 0, 1, 0), ...: a quarter turn
  // about z each; at 0.125 s an eighth of a turn, at 0.375 s three eighths.
  for (const auto& [t, degrees] : {std::pair(0.125f, 45.0), std::pair(0.375f, 135.0), std::pair(0.25f, 90.0)}) {
    const double c = std::cos(degrees * std::numbers::pi / 180), s = std::sin(degrees * std::numbers::pi / 180);
    expect_matrix_near(scene.animation.world_matrix(0, t), {{c, -s, 0, 0}, {s, c, 0, 0}, {0, 0, 1, 0}}, 1e-4,
                       fmt::format("t = {}", t));
  }
  // The vertex (1, 0, 0) at 45 degrees (to 1e-4: the file's keys are 0.707, not quite unit
  // quaternions, which moves the spherical interpolation's angle by about 6e-5 radians).
  const std::vector<P3> v = described_vertices(scene, scene.shapes[0], 0.125f);
  EXPECT_NEAR(v[1][0], std::sqrt(0.5), 1e-4);
  EXPECT_NEAR(v[1][1], std::sqrt(0.5), 1e-4);
}

TEST(GltfAnimationSamples, SkinsAndMorphTargetsBecomeDeformations) {
  const fs::path skin_file = sample("SimpleSkin"), morph_file = sample("SimpleMorph");
  if (!fs::exists(skin_file) || !fs::exists(morph_file)) GTEST_SKIP() << "the animated samples are missing";
  const SceneDesc skinned = load(skin_file);
  ASSERT_EQ(skinned.shapes.size(), 1u);
  const ShapeDesc& shape = skinned.shapes[0];
  // Skinned vertices come out of deform() in world space: the shape is not placed again.
  EXPECT_EQ(shape.animation_node, -1);
  EXPECT_TRUE(shape.to_world.is_identity());
  ASSERT_EQ(shape.deformation, 0);
  const MeshDeformation& d = skinned.animation.deformations[0];
  EXPECT_EQ(d.skin, 0);
  EXPECT_EQ(d.influences, 4);
  EXPECT_EQ(d.joints.size(), 40u);
  ASSERT_EQ(skinned.animation.skins.size(), 1u);
  EXPECT_EQ(skinned.animation.skins[0].joints, (std::vector<int>{1, 2}));
  // The inverse bind matrices: a translation by (0, -1, 0) (column-major in the file).
  EXPECT_DOUBLE_EQ(skinned.animation.skins[0].inverse_bind[1].m[1][3], -1.0);

  const SceneDesc morphed = load(morph_file);
  ASSERT_EQ(morphed.shapes.size(), 1u);
  ASSERT_EQ(morphed.shapes[0].deformation, 0);
  const MeshDeformation& m = morphed.animation.deformations[0];
  EXPECT_EQ(m.skin, -1);
  EXPECT_EQ(m.target_positions.size(), 2u);
  EXPECT_EQ(m.default_weights, (std::vector<float>{0.5f, 0.5f}));
  EXPECT_EQ(m.weights_node, 0);
  // The node itself does not move: the mesh keeps its (identity) placement.
  EXPECT_EQ(morphed.shapes[0].animation_node, -1);
}

TEST(GltfAnimationSamples, StaticFilesHaveNoAnimation) {
  const fs::path file = fs::path(CANDELA_SHARED_DIR) / "meshes/gltf-sample-assets/Box/glTF/Box.gltf";
  if (!fs::exists(file)) GTEST_SKIP() << file << " is missing";
  const SceneDesc scene = load(file);
  EXPECT_TRUE(scene.animation.empty());
  for (const ShapeDesc& shape : scene.shapes) {
    EXPECT_EQ(shape.animation_node, -1);
    EXPECT_EQ(shape.deformation, -1);
  }
  EXPECT_EQ(scene.camera.animation_node, -1);
}

// ---------------------------------------------------------------- hand-made files

// A directory of its own for this test process, removed at the end of the test.
class ScratchDir {
 public:
  ScratchDir() : dir_(fs::temp_directory_path() / fmt::format("candela_gltf_animation_test_{}_{}", getpid(), counter_++)) {
    fs::create_directories(dir_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  const fs::path& dir() const { return dir_; }

 private:
  static inline int counter_ = 0;
  fs::path dir_;
};

// A glTF file written piece by piece: float and index accessors in one external buffer.
class GltfFile {
 public:
  GltfFile() { j_ = {{"asset", {{"version", "2.0"}}}, {"scene", 0}, {"accessors", Json::array()}, {"bufferViews", Json::array()}}; }
  Json& json() { return j_; }

  int floats(const std::vector<float>& values, const std::string& type) {
    const int components = type == "SCALAR" ? 1 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 16;
    return add(values.data(), values.size() * 4, 5126, values.size() / size_t(components), type);
  }
  int shorts(const std::vector<uint16_t>& values, const std::string& type) {
    const int components = type == "SCALAR" ? 1 : 4;
    return add(values.data(), values.size() * 2, 5123, values.size() / size_t(components), type);
  }

  fs::path write(const fs::path& dir, const std::string& name) const {
    Json j = j_;
    j["buffers"] = Json::array({{{"uri", name + ".bin"}, {"byteLength", bytes_.size()}}});
    std::ofstream(dir / (name + ".bin"), std::ios::binary) << bytes_;
    std::ofstream(dir / (name + ".gltf")) << j.dump(1);
    return dir / (name + ".gltf");
  }

 private:
  int add(const void* data, size_t size, int component_type, size_t count, const std::string& type) {
    while (bytes_.size() % 4) bytes_ += '\0';
    j_["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bytes_.size()}, {"byteLength", size}});
    bytes_.append(static_cast<const char*>(data), size);
    j_["accessors"].push_back({{"bufferView", j_["bufferViews"].size() - 1}, {"componentType", component_type},
                               {"count", count}, {"type", type}});
    return int(j_["accessors"].size()) - 1;
  }

  Json j_;
  std::string bytes_;
};

// Node 0: a triangle whose translation steps; node 1: cubic-spline translation and rotation, with
// a camera on its child node 3; node 2: a triangle with two morph targets whose weights follow a
// cubic spline.
GltfFile keyed_file() {
  GltfFile f;
  const int positions = f.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  const int indices = f.shorts({0, 1, 2}, "SCALAR");
  const int target0 = f.floats({0, 0, 1, 0, 0, 0, 0, 0, 0}, "VEC3");
  const int target1 = f.floats({0, 0, 0, 0, 0, 2, 0, 0, 0}, "VEC3");
  Json& j = f.json();
  j["meshes"] = Json::array({
      {{"primitives", Json::array({{{"attributes", {{"POSITION", positions}}}, {"indices", indices}}})}},
      {{"primitives", Json::array({{{"attributes", {{"POSITION", positions}}},
                                    {"indices", indices},
                                    {"targets", Json::array({{{"POSITION", target0}}, {{"POSITION", target1}}})}}})},
       {"weights", {0.0, 0.0}}},
  });
  j["cameras"] = Json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}});
  j["nodes"] = Json::array({{{"mesh", 0}},
                            {{"children", {3}}, {"translation", {5, 5, 5}}},
                            {{"mesh", 1}},
                            {{"camera", 0}, {"translation", {0, 0, 2}}}});
  j["scenes"] = Json::array({{{"nodes", {0, 1, 2}}}});
  const float h = std::sqrt(0.5f);
  Json samplers = Json::array({
      // 0: STEP translation at 0, 1, 2 s.
      {{"input", f.floats({0, 1, 2}, "SCALAR")}, {"output", f.floats({0, 0, 0, 1, 2, 3, 4, 5, 6}, "VEC3")},
       {"interpolation", "STEP"}},
      // 1: CUBICSPLINE translation at 0 and 2 s: (in-tangent, value, out-tangent) per key.
      {{"input", f.floats({0, 2}, "SCALAR")},
       {"output", f.floats({9, 9, 9, 0, 0, 0, 1, 0, 0, /**/ 0, 3, 0, 2, 4, 0, 9, 9, 9}, "VEC3")},
       {"interpolation", "CUBICSPLINE"}},
      // 2: CUBICSPLINE rotation at 0 and 2 s, from the identity to a quarter turn about z.
      {{"input", f.floats({0, 2}, "SCALAR")},
       {"output", f.floats({9, 9, 9, 9, 0, 0, 0, 1, 0, 0, 0.3f, 0, /**/ 0, 0, 0.2f, 0, 0, 0, h, h, 9, 9, 9, 9}, "VEC4")},
       {"interpolation", "CUBICSPLINE"}},
      // 3: CUBICSPLINE weights of two targets at 0 and 1 s.
      {{"input", f.floats({0, 1}, "SCALAR")},
       {"output", f.floats({5, 5, 0, 1, 1, -1, /**/ 2, 0, 1, 0, 7, 7}, "SCALAR")},
       {"interpolation", "CUBICSPLINE"}},
  });
  Json channels = Json::array({
      {{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}},
      {{"sampler", 1}, {"target", {{"node", 1}, {"path", "translation"}}}},
      {{"sampler", 2}, {"target", {{"node", 1}, {"path", "rotation"}}}},
      {{"sampler", 3}, {"target", {{"node", 2}, {"path", "weights"}}}},
  });
  j["animations"] = Json::array({{{"samplers", samplers}, {"channels", channels}}});
  return f;
}

TEST(GltfAnimationKeyframes, StepHoldsEachKeyUntilTheNext) {
  ScratchDir scratch;
  const SceneDesc scene = load(keyed_file().write(scratch.dir(), "keyed"));
  ASSERT_EQ(scene.shapes.size(), 2u);
  EXPECT_EQ(scene.shapes[0].animation_node, 0);
  EXPECT_TRUE(scene.shapes[0].to_world.is_identity());
  const SceneAnimation& a = scene.animation;
  const std::array<double, 3> expected[] = {{0, 0, 0}, {0, 0, 0}, {1, 2, 3}, {1, 2, 3}, {4, 5, 6}, {4, 5, 6}};
  const float times[] = {-1.0f, 0.99f, 1.0f, 1.7f, 2.0f, 3.0f};
  for (size_t i = 0; i < std::size(times); ++i) {
    const Matrix4 m = a.world_matrix(0, times[i]);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.m[size_t(c)][3], expected[i][size_t(c)], 1e-6) << "t = " << times[i];
  }
}

TEST(GltfAnimationKeyframes, CubicSplineFollowsTheHermiteFormula) {
  ScratchDir scratch;
  const SceneDesc scene = load(keyed_file().write(scratch.dir(), "keyed"));
  const SceneAnimation& a = scene.animation;
  // Translation: keys at 0 s (value 0, out-tangent (1, 0, 0)) and 2 s (in-tangent (0, 3, 0), value
  // (2, 4, 0)); dt = 2. Half-way (s = 0.5: h00 = h01 = 0.5, h10 = 0.125, h11 = -0.125):
  // x = 0.125 * 2 * 1 + 0.5 * 2 = 1.25, y = 0.5 * 4 - 0.125 * 2 * 3 = 1.25.
  {
    const Matrix4 m = a.world_matrix(1, 1.0f);
    EXPECT_NEAR(m.m[0][3], 1.25, 1e-6);
    EXPECT_NEAR(m.m[1][3], 1.25, 1e-6);
    EXPECT_NEAR(m.m[2][3], 0.0, 1e-6);
  }
  for (float t : {0.3f, 0.5f, 1.0f, 1.6f}) {
    const double s = t / 2.0;
    const double x = hermite(0, 1, 2, 0, 2, s), y = hermite(0, 0, 4, 3, 2, s);
    // Rotation: z and w by the same formula, then normalised; a turn about z by 2 atan2(z, w).
    const double h = std::sqrt(0.5);
    const double qz = hermite(0, 0.3, h, 0.2, 2, s), qw = hermite(1, 0, h, 0, 2, s);
    const double angle = 2 * std::atan2(qz, qw), c = std::cos(angle), sn = std::sin(angle);
    expect_matrix_near(a.world_matrix(1, t), {{c, -sn, 0, x}, {sn, c, 0, y}, {0, 0, 1, 0}}, 1e-5,
                       fmt::format("node 1 at t = {}", t));
  }
  // Weights: keys at 0 s (value (0, 1), out-tangent (1, -1)) and 1 s (in-tangent (2, 0), value
  // (1, 0)); at 0.5 s: w0 = 0.125 * 1 + 0.5 * 1 - 0.125 * 2 = 0.375, w1 = 0.5 - 0.125 = 0.375.
  ASSERT_EQ(scene.shapes[1].deformation, 0);
  const MeshDeformation& d = a.deformations[0];
  EXPECT_EQ(d.weights_node, 2);
  ASSERT_TRUE(a.nodes[2].weights_keys);
  EXPECT_EQ(a.nodes[2].weights_keys->width, 2);
  const std::vector<float> w = a.nodes[2].weights_keys->at(0.5f);
  EXPECT_NEAR(w[0], 0.375, 1e-6);
  EXPECT_NEAR(w[1], 0.375, 1e-6);
  // Target 0 lifts vertex 0 by z = 1, target 1 vertex 1 by z = 2.
  const std::vector<P3> v = described_vertices(scene, scene.shapes[1], 0.5f);
  EXPECT_NEAR(v[0][2], 0.375, 1e-6);
  EXPECT_NEAR(v[1][2], 0.75, 1e-6);
  for (float t : {0.25f, 0.8f}) {
    const double w0 = hermite(0, 1, 1, 2, 1, t), w1 = hermite(1, -1, 0, 0, 1, t);
    const std::vector<P3> vt = described_vertices(scene, scene.shapes[1], t);
    EXPECT_NEAR(vt[0][2], w0, 1e-6) << t;
    EXPECT_NEAR(vt[1][2], 2 * w1, 1e-6) << t;
  }
}

TEST(GltfAnimationKeyframes, CameraOnAMovingNodeFollowsIt) {
  ScratchDir scratch;
  const SceneDesc scene = load(keyed_file().write(scratch.dir(), "keyed"));
  EXPECT_EQ(scene.camera.animation_node, 3);
  // Relative to the node: glTF's camera looks down its -z, candela's down +z.
  const Matrix4& m = scene.camera.world_from_camera.matrix();
  EXPECT_DOUBLE_EQ(m.m[0][0], 1);
  EXPECT_DOUBLE_EQ(m.m[1][1], 1);
  EXPECT_DOUBLE_EQ(m.m[2][2], -1);
  EXPECT_DOUBLE_EQ(m.m[0][3], 0);
  // The node: its parent's cubic translation at 0 s ((0, 0, 0)) plus its own (0, 0, 2).
  EXPECT_NEAR(scene.animation.world_matrix(3, 0).m[2][3], 2.0, 1e-6);
}

TEST(GltfAnimationKeyframes, MorphTargetsWithoutAnimationUseTheMeshWeights) {
  ScratchDir scratch;
  GltfFile f = keyed_file();
  f.json().erase("animations");
  f.json()["meshes"][1]["weights"] = {0.5, 0.25};
  const SceneDesc scene = load(f.write(scratch.dir(), "morph"));
  ASSERT_FALSE(scene.animation.empty());
  ASSERT_EQ(scene.shapes.size(), 2u);
  EXPECT_EQ(scene.shapes[0].deformation, -1);
  EXPECT_EQ(scene.shapes[0].animation_node, -1);
  const std::vector<P3> v = described_vertices(scene, scene.shapes[1], 0.0f);
  EXPECT_NEAR(v[0][2], 0.5, 1e-6);
  EXPECT_NEAR(v[1][2], 0.5, 1e-6);
  // The node's weights override the mesh's.
  f.json()["nodes"][2]["weights"] = {1.0, 0.0};
  const SceneDesc overridden = load(f.write(scratch.dir(), "override"));
  const std::vector<P3> o = described_vertices(overridden, overridden.shapes[1], 0.0f);
  EXPECT_NEAR(o[0][2], 1.0, 1e-6);
  EXPECT_NEAR(o[1][2], 0.0, 1e-6);
}

// ---------------------------------------------------------------- broken data

std::string scene_error_of(const fs::path& file) {
  try {
    load(file);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " loaded";
  return "";
}

TEST(GltfAnimationErrors, ChannelNamingAMissingNode) {
  ScratchDir scratch;
  GltfFile f = keyed_file();
  f.json()["animations"][0]["channels"][2]["target"]["node"] = 99;
  const std::string message = scene_error_of(f.write(scratch.dir(), "missing_node"));
  EXPECT_NE(message.find("/animations/0/channels/2/target/node"), std::string::npos) << message;
  EXPECT_NE(message.find("missing_node.gltf"), std::string::npos) << message;
}

TEST(GltfAnimationErrors, SamplerTimesThatDecrease) {
  ScratchDir scratch;
  GltfFile f = keyed_file();
  f.json()["animations"][0]["samplers"][0]["input"] = f.floats({0, 2, 1}, "SCALAR");
  const std::string message = scene_error_of(f.write(scratch.dir(), "decreasing"));
  EXPECT_NE(message.find("/animations/0/samplers/0"), std::string::npos) << message;
  EXPECT_NE(message.find("increase"), std::string::npos) << message;
}

TEST(GltfAnimationErrors, SamplerWithTooFewValues) {
  ScratchDir scratch;
  GltfFile f = keyed_file();
  f.json()["animations"][0]["samplers"][1]["output"] = f.floats({0, 0, 0, 1, 0, 0, 2, 4, 0}, "VEC3");
  const std::string message = scene_error_of(f.write(scratch.dir(), "short"));
  EXPECT_NE(message.find("/animations/0/samplers/1"), std::string::npos) << message;
}

TEST(GltfAnimationErrors, SkinWithTooFewInverseBindMatrices) {
  ScratchDir scratch;
  GltfFile f = keyed_file();
  const std::vector<float> identity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  f.json()["skins"] = Json::array({{{"joints", {0, 1}}, {"inverseBindMatrices", f.floats(identity, "MAT4")}}});
  const std::string message = scene_error_of(f.write(scratch.dir(), "skin"));
  EXPECT_NE(message.find("/skins/0/inverseBindMatrices"), std::string::npos) << message;
}

TEST(GltfAnimationErrors, SkinnedMeshWithoutJoints) {
  ScratchDir scratch;
  GltfFile f = keyed_file();
  f.json()["skins"] = Json::array({{{"joints", {1}}}});  // no inverse bind matrices: identities
  f.json()["nodes"][0]["skin"] = 0;
  const std::string message = scene_error_of(f.write(scratch.dir(), "no_joints"));
  EXPECT_NE(message.find("/meshes/0/primitives/0"), std::string::npos) << message;
  EXPECT_NE(message.find("JOINTS_0"), std::string::npos) << message;
}

TEST(GltfAnimationErrors, JointIndexBeyondTheSkin) {
  ScratchDir scratch;
  GltfFile f = keyed_file();
  f.json()["skins"] = Json::array({{{"joints", {1}}}});
  f.json()["nodes"][0]["skin"] = 0;
  Json& attributes = f.json()["meshes"][0]["primitives"][0]["attributes"];
  attributes["JOINTS_0"] = f.shorts({0, 0, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0}, "VEC4");
  attributes["WEIGHTS_0"] = f.floats({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, "VEC4");
  const std::string message = scene_error_of(f.write(scratch.dir(), "joint"));
  EXPECT_NE(message.find("/meshes/0/primitives/0/attributes/JOINTS_0"), std::string::npos) << message;
}

// A skin without inverse bind matrices uses identities (tinygltf calls them required; glTF does not).
TEST(GltfAnimationKeyframes, SkinWithoutInverseBindMatricesUsesIdentities) {
  ScratchDir scratch;
  GltfFile f = keyed_file();
  f.json()["skins"] = Json::array({{{"joints", {1}}}});
  f.json()["nodes"][0]["skin"] = 0;
  Json& attributes = f.json()["meshes"][0]["primitives"][0]["attributes"];
  attributes["JOINTS_0"] = f.shorts(std::vector<uint16_t>(12, 0), "VEC4");
  attributes["WEIGHTS_0"] = f.floats({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, "VEC4");
  const SceneDesc scene = load(f.write(scratch.dir(), "identity_skin"));
  ASSERT_EQ(scene.shapes.size(), 2u);
  ASSERT_GE(scene.shapes[0].deformation, 0);
  EXPECT_EQ(scene.shapes[0].animation_node, -1);
  // Every vertex follows joint node 1 alone, with an identity inverse bind matrix: it is placed by
  // node 1's world matrix (the skinned node's own transform is ignored).
  const Matrix4 m = scene.animation.world_matrix(1, 1.0f);
  const std::vector<P3> v = described_vertices(scene, scene.shapes[0], 1.0f);
  const Point3 rest[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int i = 0; i < 3; ++i)
    for (int r = 0; r < 3; ++r)
      EXPECT_NEAR(v[size_t(i)][size_t(r)],
                  m.m[size_t(r)][0] * rest[i].x + m.m[size_t(r)][1] * rest[i].y + m.m[size_t(r)][2] * rest[i].z + m.m[size_t(r)][3],
                  1e-5);
}

}  // namespace
}  // namespace candela::gltf_animation_test
