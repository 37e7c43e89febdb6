#pragma once
// Loop subdivision of a triangle mesh, as pbrt-v4's Shape "loopsubdiv" makes it (pbrt-v4's
// src/pbrt/util/loopsubdiv.cpp): the control mesh refined `levels` times (each triangle into four),
// every vertex of the result then moved to its point on the limit surface and given the limit
// surface's normal as its shading normal. The result is a triangle mesh.
//
// OpenSubdiv's Far::TopologyRefiner (Sdc::SCHEME_LOOP, boundaries as creases:
// VTX_BOUNDARY_EDGE_ONLY) refines the topology and keeps each vertex's one-ring in order; the points
// follow one of two rule sets:
//
//   LoopRules::PbrtV4 (what pbrt-v4 computes; the pbrt reader's choice):
//     - new edge points: 3/8 of each end and 1/8 of the two opposite corners; 1/2 - 1/2 on a
//       boundary edge (Loop's rules, the same in both sets: OpenSubdiv's PrimvarRefiner computes them);
//     - an interior vertex of valence n: (1 - n beta) p + beta (sum of its ring), with Warren's
//       weight beta = 3 / (8 n) (3/16 for n = 3); a boundary vertex: 1/8 - 3/4 - 1/8 of its two
//       boundary neighbours and itself;
//     - limit positions: interior (1 - n gamma) p + gamma (sum of the ring), gamma = 1 / (n + 3 / (8
//       beta)) (exact for these weights); boundary 1/5 - 3/5 - 1/5 (pbrt's rule: the exact limit of
//       the boundary's cubic B-spline is 1/6 - 2/3 - 1/6, so pbrt's boundary points lie off the
//       limit curve by 1/30 of the second difference of the refined boundary polygon, which
//       shrinks by 4 per level);
//     - normals: pbrt's limit tangents S, T (cos / sin weights inside; pbrt's boundary masks for
//       valence 2, 3, 4 and more), N = S x T, with the masks taken over the ring's limit points
//       (as pbrt-v4 does) rather than its refined points: close to the limit surface's normals,
//       not exactly them (on a coarse regular torus 2 degrees off at level 0, 0.03 at level 4).
//   LoopRules::OpenSubdiv (the textbook Loop surface): Loop's original vertex weight
//     beta = (5/8 - (3/8 + cos(2 pi / n) / 4)^2) / n and the exact limit positions and tangents
//     (OpenSubdiv's PrimvarRefiner::Interpolate and Limit). For valences 3 and 6 (and on boundaries
//     before the limit step) both rule sets refine alike; elsewhere the surfaces differ a little.
//
// Normals face the side opposite to the triangles' winding normal (p1 - p0) x (p2 - p0), as
// pbrt-v4's do: pbrt's ring runs clockwise about that winding normal. Renderers that face the
// geometric normal towards the shading normal (pbrt-v4, candela) therefore take the side the
// normals point to as the front; it matters to one-sided emitters and to media.
//
// Vertices where the control mesh is not a manifold (an edge of three or more triangles, two
// triangles that traverse their shared edge in the same direction, a vertex where separate fans of
// triangles meet) have no ordered ring: there OpenSubdiv's own rules apply in both sets (such edges
// become creases, such vertices corners). Points that no triangle uses are left out of the result.
// A normal that comes out zero (degenerate geometry) is replaced by the vertex's adjacent triangles'
// area-weighted normal, on the same side.
#include <cstdint>
#include <string>
#include <vector>

#include "candela/description/shapes.h"
#include "candela/math/vec.h"

namespace candela {

enum class LoopRules { PbrtV4, OpenSubdiv };

// The most triangles loop_subdivide makes from one control mesh: 4.2 million (pbrt-v4's killeroo at
// 4 levels is 2.1 million). The subdivision peaks at about 300 bytes per triangle made (OpenSubdiv's
// tables of every level, the points), 1.2 GiB here, and the pbrt reader runs it while reading, before
// candela's memory check (scene/resource_limits.h); the fuzz build reads it within its 2 GiB and 10 s.
inline constexpr uint64_t kMaxLoopSubdivisionTriangles = uint64_t(1) << 22;

// triangles * 4^levels, saturating at UINT64_MAX (levels < 0 counts as 0).
uint64_t loop_subdivision_triangle_count(uint64_t triangles, int levels);

// Why loop_subdivide cannot subdivide this control mesh, or "" when it can: no triangles, an index
// count that is not a multiple of 3, an index outside [0, point_count), a triangle that names a point
// twice, a point with more than 65535 triangles or neighbours around it (OpenSubdiv's limit), levels
// below 0, or more than kMaxLoopSubdivisionTriangles triangles after `levels` levels.
// Readers call it to point at the place in the file.
std::string loop_subdivision_problem(size_t point_count, const std::vector<int>& indices, int levels);

// The mesh of `levels` levels of Loop subdivision of the triangles `indices` (three indices into
// `points` each, wound consistently), pushed to the limit surface: positions, unit normals (one per
// vertex, see above for their side) and indices; no uvs. levels = 0 only pushes the control mesh's
// vertices to their limit positions. Throws InternalError when loop_subdivision_problem finds a
// problem (check it first).
TriangleMesh loop_subdivide(const std::vector<Point3>& points, const std::vector<int>& indices, int levels,
                            LoopRules rules = LoopRules::PbrtV4);

}  // namespace candela
