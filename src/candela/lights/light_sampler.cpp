#include "candela/lights/light_sampler.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "candela/base/overloaded.h"

namespace candela {

namespace {

constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

Bounds3 point_bounds(const Point3& p) {
  Bounds3 b;
  b.extend(p);
  return b;
}

// A point or a small round emitter: light in every direction (theta_o = pi, theta_e = pi/2).
LightBounds omnidirectional(const Bounds3& bounds, float phi) {
  return {bounds, phi, Vec3(0, 0, 1), -1.0f, 0.0f, false};
}

// A flat diffuse emitter: normals all n, light up to pi/2 from them.
LightBounds flat(const Bounds3& bounds, float phi, const Normal3& n, bool two_sided) {
  return {bounds, phi, n, 1.0f, 0.0f, two_sided};
}

// v turned by angle theta about the unit axis k (perpendicular to v): Rodrigues' formula.
Vec3 rotate_perpendicular(const Vec3& v, const Vec3& k, float theta) {
  return v * std::cos(theta) + cross(k, v) * std::sin(theta);
}

float surface_area(const Bounds3& b) {
  Vec3 d = b.diagonal();
  return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

// The cost of a node with these bounds in the build's split heuristic (Conty Estevez and Kulla's
// surface area orientation heuristic, as pbrt-v4 weighs it): power x the solid angle the emission
// cone reaches x the box's area, penalising boxes thin along the split axis.
float node_cost(const LightBounds& b, const Bounds3& parent_box, int axis) {
  float theta_o = std::acos(std::clamp(b.cos_theta_o, -1.0f, 1.0f));
  float theta_e = std::acos(std::clamp(b.cos_theta_e, -1.0f, 1.0f));
  float theta_w = std::min(theta_o + theta_e, kPi);
  float sin_o = safe_sqrt(1 - b.cos_theta_o * b.cos_theta_o);
  float m_omega = 2 * kPi * (1 - b.cos_theta_o) +
                  kPi / 2 * (2 * theta_w * sin_o - std::cos(theta_o - 2 * theta_w) - 2 * theta_o * sin_o + b.cos_theta_o);
  Vec3 d = parent_box.diagonal();
  float extent = d[axis] > 0 ? std::max({d.x, d.y, d.z}) / d[axis] : 1.0f;
  return b.phi * m_omega * extent * surface_area(b.bounds);
}

}  // namespace

std::optional<LightBounds> light_bounds(const Light& light) {
  std::optional<LightBounds> b = std::visit(
      overloaded{
          [](const PointLightSource& l) -> std::optional<LightBounds> {
            return omnidirectional(point_bounds(l.position), l.intensity.luminance());
          },
          [](const SpotLightSource& l) -> std::optional<LightBounds> {
            // Full intensity within the inner cone, none past the outer one.
            float theta_start = std::acos(std::clamp(l.cos_falloff_start, -1.0f, 1.0f));
            float theta_end = std::acos(std::clamp(l.cos_falloff_end, -1.0f, 1.0f));
            return LightBounds{point_bounds(l.position), l.intensity.luminance(), l.frame.n, l.cos_falloff_start,
                               std::cos(std::max(0.0f, theta_end - theta_start)), false};
          },
          [](const GoniometricLightSource& l) -> std::optional<LightBounds> {
            // As pbrt-v4 bounds it: an isotropic point light of the same power.
            return omnidirectional(point_bounds(l.position), l.power() / (4 * kPi));
          },
          [](const ProjectorLightSource& l) -> std::optional<LightBounds> {
            // As bright as a point light of the same power, in every direction (a loose but safe cone).
            return omnidirectional(point_bounds(l.position), l.power() / (4 * kPi));
          },
          [](const TriangleLight& l) -> std::optional<LightBounds> {
            Bounds3 b = point_bounds(l.p0);
            b.extend(l.p1);
            b.extend(l.p2);
            return flat(b, l.radiance.luminance() * l.area, l.n, l.two_sided);
          },
          [](const RectangleLight& l) -> std::optional<LightBounds> {
            Bounds3 b = point_bounds(l.corner);
            b.extend(l.corner + l.edge_u);
            b.extend(l.corner + l.edge_v);
            b.extend(l.corner + l.edge_u + l.edge_v);
            return flat(b, l.radiance.luminance() * l.area, l.n, l.two_sided);
          },
          [](const DiskLight& l) -> std::optional<LightBounds> {
            Vec3 half(std::abs(l.axis_u.x) + std::abs(l.axis_v.x), std::abs(l.axis_u.y) + std::abs(l.axis_v.y),
                      std::abs(l.axis_u.z) + std::abs(l.axis_v.z));
            Bounds3 b = point_bounds(l.center - half);
            b.extend(l.center + half);
            return flat(b, l.radiance.luminance() * l.area, l.n, l.two_sided);
          },
          [](const SphereLight& l) -> std::optional<LightBounds> {
            // Seen from anywhere outside, a disk of area pi r^2.
            Bounds3 b = point_bounds(l.center - Vec3(l.radius));
            b.extend(l.center + Vec3(l.radius));
            return omnidirectional(b, l.radiance.luminance() * kPi * l.radius * l.radius);
          },
          [](const PartialSphereLight& l) -> std::optional<LightBounds> {
            // Seen from anywhere, at most the whole sphere's disk, and at most its own area.
            Bounds3 b = point_bounds(l.center - Vec3(l.radius));
            b.extend(l.center + Vec3(l.radius));
            return omnidirectional(b, l.radiance.luminance() * std::min(kPi * l.radius * l.radius, l.area));
          },
          [](const CylinderLight& l) -> std::optional<LightBounds> {
            Bounds3 b = point_bounds(l.base - Vec3(l.radius));
            b.extend(l.base + Vec3(l.radius));
            b.extend(l.base + l.axis - Vec3(l.radius));
            b.extend(l.base + l.axis + Vec3(l.radius));
            float projected = 2 * l.radius * length(l.axis) + kPi * l.radius * l.radius;  // at most, from any side
            return omnidirectional(b, l.radiance.luminance() * projected);
          },
          [](const auto&) -> std::optional<LightBounds> { return std::nullopt; }},  // at infinity
      light);
  if (!b || !(b->phi > 0) || !std::isfinite(b->phi)) return std::nullopt;
  return b;
}

LightBounds merge(const LightBounds& a, const LightBounds& b) {
  LightBounds m;
  m.bounds = a.bounds;
  m.bounds.extend(b.bounds);
  m.phi = a.phi + b.phi;
  m.cos_theta_e = std::min(a.cos_theta_e, b.cos_theta_e);
  m.two_sided = a.two_sided || b.two_sided;
  // The smallest cone holding both direction cones.
  float theta_a = std::acos(std::clamp(a.cos_theta_o, -1.0f, 1.0f));
  float theta_b = std::acos(std::clamp(b.cos_theta_o, -1.0f, 1.0f));
  float theta_d = std::acos(std::clamp(dot(a.w, b.w), -1.0f, 1.0f));
  if (std::min(theta_d + theta_b, kPi) <= theta_a) {
    m.w = a.w, m.cos_theta_o = a.cos_theta_o;
  } else if (std::min(theta_d + theta_a, kPi) <= theta_b) {
    m.w = b.w, m.cos_theta_o = b.cos_theta_o;
  } else {
    float theta_o = (theta_a + theta_d + theta_b) / 2;
    Vec3 axis = cross(a.w, b.w);
    if (theta_o >= kPi || length_squared(axis) == 0) {
      m.w = a.w, m.cos_theta_o = -1;  // the whole sphere
    } else {
      m.w = normalize(rotate_perpendicular(a.w, normalize(axis), theta_o - theta_a));
      m.cos_theta_o = std::cos(theta_o);
    }
  }
  return m;
}

LightImportance::LightImportance(const LightBounds& b)
    : center(b.bounds.center()),
      radius(0.5f * length(b.bounds.diagonal())),
      phi(b.phi),
      w(b.w),
      cos_o(b.cos_theta_o),
      sin_o(safe_sqrt(1 - b.cos_theta_o * b.cos_theta_o)),
      cos_e(b.cos_theta_e),
      two_sided(b.two_sided) {}

float LightImportance::operator()(const LightSampleContext& ctx) const {
  const Vec3 d = ctx.p - center;
  const float d2_true = length_squared(d);
  const float radius2 = radius * radius;
  // Closer than the bounds' bounding sphere, the lights could be anywhere around: no 1/d^2 growth,
  // and every direction may lead to one (theta_b = pi).
  const float d2 = std::max({d2_true, radius2, 1e-12f});
  float sin_b = 0, cos_b = -1;
  Vec3 wi(0, 0, 1);
  if (d2_true > radius2) {
    const float inv_d = 1 / std::sqrt(d2_true);
    wi = d * inv_d;
    sin_b = radius * inv_d;
    cos_b = safe_sqrt(1 - sin_b * sin_b);
  }

  // The smallest angle between an emission direction in the cone and a direction towards the
  // point: theta' = max(0, theta_w - theta_o - theta_b); nothing arrives past theta_e. (Sines
  // only where an angle difference needs them: inside a cone the clamped difference is 0.)
  float cos_w = dot(w, wi);
  if (two_sided) cos_w = std::abs(cos_w);
  float cos_x = 1, sin_x = 0;  // of max(0, theta_w - theta_o)
  if (!(cos_w > cos_o)) {
    const float sin_w = safe_sqrt(1 - cos_w * cos_w);
    cos_x = cos_w * cos_o + sin_w * sin_o;
    sin_x = sin_w * cos_o - cos_w * sin_o;
  }
  const float cos_p = cos_x > cos_b ? 1.0f : cos_x * cos_b + sin_x * sin_b;
  if (cos_p <= cos_e) return 0;
  float importance = phi * cos_p / d2;

  // At a surface, the largest cosine with the gathering side's normal any of the lights could make.
  if (ctx.n != Normal3(0.0f)) {
    const float cos_i = -dot(ctx.n, wi);
    if (!(cos_i > cos_b)) importance *= std::max(0.0f, cos_i * cos_b + safe_sqrt(1 - cos_i * cos_i) * sin_b);
  }
  return std::isfinite(importance) ? std::max(0.0f, importance) : 0.0f;
}

LightSampler::LightSampler(std::span<const Light> lights, std::span<const float> weights, Mode mode)
    : emitter_choice_(weights), mode_(mode) {
  if (mode_ == Mode::Weights) return;
  if (mode_ == Mode::Paper) lights_ = lights;
  slot_of_light_.assign(lights.size(), -1);
  infinite_slot_.assign(lights.size(), -1);
  std::vector<std::pair<uint32_t, LightBounds>> bounded;
  for (size_t i = 0; i < lights.size(); ++i) {
    if (light_is_at_infinity(lights[i])) {
      infinite_slot_[i] = int32_t(infinite_.size());
      infinite_.push_back(uint32_t(i));
    } else if (std::optional<LightBounds> b = light_bounds(lights[i])) {
      bounded.emplace_back(uint32_t(i), *b);
    }
  }
  if (bounded.empty()) return;
  nodes_.reserve(2 * bounded.size());
  bounds_.reserve(2 * bounded.size());
  nodes_.resize(1);
  bounds_.resize(1);
  build(bounded, 0, bounded.size(), 0, 0);
  root_importance_ = LightImportance(bounds_[0]);
  wide_.reserve(bounded.size());
  build_wide(0, 0, 0);
}

void LightSampler::build(std::vector<std::pair<uint32_t, LightBounds>>& lights, size_t begin, size_t end,
                         uint32_t index, uint32_t parent) {
  if (end - begin == 1) {
    const auto& [light, bounds] = lights[begin];
    nodes_[index] = BuildNode{light, parent, 1, true};
    bounds_[index] = bounds;
    return;
  }
  LightBounds all = lights[begin].second;
  Bounds3 centroids;
  for (size_t i = begin; i < end; ++i) {
    if (i > begin) all = merge(all, lights[i].second);
    centroids.extend(lights[i].second.bounds.center());
  }

  // Choose the split: among 12 buckets of centroids along each axis, the boundary of least cost.
  constexpr int kBuckets = 12;
  float best_cost = INFINITY;
  int best_axis = -1, best_bucket = -1;
  auto bucket_of = [&](const LightBounds& b, int axis) {
    float extent = centroids.hi[axis] - centroids.lo[axis];
    int k = int(kBuckets * (b.bounds.center()[axis] - centroids.lo[axis]) / extent);
    return std::clamp(k, 0, kBuckets - 1);
  };
  for (int axis = 0; axis < 3; ++axis) {
    if (!(centroids.hi[axis] > centroids.lo[axis])) continue;
    std::array<std::optional<LightBounds>, kBuckets> buckets;
    for (size_t i = begin; i < end; ++i) {
      auto& bucket = buckets[size_t(bucket_of(lights[i].second, axis))];
      bucket = bucket ? merge(*bucket, lights[i].second) : lights[i].second;
    }
    for (int split = 0; split + 1 < kBuckets; ++split) {
      std::optional<LightBounds> below, above;
      for (int k = 0; k < kBuckets; ++k) {
        if (!buckets[size_t(k)]) continue;
        auto& side = k <= split ? below : above;
        side = side ? merge(*side, *buckets[size_t(k)]) : *buckets[size_t(k)];
      }
      if (!below || !above) continue;
      float cost = node_cost(*below, all.bounds, axis) + node_cost(*above, all.bounds, axis);
      if (cost < best_cost) best_cost = cost, best_axis = axis, best_bucket = split;
    }
  }
  size_t mid = (begin + end) / 2;
  if (best_axis >= 0) {
    auto it = std::partition(lights.begin() + std::ptrdiff_t(begin), lights.begin() + std::ptrdiff_t(end),
                             [&](const auto& l) { return bucket_of(l.second, best_axis) <= best_bucket; });
    mid = size_t(it - lights.begin());
  }
  if (mid == begin || mid == end) mid = (begin + end) / 2;  // all alike: halve the list

  const uint32_t first = uint32_t(nodes_.size());
  nodes_.resize(nodes_.size() + 2);
  bounds_.resize(bounds_.size() + 2);
  nodes_[index] = BuildNode{first, parent, uint32_t(end - begin), false};
  bounds_[index] = all;
  build(lights, begin, mid, first, index);
  build(lights, mid, end, first + 1, index);
}

uint32_t LightSampler::build_wide(uint32_t binary_node, uint32_t parent, uint8_t parent_slot) {
  // The slots: the binary node's children; then, while there is room, the interior slot of most
  // lights replaced by its two children (the binary root alone, if it is a leaf).
  std::vector<uint32_t> slots;
  if (nodes_[binary_node].leaf) {
    slots.push_back(binary_node);
  } else {
    slots = {nodes_[binary_node].child_or_light, nodes_[binary_node].child_or_light + 1};
    while (slots.size() < size_t(kWidth)) {
      auto largest = std::max_element(slots.begin(), slots.end(), [&](uint32_t a, uint32_t b) {
        return (nodes_[a].leaf ? 0 : nodes_[a].lights) < (nodes_[b].leaf ? 0 : nodes_[b].lights);
      });
      if (nodes_[*largest].leaf) break;
      const uint32_t first = nodes_[*largest].child_or_light;
      *largest = first;
      slots.insert(largest + 1, first + 1);
    }
  }
  const uint32_t index = uint32_t(wide_.size());
  wide_.emplace_back();
  {
    WideNode& w = wide_[index];
    w.parent = parent;
    w.parent_slot = parent_slot;
    w.used = uint8_t(slots.size());
    for (int k = 0; k < kWidth; ++k) {
      // Unused slots: nothing there (phi = 0), at the origin, a cone the math stays finite on.
      LightImportance li;
      if (k < int(slots.size())) li = LightImportance(bounds_[slots[size_t(k)]]);
      w.cx[k] = li.center.x, w.cy[k] = li.center.y, w.cz[k] = li.center.z, w.radius[k] = li.radius;
      w.phi[k] = li.phi;
      w.wx[k] = li.w.x, w.wy[k] = li.w.y, w.wz[k] = li.w.z;
      w.cos_o[k] = li.cos_o, w.sin_o[k] = li.sin_o, w.cos_e[k] = li.cos_e;
      w.two_sided[k] = li.two_sided ? 1.0f : 0.0f;
      w.child[k] = 0;
    }
  }
  for (size_t k = 0; k < slots.size(); ++k) {
    const BuildNode& b = nodes_[slots[k]];
    if (b.leaf) {
      wide_[index].leaf_mask = uint16_t(wide_[index].leaf_mask | (1u << k));
      wide_[index].child[k] = b.child_or_light;
      slot_of_light_[b.child_or_light] = int32_t(kWidth * index + k);
    } else {
      const uint32_t child = build_wide(slots[k], index, uint8_t(k));  // (wide_ may move)
      wide_[index].child[k] = child;
    }
  }
  return index;
}

namespace {

// Four floats, one per slot of a wide node (GCC's vector extensions: SSE on x86-64).
using F4 = float __attribute__((vector_size(16)));
using I4 = int __attribute__((vector_size(16)));

F4 load(const float* p) {
  F4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
F4 splat(float x) { return F4{x, x, x, x}; }
F4 sqrt4(F4 x) {
  for (int k = 0; k < 4; ++k) x[k] = std::sqrt(x[k]);  // (sqrtps)
  return x;
}
F4 select(I4 mask, F4 a, F4 b) { return mask ? a : b; }
F4 max4(F4 a, F4 b) { return a > b ? a : b; }
F4 safe_sqrt4(F4 x) { return sqrt4(max4(x, splat(0.0f))); }

// The importances' total, summed pairwise (the same order wherever a choice's probability is made)
// over the first `used` slots rounded up to a power of two: the empty slots after them hold 0, and
// adding those pairwise would change nothing.
float sum_of_slots(const float importance[LightSampler::kWidth], int used) {
  int n = 4;
  while (n < used) n *= 2;
  float s[LightSampler::kWidth];
  std::memcpy(s, importance, sizeof(float) * size_t(n));
  for (; n > 1; n /= 2)
    for (int i = 0; i < n / 2; ++i) s[i] = s[2 * i] + s[2 * i + 1];
  return s[0];
}

}  // namespace

void LightSampler::importances(const WideNode& node, const LightSampleContext& ctx, float out[kWidth]) {
  // LightImportance::operator() for four slots at once; see there for the steps. The passes over
  // the node's groups of four do not depend on each other; groups of empty slots weigh nothing.
  int group = 0;
  for (; group < node.used; group += 4) {
    const F4 radius = load(node.radius + group);
    const F4 dx = splat(ctx.p.x) - load(node.cx + group), dy = splat(ctx.p.y) - load(node.cy + group),
             dz = splat(ctx.p.z) - load(node.cz + group);
    const F4 d2_true = dx * dx + dy * dy + dz * dz;
    const F4 radius2 = radius * radius;
    const F4 d2 = max4(max4(d2_true, radius2), splat(1e-12f));
    const I4 outside = d2_true > radius2;
    const F4 inv_d = 1.0f / sqrt4(select(outside, d2_true, splat(1.0f)));
    const F4 sin_b = select(outside, radius * inv_d, splat(0.0f));
    const F4 cos_b = select(outside, safe_sqrt4(1.0f - sin_b * sin_b), splat(-1.0f));
    const F4 wix = select(outside, dx * inv_d, splat(0.0f)), wiy = select(outside, dy * inv_d, splat(0.0f)),
             wiz = select(outside, dz * inv_d, splat(1.0f));

    F4 cos_w = load(node.wx + group) * wix + load(node.wy + group) * wiy + load(node.wz + group) * wiz;
    cos_w = select(load(node.two_sided + group) > 0.0f, select(cos_w < 0.0f, -cos_w, cos_w), cos_w);
    const F4 cos_o = load(node.cos_o + group), sin_o = load(node.sin_o + group);
    const I4 in_cone = cos_w > cos_o;
    const F4 sin_w = safe_sqrt4(1.0f - cos_w * cos_w);
    const F4 cos_x = select(in_cone, splat(1.0f), cos_w * cos_o + sin_w * sin_o);
    const F4 sin_x = select(in_cone, splat(0.0f), sin_w * cos_o - cos_w * sin_o);
    const F4 cos_p = select(cos_x > cos_b, splat(1.0f), cos_x * cos_b + sin_x * sin_b);
    F4 importance = select(cos_p <= load(node.cos_e + group), splat(0.0f), load(node.phi + group) * cos_p / d2);

    if (ctx.n != Normal3(0.0f)) {
      const F4 cos_i = -(splat(ctx.n.x) * wix + splat(ctx.n.y) * wiy + splat(ctx.n.z) * wiz);
      const F4 bound = max4(cos_i * cos_b + safe_sqrt4(1.0f - cos_i * cos_i) * sin_b, splat(0.0f));
      importance *= select(cos_i > cos_b, splat(1.0f), bound);
    }
    // Not finite (or negative): nothing (NaN fails both comparisons).
    importance = select((importance > 0.0f) & (importance < splat(INFINITY)), importance, splat(0.0f));
    std::memcpy(out + group, &importance, sizeof importance);
  }
  std::fill(out + group, out + kWidth, 0.0f);
}

int LightSampler::bvh_depth() const {
  int depth = 0;
  for (size_t i = 0; i < nodes_.size(); ++i) {
    if (!nodes_[i].leaf) continue;
    int d = 0;
    for (size_t n = i; n != 0; n = nodes_[n].parent) ++d;
    depth = std::max(depth, d);
  }
  return depth;
}

bool LightSampler::tree_may_reach(const LightSampleContext& ctx) const {
  if (nodes_.empty()) return false;
  // Only lights at infinity need to know, to take the tree's share. Otherwise an interior root
  // that cannot reach ctx shows in its children's importance, and a lone light is chosen anyway
  // (as by power: its shadow ray finds nothing where it cannot reach).
  if (infinite_.empty()) return true;
  return root_importance_(ctx) > 0;
}

float LightSampler::infinite_probability(bool tree_may_reach) const {
  if (infinite_.empty()) return 0;
  // Where no light of the tree can reach, the lights at infinity take every ray.
  return tree_may_reach ? float(infinite_.size()) / float(infinite_.size() + 1) : 1.0f;
}

SampledLight LightSampler::sample_emitter(float u) const {
  if (emitter_choice_.empty()) return {};
  size_t li = emitter_choice_.sample(u);
  return {uint32_t(li), emitter_choice_.pmf(li)};
}

// The paper's rule gives every light this share uniformly.
constexpr float kPaperUniformShare = 0.1f;

SampledLight LightSampler::sample(const LightSampleContext& ctx, float u) const {
  if (mode_ == Mode::Weights) return sample_emitter(u);
  if (mode_ == Mode::Bvh) return sample_tree(ctx, u);
  // The paper's rule: the uniform share, or the tree under the paper's estimates.
  const size_t n = lights_.size();
  if (u < kPaperUniformShare) {
    size_t light = std::min(size_t(u / kPaperUniformShare * float(n)), n - 1);
    return {uint32_t(light), pmf(ctx, light)};
  }
  SampledLight s = sample_tree(ctx, std::min((u - kPaperUniformShare) / (1 - kPaperUniformShare), kOneMinusEpsilon));
  if (s.pmf > 0) s.pmf = kPaperUniformShare / float(n) + (1 - kPaperUniformShare) * s.pmf;
  return s;
}

float LightSampler::pmf(const LightSampleContext& ctx, size_t light) const {
  if (mode_ == Mode::Weights) return emitter_choice_.pmf(light);
  if (mode_ == Mode::Bvh) return tree_pmf(ctx, light);
  return kPaperUniformShare / float(lights_.size()) + (1 - kPaperUniformShare) * tree_pmf(ctx, light);
}

void LightSampler::slot_importances(const WideNode& node, const LightSampleContext& ctx, float out[kWidth]) const {
  importances(node, ctx, out);
  if (mode_ != Mode::Paper || node.leaf_mask == 0) return;
  for (int k = 0; k < kWidth; ++k)
    if (node.leaf_mask & (1u << k)) out[k] = std::max(0.0f, light_importance(lights_[node.child[k]], ctx));
}

SampledLight LightSampler::sample_tree(const LightSampleContext& ctx, float u) const {
  // A light at infinity, each with probability 1 / (n_infinite + 1), or the tree.
  const bool reaches = tree_may_reach(ctx);
  const float p_infinite = infinite_probability(reaches);
  if (u < p_infinite) {
    size_t k = std::min(size_t(u / p_infinite * float(infinite_.size())), infinite_.size() - 1);
    return {infinite_[k], p_infinite / float(infinite_.size())};
  }
  if (!reaches) return {};
  u = std::min((u - p_infinite) / (1 - p_infinite), kOneMinusEpsilon);
  float pmf = 1 - p_infinite;
  // A lone light is chosen anyway, as by power (its shadow ray finds nothing where it cannot reach).
  if (nodes_[0].leaf) return {wide_[0].child[0], pmf};
  // Descend, choosing each slot by the importance its bounds promise at ctx and reusing u.
  uint32_t node = 0;
  for (;;) {
    const WideNode& w = wide_[node];
    float importance[kWidth];
    slot_importances(w, ctx, importance);
    const float total = sum_of_slots(importance, w.used);
    if (!(total > 0)) return {};
    // The slot whose share of [0, total) holds u x total; the last slot with any importance takes
    // what rounding leaves, and no slot of importance 0 is ever chosen.
    const float target = u * total;
    int last = w.used - 1;
    while (importance[last] == 0) --last;
    int k = 0;
    float below = 0;
    while (k < last && (importance[k] == 0 || below + importance[k] <= target)) below += importance[k++];
    pmf *= importance[k] / total;
    u = std::clamp((target - below) / importance[k], 0.0f, kOneMinusEpsilon);
    if (w.leaf_mask & (1u << k)) {
      if (!(pmf > 0)) return {};
      return {w.child[k], pmf};
    }
    node = w.child[k];
  }
}

float LightSampler::tree_pmf(const LightSampleContext& ctx, size_t light) const {
  const bool reaches = tree_may_reach(ctx);
  const float p_infinite = infinite_probability(reaches);
  if (infinite_slot_[light] >= 0) return p_infinite / float(infinite_.size());
  const int32_t slot = slot_of_light_[light];
  if (slot < 0 || !reaches) return 0;
  // The product of the choices on the way down, gathered on the way up from the light's slot.
  float pmf = 1 - p_infinite;
  if (nodes_[0].leaf) return pmf;  // a lone light
  uint32_t node = uint32_t(slot) / kWidth, k = uint32_t(slot) % kWidth;
  for (;;) {
    const WideNode& w = wide_[node];
    float importance[kWidth];
    slot_importances(w, ctx, importance);
    const float total = sum_of_slots(importance, w.used);
    if (!(total > 0)) return 0;
    pmf *= importance[k] / total;
    if (node == 0) return pmf;
    k = w.parent_slot;
    node = w.parent;
  }
}

}  // namespace candela
