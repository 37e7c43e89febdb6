#pragma once
// The primary-sample-space sampler of Kelemen et al. 2002, as pbrt-v3 builds it (sec. 16.4.4): a
// Markov chain state is the vector of uniform numbers a path sampler consumes. A large step draws
// all of them afresh; a small step moves each by a Gaussian of deviation sigma (wrapped around
// [0, 1)). Numbers are drawn lazily, the first time a path asks for them in an iteration, so a
// path that grows longer gets fresh numbers for its new dimensions, and a number untouched for n
// small steps catches up with one Gaussian of deviation sigma sqrt(n).
//
// Beyond pbrt: Veach's lens and caustic perturbations, in primary sample space. A lens
// perturbation moves only the two numbers that place the camera ray on the film, a caustic
// perturbation only the two that give the direction of the light ray leaving the light; every other
// number stays. The path keeps its strategy, its light subpath (lens) or its camera (caustic), and
// follows any specular chain from the moved ray to a nearby point of the same diffuse surface, the
// path-space moves of Veach (1997, sec. 11.4.3) for paths E S* D ... and L S* D E. Each moves its
// pair by a uniformly random direction and a distance exponentially distributed between r1 and r2
// (Veach's lens radii: 0.1 pixel and 10% of the film; caustic: 1e-4 and 0.1 radian, about 5e-5 and
// 0.05 of the direction numbers' unit square), wrapped around the unit square: a symmetric
// proposal, so the acceptance probability stays min(1, f(new) / f(old)) and every mixture of the
// four kinds of mutation, chosen with fixed probabilities, leaves the chain's target unchanged.
// (Where a perturbation would move nothing, a small step stands in for it: start_iteration.)
//
// Numbers come in interleaved streams (camera subpath, light subpath, connection), so a change in
// how many numbers one subpath uses does not shift the numbers of the others.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "candela/math/vec.h"
#include "candela/sampling/rng.h"

namespace candela {

// How often a chain proposes each kind of mutation (the rest are small steps).
struct MltMutationProbabilities {
  float large_step = 0.3f;
  float lens = 0;
  float caustic = 0;
};

// Which numbers the perturbations move: the index within its stream of the first of each pair, and
// the film's size in pixels (the lens radii are in pixels). -1: that perturbation is not used.
struct MltPerturbedNumbers {
  int camera_film = -1;     // camera stream: the film position
  int light_direction = -1; // light stream: the direction leaving the light
  Vec2 film_pixels{1, 1};
};

class MltSampler {
 public:
  static constexpr int kCameraStream = 0, kLightStream = 1, kConnectionStream = 2, kStreamCount = 3;

  // `chain` picks the random sequence: the same (seed, chain) gives the same path as a bootstrap
  // sample, which is how chains start at the paths the bootstrap chose.
  enum class Mutation { Large, Small, Lens, Caustic };

  MltSampler(uint64_t seed, uint64_t chain, float sigma, MltMutationProbabilities probabilities = {},
             MltPerturbedNumbers perturbed = {})
      : rng_(chain, hash_values(seed, 0x6d6c74)), sigma_(sigma), probabilities_(probabilities), perturbed_(perturbed) {
    if (perturbed_.camera_film < 0) probabilities_.lens = 0;
    if (perturbed_.light_direction < 0) probabilities_.caustic = 0;
  }

  // Starts a proposal, of a kind drawn with the fixed probabilities. A perturbation that would move
  // only numbers the current path does not read (the film position of a light-traced path, t = 1;
  // the light's direction when the light subpath has fewer than two vertices) would propose the same
  // path again: it becomes a small step instead. The chance of a small step then depends on the
  // current path, which the acceptance must weigh (small_step_probability).
  void start_iteration(bool lens_moves_path = true, bool caustic_moves_path = true) {
    ++iteration_;
    float u = rng_.next_float();
    const float lens = lens_moves_path ? probabilities_.lens : 0;
    const float caustic = caustic_moves_path ? probabilities_.caustic : 0;
    if (u < probabilities_.large_step) {
      mutation_ = Mutation::Large;
    } else if ((u -= probabilities_.large_step) < lens) {
      mutation_ = Mutation::Lens;
      // Radii in pixels, then in units of the film's extent.
      float r = exponential_radius(0.1f, 0.1f * std::max(perturbed_.film_pixels.x, perturbed_.film_pixels.y));
      Vec2 d = random_direction(r);
      offset_ = {d.x / perturbed_.film_pixels.x, d.y / perturbed_.film_pixels.y};
    } else if ((u -= lens) < caustic) {
      mutation_ = Mutation::Caustic;
      offset_ = random_direction(exponential_radius(5e-5f, 0.05f));
    } else {
      mutation_ = Mutation::Small;
      ++small_steps_;
    }
  }
  void accept() {
    if (mutation_ == Mutation::Large) {
      last_large_step_ = iteration_;
      small_steps_at_large_step_ = small_steps_;
    }
  }
  // Puts back every number the rejected proposal changed.
  void reject() {
    for (PrimarySample& x : samples_)
      if (x.modified == iteration_) x.restore();
    --iteration_;
    if (mutation_ == Mutation::Small) --small_steps_;
  }
  void start_stream(int stream) {
    stream_ = stream;
    sample_in_stream_ = 0;
  }
  // The probability that start_iteration makes a small step from a path where the perturbations
  // would (or would not) move anything. A small step from path x to path y is accepted with
  // min(1, f(y) P(y) / (f(x) P(x))) for P this probability, which keeps detailed balance.
  float small_step_probability(bool lens_moves_path, bool caustic_moves_path) const {
    return std::max(0.0f, 1 - probabilities_.large_step - (lens_moves_path ? probabilities_.lens : 0) -
                              (caustic_moves_path ? probabilities_.caustic : 0));
  }
  bool large_step() const { return mutation_ == Mutation::Large; }
  Mutation mutation() const { return mutation_; }

