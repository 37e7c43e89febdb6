#pragma once
// Which light a shadow ray goes to (and which light a light path starts from).
//
//   LightSelection::Power / Uniform  one distribution for every point: by power, or every emitter
//                                    alike (scene.cpp builds the weights)
//   LightSelection::Bvh              a light BVH (Conty Estevez and Kulla 2018, as pbrt-v4's
//                                    BVHLightSampler): each node bounds its lights' positions,
//                                    total power and emission directions; a point descends the tree
//                                    choosing each child by the importance its bounds promise there
//                                    (power / distance^2, times the cosines the direction cones
//                                    allow at the light and at the point). O(log n) per choice, and
//                                    lights behind the point or facing away get no rays.
//   LightSelection::Paper            the paper's rule (sec. 4.5): each light in proportion to its
//                                    estimated irradiance at the point (light_importance: radiance
//                                    x projected solid angle), mixed with a uniform share of 0.1 so
//                                    that no light the estimate misjudges is left out. Found through
//                                    the same tree (its bounds above the lights, the estimate at
//                                    them): O(log n) per choice, not O(n).
//
// Lights at infinity (sky, environment maps, distant lights) have no position to bound: the BVH
// sampler picks each of them with probability 1 / (n_infinite + 1) and the tree with the rest, as
// pbrt-v4 does (all of it where no light of the tree can reach the point). Light paths (BDPT, MLT)
// start from lights chosen without a point, by power.
//
// The tree's probabilities sum to 1 less the chance of descending into a group whose bounds reach
// the point while none of its lights does (a merged cone is wider than its parts): sample() then
// returns no light, whose shadow ray would have carried nothing. No light that can reach the point
// ever has probability 0 there (the bounds are conservative), so estimators stay unbiased.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "candela/lights/light.h"
#include "candela/sampling/distribution1d.h"

namespace candela {

// What a light (or a group of lights) can give: where it is, its power, and the cone of its
// emission directions: normals within theta_o of w, each emitting up to theta_e away from its
// normal (a diffuse emitter: theta_o = 0 and theta_e = pi/2 about its normal; a point: theta_o = pi).
struct LightBounds {
  Bounds3 bounds;
  float phi = 0;        // power-like weight: the importance at unit distance, head-on
  Vec3 w{0, 0, 1};      // the cone axis
  float cos_theta_o = 1;
  float cos_theta_e = 1;
  bool two_sided = false;
};

// The bounds of one light, or nothing for lights at infinity and lights that emit nothing.
std::optional<LightBounds> light_bounds(const Light& light);
// Bounds of both (the direction cones merged into the smallest cone holding both).
LightBounds merge(const LightBounds& a, const LightBounds& b);
// The importance bounds promise at a point: an upper estimate of the irradiance any of their
// lights could give there (up to a common factor), zero only where none of them can reach it.
// What the sampler evaluates at every step down the tree, precomputed from the bounds.
struct LightImportance {
  Point3 center;  // of the box, and the radius of its bounding sphere
  float radius = 0;
  float phi = 0;
  Vec3 w{0, 0, 1};
  float cos_o = 1, sin_o = 0, cos_e = 1;
  bool two_sided = false;

  LightImportance() = default;
  explicit LightImportance(const LightBounds& b);
  float operator()(const LightSampleContext& ctx) const;
};

struct SampledLight {
  uint32_t light = 0;
  float pmf = 0;  // 0: no light (none can reach the point)
};

class LightSampler {
 public:
  LightSampler() = default;
  enum class Mode {
    Weights,  // every point by the weights (power, or uniform over emitters)
    Bvh,      // points through the light BVH
    Paper,    // points by the paper's rule, through the light BVH
  };
  // weights: per light, the point-independent choice (power, or uniform over emitters), which light
  // paths use in every mode. Mode::Paper keeps `lights` (it evaluates their estimates): they must
  // outlive the sampler and stay where they are.
  LightSampler(std::span<const Light> lights, std::span<const float> weights, Mode mode);

