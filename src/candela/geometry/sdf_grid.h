#pragma once
// Signed distance function grids (Mitsuba 3's "sdfgrid" shape): Mitsuba's .vol files, and the math
// the ray tracer needs on the trilinear interpolant of the samples: the cubic it becomes along a ray
// (Hansson-Söderlund, Evans and Akenine-Möller, "Ray Tracing of Signed Distance Function Grids",
// JCGT 11(3), 2022), its first root inside a voxel, its gradient and Mitsuba's smooth normal.
//
// Coordinates: in *index space* sample (i, j, k) sits at (i, j, k), so voxel (i, j, k) is the cube
// [i, i + 1] x [j, j + 1] x [k, k + 1]; object space ([0,1]^3) is index space divided by n - 1 per
// axis; a voxel's *local* coordinates run over [0,1]^3 from its lower corner.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/math/transform.h"
#include "candela/math/vec3d.h"
#include "candela/description/scene_desc.h"

namespace candela {

// ---------------------------------------------------------------- Mitsuba's .vol files

// A grid of samples as a .vol file holds it. The file is little-endian: the bytes "VOL", a version
// byte (3), int32 encoding (1 = float32), int32 nx, ny, nz, int32 channels, six float32 (a bounding
// box, min then max), then nx ny nz channels float32: a sample's channels together, x fastest, then
// y, then z.
struct VolumeGrid {
  std::array<int, 3> resolution{0, 0, 0};
  int channels = 1;
  std::array<float, 6> bounds{0, 0, 0, 1, 1, 1};
  std::vector<float> values;
};

// More samples than this are refused (voxel indices are 32-bit, and it is 8 GiB of floats).
inline constexpr uint64_t kMaxVolumeGridValues = uint64_t(1) << 31;

// Throws SceneError "<referenced_from>: cannot read volume grid 'FILE': <why>" for a missing,
// unreadable, truncated or malformed file (magic, version, encoding, a resolution below 1, more
// than kMaxVolumeGridValues values). Bytes after the values are ignored, as Mitsuba does.
VolumeGrid read_volume_grid(const std::filesystem::path& file, const SourceLocation& referenced_from);

// Writes `grid` as a version 3 float32 .vol file; throws OutputError naming the file.
void write_volume_grid(const std::filesystem::path& file, const VolumeGrid& grid);

// Why `grid` cannot be rendered as an SDF grid, or "" when it can: a resolution below 2 on an axis,
// a value count other than nx ny nz, a value that is not finite, or no voxel that the surface
// passes through (Mitsuba refuses an empty grid too).
std::string sdf_grid_problem(const SdfGridShape& grid);

// The SDF grid shape of a one-channel .vol file; throws SceneError naming the file (as
// read_volume_grid) for any problem of read_volume_grid or sdf_grid_problem, or another channel count.
SdfGridShape read_sdf_grid_file(const std::filesystem::path& file, const SourceLocation& referenced_from,
                                SdfNormals normals);

// The number of voxels the surface passes through: those whose corners are not all > 0 or all < 0.
uint64_t count_surface_voxels(const SdfGridShape& grid);

// ---------------------------------------------------------------- the interpolant in one voxel

// The samples at a voxel's corners; corner (x, y, z) in {0, 1}^3 is at index x + 2y + 4z.
using VoxelCorners = std::array<double, 8>;

// The trilinear interpolant of `f` at the local point p in [0,1]^3. It reproduces the corners
// exactly, and on a face it is the same function of that face's four samples in both voxels that
// share the face, evaluated by the same operations: the two give bit-identical values there.
double trilinear(const VoxelCorners& f, const Vec3d& p);
// Its gradient with respect to the local coordinates.
Vec3d trilinear_gradient(const VoxelCorners& f, const Vec3d& p);

// The cubic the interpolant becomes along the local line o + s d: f(o + s d) = c[0] + c[1] s +
// c[2] s^2 + c[3] s^3.
std::array<double, 4> trilinear_along_line(const VoxelCorners& f, const Vec3d& o, const Vec3d& d);

// The first root in [s0, s1] of the cubic c (coefficients as above), where f0 and f1 stand for its
// values at s0 and s1 (a caller may take them from an evaluation it keeps consistent between
// neighbouring voxels). The interval is split at the extrema of the cubic so that the first piece
// where it changes sign (or reaches zero) brackets the root, which a Newton iteration safeguarded by
// bisection then finds to near double precision. nullopt where it does not reach zero.
std::optional<double> first_cubic_root(const std::array<double, 4>& c, double s0, double s1, double f0, double f1);

// ---------------------------------------------------------------- the grid

// The surface voxels of an SDF grid (Embree's primitives, one each) and the queries on them.
class SdfGrid {
 public:
  // `shape` must be valid (sdf_grid_problem(shape) empty).
  explicit SdfGrid(const SdfGridShape& shape);

  const std::array<int, 3>& resolution() const { return n_; }
  uint32_t voxel_count() const { return uint32_t(voxels_.size()); }
  // The lower corner (sample index) of surface voxel `voxel`.
  std::array<int, 3> voxel_corner(uint32_t voxel) const;
  // Object space from index space: a scale by 1 / (n - 1) per axis.
  Transform index_to_object() const;

  // The first t in (t_near, t_far) where the line o + t d (index space; d need not be unit length)
  // meets the surface inside the voxel. Where the line enters and leaves the voxel through a face,
  // the value there is taken on the face itself, as the neighbour across it takes it, so that a
  // surface crossing near a face is found by one of the two voxels and never by neither.
  std::optional<double> intersect_voxel(uint32_t voxel, const Vec3d& o, const Vec3d& d, double t_near,
                                        double t_far) const;

  // The point p (index space) moved along the gradient of the voxel's interpolant onto its zero set
  // by one Newton step, kept inside the voxel: removes most of the rounding of a hit point.
  Vec3d project_to_surface(uint32_t voxel, const Vec3d& p) const;
  // The gradient of the voxel's interpolant at p (index space, clamped into the voxel), in object
  // space: the geometric normal before to_world.
  Vec3d gradient(uint32_t voxel, const Vec3d& p) const;
  // Mitsuba's smooth shading normal at p (index space), in object space and not normalised: the
  // normalised gradients of the eight voxels around the sample nearest to p, blended trilinearly
  // by p's position relative to their centres (Hansson-Söderlund et al. 2022). Each voxel's
  // gradient is taken from differences of the interpolant across the voxel along each axis at p's
  // position along the other two, so it varies continuously as p crosses voxel faces.
  Vec3d smooth_normal(const Vec3d& p) const;

 private:
  double sample(int x, int y, int z) const;  // clamped to the grid
  VoxelCorners corners(const std::array<int, 3>& corner) const;
  // The bilinear interpolant on the sample plane `index` across `axis`, at cell `cell` of the two
  // other axes with weights w.
  double plane(int axis, int index, const std::array<int, 3>& cell, const Vec3d& w) const;

  std::array<int, 3> n_;
  std::shared_ptr<const std::vector<float>> values_;
  std::vector<uint32_t> voxels_;  // the sample index of each surface voxel's lower corner
};

}  // namespace candela