  float get_1d() {
    size_t index = size_t(stream_) + size_t(kStreamCount) * size_t(sample_in_stream_++);
    ensure_ready(index);
    return samples_[index].value;
  }
  Vec2 get_2d() {
    float x = get_1d();
    return {x, get_1d()};
  }
  Vec2 get_pixel_2d() { return get_2d(); }

 private:
  struct PrimarySample {
    float value = 0;
    int64_t modified = 0;     // the iteration that last changed it
    int64_t small_steps = 0;  // how many small steps it has taken
    float saved_value = 0;
    int64_t saved_modified = 0, saved_small_steps = 0;
    void backup() {
      saved_value = value;
      saved_modified = modified;
      saved_small_steps = small_steps;
    }
    void restore() {
      value = saved_value;
      modified = saved_modified;
      small_steps = saved_small_steps;
    }
  };

  float gaussian() {
    // Box-Muller: deterministic given the generator.
    float u1 = 1 - rng_.next_float(), u2 = rng_.next_float();
    return std::sqrt(-2 * std::log(u1)) * std::cos(2 * kPi * u2);
  }
  // Veach's perturbation radius: r2 (r1 / r2)^u, exponentially distributed between r1 and r2.
  float exponential_radius(float r1, float r2) { return r2 * std::pow(r1 / r2, rng_.next_float()); }
  Vec2 random_direction(float r) {
    float phi = 2 * kPi * rng_.next_float();
    return {r * std::cos(phi), r * std::sin(phi)};
  }

  // The move, if any, that this iteration's perturbation makes to number `index`.
  float perturbation(size_t index) const {
    auto in_pair = [&](int stream, int first, int& which) {
      if (first < 0 || index % kStreamCount != size_t(stream)) return false;
      int64_t k = int64_t(index / kStreamCount) - first;
      which = int(k);
      return k == 0 || k == 1;
    };
    int which = 0;
    if (mutation_ == Mutation::Lens && in_pair(kCameraStream, perturbed_.camera_film, which))
      return which == 0 ? offset_.x : offset_.y;
    if (mutation_ == Mutation::Caustic && in_pair(kLightStream, perturbed_.light_direction, which))
      return which == 0 ? offset_.x : offset_.y;
    return 0;
  }

  void ensure_ready(size_t index) {
    if (index >= samples_.size()) samples_.resize(index + 1);
    PrimarySample& x = samples_[index];
    // Numbers not touched since the last accepted large step start from a fresh uniform value.
    if (x.modified < last_large_step_) {
      x.value = rng_.next_float();
      x.modified = last_large_step_;
      x.small_steps = small_steps_at_large_step_;
    }
    x.backup();
    if (mutation_ == Mutation::Large) {
      x.value = rng_.next_float();
    } else {
      // The small steps it missed (this one included, if this is one), then this iteration's
      // perturbation if it moves this number.
      int64_t missed = small_steps_ - x.small_steps;
      if (missed > 0) x.value += gaussian() * sigma_ * std::sqrt(float(missed));
      x.value += perturbation(index);
      x.value -= std::floor(x.value);
      if (x.value >= 1) x.value = 0;  // -tiny - floor(-tiny) rounds to 1 in float
    }
    x.small_steps = small_steps_;
    x.modified = iteration_;
  }

  Rng rng_;
  float sigma_;
  MltMutationProbabilities probabilities_;
  MltPerturbedNumbers perturbed_;
  std::vector<PrimarySample> samples_;
  int64_t iteration_ = 0, last_large_step_ = 0;
  int64_t small_steps_ = 0, small_steps_at_large_step_ = 0;
  Mutation mutation_ = Mutation::Large;
  Vec2 offset_{0, 0};
  int stream_ = 0, sample_in_stream_ = 0;
};

}  // namespace candela
