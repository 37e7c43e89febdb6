#include "candela/geometry/triangle_pairs.h"

#include <algorithm>

namespace candela {

TrianglePairs pair_triangles(const std::vector<uint32_t>& indices, const std::vector<Point3>& positions) {
  const size_t n = indices.size() / 3;
  // Every directed edge (a, b) of triangle t at position k (from vertex k to vertex k + 1), sorted by
  // (a, b): the partner of an edge is the entry for (b, a).
  struct Edge {
    uint64_t key;
    uint32_t triangle;
    uint8_t position;
  };
  auto key = [](uint32_t a, uint32_t b) { return (uint64_t(a) << 32) | b; };
  std::vector<Edge> edges(3 * n);
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k)
      edges[3 * t + size_t(k)] = {key(indices[3 * t + size_t(k)], indices[3 * t + size_t((k + 1) % 3)]), uint32_t(t),
                                  uint8_t(k)};
  std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
    return a.key != b.key ? a.key < b.key : a.triangle < b.triangle;
  });

  TrianglePairs out;
  out.quads.reserve(4 * (n / 2 + n / 8));
  out.halves.reserve(n / 2 + n / 8);
  std::vector<bool> paired(n, false);
  for (size_t t = 0; t < n; ++t) {
    if (paired[t]) continue;
    paired[t] = true;
    const uint32_t* a = &indices[3 * t];
    QuadTriangles q;
    q.first = uint32_t(t);
    // Of the unpaired neighbours, the one across the longest edge: a quad's diagonal is its longest
    // edge when the quad is compact (two halves of a grid cell, not two cells' slivers), and compact
    // quads have tight bounding boxes.
    float longest = -1;
    for (int k = 0; k < 3; ++k) {
      uint32_t from = a[k], to = a[(k + 1) % 3];
      if (from == to) continue;
      float length2 = length_squared(positions[to] - positions[from]);
      if (length2 <= longest) continue;
      auto it = std::lower_bound(edges.begin(), edges.end(), key(to, from),
                                 [](const Edge& e, uint64_t k) { return e.key < k; });
      for (; it != edges.end() && it->key == key(to, from); ++it) {
        if (paired[it->triangle] || it->triangle == t) continue;
        // The quad (v0, v1, v2, v3): this triangle is (v0, v1, v3) with the shared edge v1 -> v3
        // being its edge k, and the partner is (v2, v3, v1) with v3 -> v1 its edge at `position`.
        longest = length2;
        q.second = it->triangle;
        q.first_rotation = uint8_t((k + 2) % 3);
        q.second_rotation = uint8_t((it->position + 2) % 3);
        break;
      }
    }
    if (q.second != QuadTriangles::kNone) paired[q.second] = true;
    const uint32_t v0 = a[q.first_rotation], v1 = a[(q.first_rotation + 1) % 3], v3 = a[(q.first_rotation + 2) % 3];
    const uint32_t v2 = q.second == QuadTriangles::kNone ? v3 : indices[3 * size_t(q.second) + q.second_rotation];
    out.quads.insert(out.quads.end(), {v0, v1, v2, v3});
    out.halves.push_back(q);
  }
  return out;
}

}  // namespace candela
