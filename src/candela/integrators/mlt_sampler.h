#pragma once
// The primary-sample-space sampler of Kelemen et al. 2002, as pbrt-v3 builds it (sec. 16.4.4): a
// Markov chain state is the vector of uniform numbers a path sampler consumes. A large step draws
// all of them afresh; a small step moves each by a Gaussian of deviation sigma (wrapped around
// [0, 1)). Numbers are drawn lazily, the first time a path asks for them in an iteration, so a
// path that grows longer gets fresh numbers for its new dimensions, and a number untouched for n
// iterations catches up with one Gaussian of deviation sigma sqrt(n).
//
// Numbers come in interleaved streams (camera subpath, light subpath, connection), so a change in
// how many numbers one subpath uses does not shift the numbers of the others.
#include <cmath>
#include <cstdint>
#include <vector>

#include "candela/math/vec.h"
#include "candela/sampling/rng.h"

namespace candela {

class MltSampler {
 public:
  static constexpr int kCameraStream = 0, kLightStream = 1, kConnectionStream = 2, kStreamCount = 3;

  // `chain` picks the random sequence: the same (seed, chain) gives the same path as a bootstrap
  // sample, which is how chains start at the paths the bootstrap chose.
  MltSampler(uint64_t seed, uint64_t chain, float sigma, float large_step_probability)
      : rng_(chain, hash_values(seed, 0x6d6c74)), sigma_(sigma), large_step_probability_(large_step_probability) {}

  // Starts a proposal: a large step with probability large_step_probability.
  void start_iteration() {
    ++iteration_;
    large_step_ = rng_.next_float() < large_step_probability_;
  }
  void accept() {
    if (large_step_) last_large_step_ = iteration_;
  }
  // Puts back every number the rejected proposal changed.
  void reject() {
    for (PrimarySample& x : samples_)
      if (x.modified == iteration_) x.restore();
    --iteration_;
  }
  void start_stream(int stream) {
    stream_ = stream;
    sample_in_stream_ = 0;
  }
  bool large_step() const { return large_step_; }

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
    int64_t modified = 0;  // the iteration that last changed it
    float saved_value = 0;
    int64_t saved_modified = 0;
    void backup() {
      saved_value = value;
      saved_modified = modified;
    }
    void restore() {
      value = saved_value;
      modified = saved_modified;
    }
  };

  float gaussian() {
    // Box-Muller: deterministic given the generator.
    float u1 = 1 - rng_.next_float(), u2 = rng_.next_float();
    return std::sqrt(-2 * std::log(u1)) * std::cos(2 * kPi * u2);
  }

  void ensure_ready(size_t index) {
    if (index >= samples_.size()) samples_.resize(index + 1);
    PrimarySample& x = samples_[index];
    // Numbers not touched since the last accepted large step start from a fresh uniform value.
    if (x.modified < last_large_step_) {
      x.value = rng_.next_float();
      x.modified = last_large_step_;
    }
    x.backup();
    if (large_step_) {
      x.value = rng_.next_float();
    } else {
      int64_t small_steps = iteration_ - x.modified;
      x.value += gaussian() * sigma_ * std::sqrt(float(small_steps));
      x.value -= std::floor(x.value);
      if (x.value >= 1) x.value = 0;  // -tiny - floor(-tiny) rounds to 1 in float
    }
    x.modified = iteration_;
  }

  Rng rng_;
  float sigma_, large_step_probability_;
  std::vector<PrimarySample> samples_;
  int64_t iteration_ = 0, last_large_step_ = 0;
  bool large_step_ = true;
  int stream_ = 0, sample_in_stream_ = 0;
};

}  // namespace candela
