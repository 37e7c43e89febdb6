#pragma once
// Piecewise-constant 1D distribution over a discrete set (used to pick lights by power).
#include <algorithm>
#include <cstddef>
#include <span>
#include <vector>

namespace candela {

class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(std::span<const float> weights) : pmf_(weights.begin(), weights.end()) {
    double total = 0;
    for (float w : pmf_) total += std::max(0.0f, w);
    if (total <= 0) {
      std::fill(pmf_.begin(), pmf_.end(), 1.0f);
      total = double(pmf_.size());
    }
    cdf_.resize(pmf_.size() + 1);
    double acc = 0;
    for (size_t i = 0; i < pmf_.size(); ++i) {
      pmf_[i] = float(std::max(0.0f, pmf_[i]) / total);
      acc += pmf_[i];
      cdf_[i + 1] = float(acc);
    }
    cdf_.back() = 1.0f;
  }
  size_t size() const { return pmf_.size(); }
  bool empty() const { return pmf_.empty(); }
  float pmf(size_t i) const { return pmf_[i]; }
  // Picks index i with probability pmf(i); u in [0,1).
  size_t sample(float u) const {
    auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
    size_t i = size_t(std::max<std::ptrdiff_t>(0, (it - cdf_.begin()) - 1));
    i = std::min(i, pmf_.size() - 1);
    while (pmf_[i] == 0 && i > 0) --i;  // never return a zero-probability entry
    return i;
  }
  // Remaps u into [0,1) within the chosen bucket, so the same number can be reused.
  float remap(float u, size_t i) const {
    float w = cdf_[i + 1] - cdf_[i];
    return w > 0 ? std::min((u - cdf_[i]) / w, 0x1.fffffep-1f) : 0.0f;
  }

 private:
  std::vector<float> pmf_, cdf_;
};

}  // namespace candela
