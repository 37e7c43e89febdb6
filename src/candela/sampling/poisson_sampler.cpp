#include "candela/sampling/poisson_sampler.h"

#include <algorithm>

namespace candela {
namespace {

float toroidal_distance_squared(Vec2 a, Vec2 b) {
  float dx = std::abs(a.x - b.x), dy = std::abs(a.y - b.y);
  dx = std::min(dx, 1 - dx);
  dy = std::min(dy, 1 - dy);
  return dx * dx + dy * dy;
}

// Kept points bucketed on a g x g toroidal grid whose cells are at least the initial radius wide, so
// a candidate's conflicts lie in its own and the 8 neighbouring cells (the radius only ever shrinks).
// With fewer than 3 cells per side the neighbourhood would wrap onto itself: one cell then holds all.
class ToroidalGrid {
 public:
  ToroidalGrid(float cell_min_size, int capacity)
      : cells_(cells_per_side(cell_min_size)), head_(size_t(cells_ * cells_), -1) {
    next_.reserve(size_t(capacity));
    points_.reserve(size_t(capacity));
  }

  bool far_from_all(Vec2 p, float radius) const {
    float radius_squared = radius * radius;
    int cx = cell_coordinate(p.x), cy = cell_coordinate(p.y);
    int reach = cells_ == 1 ? 0 : 1;
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx)
        for (int i = head_[cell_index(cx + dx, cy + dy)]; i >= 0; i = next_[size_t(i)])
          if (toroidal_distance_squared(p, points_[size_t(i)]) < radius_squared) return false;
    return true;
  }

  void add(Vec2 p) {
    int cell = cell_index(cell_coordinate(p.x), cell_coordinate(p.y));
    next_.push_back(head_[cell]);
    head_[cell] = int(points_.size());
    points_.push_back(p);
  }

  std::vector<Vec2> take_points() { return std::move(points_); }

 private:
  static int cells_per_side(float cell_min_size) {
    int cells = int(1 / cell_min_size);
    return cells < 3 ? 1 : cells;
  }
  int cell_coordinate(float v) const { return std::min(cells_ - 1, int(v * float(cells_))); }
  size_t cell_index(int cx, int cy) const {
    cx = (cx + cells_) % cells_;
    cy = (cy + cells_) % cells_;
    return size_t(cy * cells_ + cx);
  }

  int cells_;
  std::vector<int> head_;  // first point of each cell's linked list, -1 when empty
  std::vector<int> next_;  // next point in the same cell
  std::vector<Vec2> points_;
};

}  // namespace

PoissonDiscSet generate_poisson_disc_set(int n, Rng& rng) {
  n = std::max(1, n);
  float radius = poisson_disc_radius(n);
  ToroidalGrid grid(radius, n);
  const int rejections_before_relaxing = 100 * n;
  int placed = 0, rejections = 0;
  while (placed < n) {
    float x = rng.next_float();
    Vec2 candidate{x, rng.next_float()};
    if (grid.far_from_all(candidate, radius)) {
      grid.add(candidate);
      ++placed;
      rejections = 0;
    } else if (++rejections >= rejections_before_relaxing) {
      radius *= 0.95f;  // relaxation: the square is (nearly) full at this radius
      rejections = 0;
    }
  }
  return {grid.take_points(), radius};
}

PoissonSampler::PoissonSampler(int samples_per_set, uint64_t seed) : n_(std::max(1, samples_per_set)), seed_(seed) {}

void PoissonSampler::start_pixel_sample(int x, int y, uint64_t sample_index) {
  uint64_t set_number = sample_index / uint64_t(n_);
  if (!has_set_ || x != set_x_ || y != set_y_ || set_number != set_number_) {
    // The set's own stream, distinct from every per-sample stream below (different sequence hash).
    Rng set_rng(hash_values(uint64_t(x), uint64_t(y), set_number, seed_, 0x706f6973736f6eULL), set_number);
    set_ = generate_poisson_disc_set(n_, set_rng);
    has_set_ = true;
    set_x_ = x;
    set_y_ = y;
    set_number_ = set_number;
  }
  index_in_set_ = uint32_t(sample_index % uint64_t(n_));
  rng_.set_sequence(hash_values(uint64_t(x), uint64_t(y), seed_), mix_bits(sample_index));
}

}  // namespace candela