  // A light for a point gathering light at ctx (u in [0, 1)), and the probability of choosing it.
  SampledLight sample(const LightSampleContext& ctx, float u) const;
  // The probability that sample(ctx, .) chooses `light`.
  float pmf(const LightSampleContext& ctx, size_t light) const;
  // A light for a light path, chosen without a point (by the weights), and its probability.
  SampledLight sample_emitter(float u) const;
  float emitter_pmf(size_t light) const { return emitter_choice_.pmf(light); }

  bool uses_bvh() const { return mode_ != Mode::Weights; }
  // The binary tree's depth (0 without one): for tests and the scene's statistics.
  int bvh_depth() const;

  // The tree as built: binary, each node with its bounds (for the tests).
  struct BuildNode {
    uint32_t child_or_light = 0;  // interior: the first of its two children (the second follows it)
    uint32_t parent = 0;
    uint32_t lights = 1;          // in its subtree
    bool leaf = false;
  };
  const std::vector<BuildNode>& nodes() const { return nodes_; }
  const LightBounds& node_bounds(size_t node) const { return bounds_[node]; }

  // The tree as descended: up to sixteen descendants of a binary node side by side in one node (its
  // children, the one of most lights replaced by its own two while there is room), their bounds
  // stored lane by lane so that passes of 4-wide SIMD, independent of each other, evaluate the
  // importances of four slots each. A quarter of the levels of the binary tree, and each choice is
  // made from the tighter bounds of the lower levels: on the many-light city, relMSE at equal
  // samples 0.028 four-wide, 0.024 eight-wide, 0.016 sixteen-wide (docs/performance.md).
  static constexpr int kWidth = 16;
  struct alignas(64) WideNode {
    float cx[kWidth], cy[kWidth], cz[kWidth], radius[kWidth];  // bounding sphere
    float phi[kWidth];                                          // 0 in unused slots
    float wx[kWidth], wy[kWidth], wz[kWidth];                   // cone axis
    float cos_o[kWidth], sin_o[kWidth], cos_e[kWidth];
    float two_sided[kWidth];                                    // 1 or 0
    uint32_t child[kWidth];  // a wide node, or a light where leaf_mask has the slot's bit
    uint32_t parent = 0;                   // wide node and slot above (the root: itself)
    uint8_t parent_slot = 0;
    uint8_t used = 0;         // slots in use, the first ones (the others are empty)
    uint16_t leaf_mask = 0;  // bit k: slot k holds a light
  };

 private:
  // The importance of each of a wide node's slots at ctx (LightImportance, four at once).
  static void importances(const WideNode& node, const LightSampleContext& ctx, float out[kWidth]);
  void build(std::vector<std::pair<uint32_t, LightBounds>>& lights, size_t begin, size_t end, uint32_t index,
             uint32_t parent);
  uint32_t build_wide(uint32_t binary_node, uint32_t parent, uint8_t parent_slot);
  SampledLight sample_tree(const LightSampleContext& ctx, float u) const;
  float tree_pmf(const LightSampleContext& ctx, size_t light) const;
  // importances() of a node's slots, the paper's estimate at lights under Mode::Paper.
  void slot_importances(const WideNode& node, const LightSampleContext& ctx, float out[kWidth]) const;
  bool tree_may_reach(const LightSampleContext& ctx) const;
  float infinite_probability(bool tree_may_reach) const;

  Distribution1D emitter_choice_;
  Mode mode_ = Mode::Weights;
  std::span<const Light> lights_;  // (Mode::Paper)
  std::vector<BuildNode> nodes_;
  std::vector<LightBounds> bounds_;  // of each binary node
  LightImportance root_importance_;  // of the whole tree
  std::vector<WideNode> wide_;       // wide_[0] is the root
  std::vector<uint32_t> infinite_;           // lights at infinity, chosen uniformly beside the tree
  std::vector<int32_t> slot_of_light_;       // wide node x 4 + slot holding each light (-1: at infinity or dark)
  std::vector<int32_t> infinite_slot_;       // each light's place in infinite_ (-1: not there)
};

}  // namespace candela
