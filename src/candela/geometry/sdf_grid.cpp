#include "candela/geometry/sdf_grid.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <stdexcept>
#include <system_error>

#include "candela/base/error.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

constexpr size_t kVolumeHeaderBytes = 48;

uint32_t little_endian_u32(const unsigned char* bytes) {
  return uint32_t(bytes[0]) | uint32_t(bytes[1]) << 8 | uint32_t(bytes[2]) << 16 | uint32_t(bytes[3]) << 24;
}
int32_t little_endian_i32(const unsigned char* bytes) { return std::bit_cast<int32_t>(little_endian_u32(bytes)); }
float little_endian_f32(const unsigned char* bytes) { return std::bit_cast<float>(little_endian_u32(bytes)); }

void put_u32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xff));
}

VolumeGrid parse_volume_file(const fs::path& file) {
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (status.type() == fs::file_type::not_found) fail_file_content("no such file");
  if (status.type() == fs::file_type::directory) fail_file_content("it is a directory, not a file");
  std::ifstream in(file, std::ios::binary);
  if (!in) fail_file_content("cannot open it: {}", std::strerror(errno));

  unsigned char header[kVolumeHeaderBytes];
  in.read(reinterpret_cast<char*>(header), kVolumeHeaderBytes);
  const size_t got = size_t(in.gcount());
  if (got >= 3 && std::memcmp(header, "VOL", 3) != 0) fail_file_content("not a Mitsuba volume file (it does not start with \"VOL\")");
  if (got < kVolumeHeaderBytes) fail_file_content("truncated: {} bytes, but the header alone takes {}", got, kVolumeHeaderBytes);
  if (header[3] != 3) fail_file_content("version {}; only version 3 is supported", int(header[3]));
  const int32_t encoding = little_endian_i32(header + 4);
  if (encoding != 1) fail_file_content("data encoding {}; only 1 (float32) is supported", encoding);

  VolumeGrid grid;
  uint64_t count = 1;
  for (int axis = 0; axis < 3; ++axis) {
    const int32_t n = little_endian_i32(header + 8 + 4 * axis);
    grid.resolution[size_t(axis)] = n;
    if (n < 1) fail_file_content("the resolution along {} is {}", "xyz"[axis], n);
    // Saturated above the limit: both factors stay below 2^32, so the product cannot overflow.
    count = std::min(count * uint64_t(n), kMaxVolumeGridValues + 1);
  }
  grid.channels = little_endian_i32(header + 20);
  if (grid.channels < 1) fail_file_content("{} channels", grid.channels);
  const auto& n = grid.resolution;
  if (count > kMaxVolumeGridValues || count * uint64_t(grid.channels) > kMaxVolumeGridValues)
    fail_file_content("{} x {} x {} samples of {} channels is more than the {} values supported", n[0], n[1], n[2], grid.channels,
         kMaxVolumeGridValues);
  count *= uint64_t(grid.channels);
  for (size_t i = 0; i < 6; ++i) grid.bounds[i] = little_endian_f32(header + 24 + 4 * i);

  // The size is checked before anything is allocated: a corrupt header must not ask for gigabytes.
  const uintmax_t size = fs::file_size(file, ec);
  const uint64_t needed = count * sizeof(float);
  if (!ec && size - kVolumeHeaderBytes < needed)
    fail_file_content("truncated: {} x {} x {} samples of {} channels need {} bytes of values, but the file has {} after its header",
         n[0], n[1], n[2], grid.channels, needed, size - kVolumeHeaderBytes);
  grid.values.resize(count);
  in.read(reinterpret_cast<char*>(grid.values.data()), std::streamsize(needed));
  if (uint64_t(in.gcount()) != needed)
    fail_file_content("truncated: {} bytes of values expected after the header, {} read", needed, in.gcount());
  if constexpr (std::endian::native == std::endian::big)
    for (float& v : grid.values) v = little_endian_f32(reinterpret_cast<const unsigned char*>(&v));
  return grid;
}

double lerp(double a, double b, double t) {
  // Exact at both ends (a * 0 + b = b), which the face-consistent evaluation relies on.
  return a * (1 - t) + b * t;
}

Vec3d clamp01(const Vec3d& p) {
  return {std::clamp(p.x, 0.0, 1.0), std::clamp(p.y, 0.0, 1.0), std::clamp(p.z, 0.0, 1.0)};
}

size_t sample_count(const std::array<int, 3>& n) { return size_t(n[0]) * size_t(n[1]) * size_t(n[2]); }

// Calls visit(lower corner sample index) for every voxel the surface passes through, in order.
template <typename Visit>
void for_each_surface_voxel(const std::array<int, 3>& n, const std::vector<float>& values, Visit visit) {
  const size_t nx = size_t(n[0]), nxy = size_t(n[0]) * size_t(n[1]);
  const size_t offsets[8] = {0, 1, nx, nx + 1, nxy, nxy + 1, nxy + nx, nxy + nx + 1};
  for (int z = 0; z + 1 < n[2]; ++z)
    for (int y = 0; y + 1 < n[1]; ++y)
      for (int x = 0; x + 1 < n[0]; ++x) {
        const size_t base = size_t(z) * nxy + size_t(y) * nx + size_t(x);
        bool some_non_negative = false, some_non_positive = false;
        for (size_t offset : offsets) {
          const float v = values[base + offset];
          some_non_negative |= v >= 0;
          some_non_positive |= v <= 0;
        }
        if (some_non_negative && some_non_positive) visit(base);
      }
}

}  // namespace

// ---------------------------------------------------------------- files

VolumeGrid read_volume_grid(const fs::path& file, const SourceLocation& referenced_from) {
  try {
    return parse_volume_file(file);
  } catch (const FileContentError& problem) {
    throw_scene_error(referenced_from, "cannot read volume grid '{}': {}", file.string(), problem.what());
  } catch (const std::bad_alloc&) {
    throw_scene_error(referenced_from, "cannot read volume grid '{}': out of memory", file.string());
  }
}

void write_volume_grid(const fs::path& file, const VolumeGrid& grid) {
  std::string bytes = "VOL";
  bytes.push_back(char(3));
  put_u32(bytes, 1);
  for (int n : grid.resolution) put_u32(bytes, uint32_t(n));
  put_u32(bytes, uint32_t(grid.channels));
  for (float b : grid.bounds) put_u32(bytes, std::bit_cast<uint32_t>(b));
  for (float v : grid.values) put_u32(bytes, std::bit_cast<uint32_t>(v));
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  if (!out) throw OutputError("cannot write volume grid '" + file.string() + "'");
}

std::string sdf_grid_problem(const SdfGridShape& grid) {
  const auto& n = grid.resolution;
  if (n[0] < 2 || n[1] < 2 || n[2] < 2)
    return fmt::format("the resolution {} x {} x {} has fewer than 2 samples along an axis (a voxel needs 2)", n[0],
                       n[1], n[2]);
  if (uint64_t(n[0]) * uint64_t(n[1]) * uint64_t(n[2]) > kMaxVolumeGridValues)
    return fmt::format("{} x {} x {} samples is more than the {} supported", n[0], n[1], n[2], kMaxVolumeGridValues);
  const size_t expected = sample_count(n);
  const size_t count = grid.values ? grid.values->size() : 0;
  if (count != expected)
    return fmt::format("{} values for {} x {} x {} samples (expected {})", count, n[0], n[1], n[2], expected);
  const std::vector<float>& values = *grid.values;
  for (size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i])) {
      const size_t x = i % size_t(n[0]), y = i / size_t(n[0]) % size_t(n[1]), z = i / (size_t(n[0]) * size_t(n[1]));
      return fmt::format("the value of sample ({}, {}, {}) is {}; every distance must be finite", x, y, z, values[i]);
    }
  if (count_surface_voxels(grid) == 0)
    return "no voxel holds a surface (no voxel has corners of both signs): the grid is empty";
  return "";
}

SdfGridShape read_sdf_grid_file(const fs::path& file, const SourceLocation& referenced_from, SdfNormals normals) {
  VolumeGrid volume = read_volume_grid(file, referenced_from);
  if (volume.channels != 1)
    throw_scene_error(referenced_from, "cannot read SDF grid '{}': it has {} channels per sample; a distance has 1",
                      file.string(), volume.channels);
  SdfGridShape shape;
  shape.resolution = volume.resolution;
  shape.values = std::make_shared<const std::vector<float>>(std::move(volume.values));
  shape.normals = normals;
  shape.filename = file.string();
  if (std::string problem = sdf_grid_problem(shape); !problem.empty())
    throw_scene_error(referenced_from, "cannot read SDF grid '{}': {}", file.string(), problem);
  return shape;
}

uint64_t count_surface_voxels(const SdfGridShape& grid) {
  if (!grid.values || grid.values->size() != sample_count(grid.resolution)) return 0;
  uint64_t count = 0;
  for_each_surface_voxel(grid.resolution, *grid.values, [&](size_t) { ++count; });
  return count;
}

// ---------------------------------------------------------------- the interpolant in one voxel

double trilinear(const VoxelCorners& f, const Vec3d& p) {
  // Along x first, then y, then z: on any face the result reduces to the same operations on the
  // face's four samples whichever voxel evaluates it.
  const double y0z0 = lerp(f[0], f[1], p.x), y1z0 = lerp(f[2], f[3], p.x);
  const double y0z1 = lerp(f[4], f[5], p.x), y1z1 = lerp(f[6], f[7], p.x);
  return lerp(lerp(y0z0, y1z0, p.y), lerp(y0z1, y1z1, p.y), p.z);
}

Vec3d trilinear_gradient(const VoxelCorners& f, const Vec3d& p) {
  // Each partial derivative is the bilinear interpolant of the differences along the four edges
  // parallel to its axis.
  const double dx = lerp(lerp(f[1] - f[0], f[3] - f[2], p.y), lerp(f[5] - f[4], f[7] - f[6], p.y), p.z);
  const double dy = lerp(lerp(f[2] - f[0], f[3] - f[1], p.x), lerp(f[6] - f[4], f[7] - f[5], p.x), p.z);
  const double dz = lerp(lerp(f[4] - f[0], f[5] - f[1], p.x), lerp(f[6] - f[2], f[7] - f[3], p.x), p.y);
  return {dx, dy, dz};
}

std::array<double, 4> trilinear_along_line(const VoxelCorners& f, const Vec3d& o, const Vec3d& d) {
  // f = a0 + a1 x + a2 y + a3 z + axy xy + axz xz + ayz yz + axyz xyz. The constant and linear terms
  // in s are the value and the directional derivative at o; the others come from the products.
  const double axy = f[3] - f[2] - f[1] + f[0];
  const double axz = f[5] - f[4] - f[1] + f[0];
  const double ayz = f[6] - f[4] - f[2] + f[0];
  const double axyz = f[7] - f[6] - f[5] + f[4] - f[3] + f[2] + f[1] - f[0];
  const double c2 = d.x * d.y * (axy + axyz * o.z) + d.x * d.z * (axz + axyz * o.y) + d.y * d.z * (ayz + axyz * o.x);
  return {trilinear(f, o), dot(trilinear_gradient(f, o), d), c2, axyz * d.x * d.y * d.z};
}

std::optional<double> first_cubic_root(const std::array<double, 4>& c, double s0, double s1, double f0, double f1) {
  const auto eval = [&](double s) { return ((c[3] * s + c[2]) * s + c[1]) * s + c[0]; };
  const auto slope = [&](double s) { return (3 * c[3] * s + 2 * c[2]) * s + c[1]; };

  // The extrema: roots of 3 c3 s^2 + 2 c2 s + c1, in increasing order.
  double extrema[2];
  int extremum_count = 0;
  const double a = 3 * c[3], b = 2 * c[2];
  if (a == 0) {
    if (b != 0) extrema[extremum_count++] = -c[1] / b;
  } else {
    const double discriminant = b * b - 4 * a * c[1];
    if (discriminant >= 0) {
      const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
      double r0 = q / a, r1 = q != 0 ? c[1] / q : r0;
      if (r0 > r1) std::swap(r0, r1);
      extrema[extremum_count++] = r0;
      extrema[extremum_count++] = r1;
    }
  }

  // Between consecutive extrema the cubic is monotonic: keep the first piece that reaches zero.
  double lo = s0, hi = s1, f_lo = f0, f_hi = f1;
  for (int i = 0; i < extremum_count; ++i) {
    const double s = extrema[i];
    if (!(s > lo && s < hi)) continue;
    const double f = eval(s);
    if (f_lo * f <= 0) {
      hi = s;
      f_hi = f;
      break;
    }
    lo = s;
    f_lo = f;
  }
  if (!(f_lo * f_hi <= 0)) return std::nullopt;  // no sign change (or NaN)
  if (f_lo == 0) return lo;
  if (f_hi == 0) return hi;

  // Newton from the secant estimate; a step that leaves the bracket is replaced by bisection. The
  // bracket keeps f_lo's sign at its lower end.
  double s = lo + (hi - lo) * (f_lo / (f_lo - f_hi));
  if (!(s >= lo && s <= hi)) s = 0.5 * (lo + hi);
  const double tolerance = 1e-12 * std::max(std::abs(s0), std::abs(s1)) + 1e-300;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double f = eval(s);
    if (f == 0) return s;
    if ((f < 0) == (f_lo < 0)) lo = s;
    else hi = s;
    double next = s - f / slope(s);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - s) <= tolerance) return next;
    s = next;
  }
  return s;
}

// ---------------------------------------------------------------- the grid

SdfGrid::SdfGrid(const SdfGridShape& shape) : n_(shape.resolution), values_(shape.values) {
  for_each_surface_voxel(n_, *values_, [&](size_t base) { voxels_.push_back(uint32_t(base)); });
}

std::array<int, 3> SdfGrid::voxel_corner(uint32_t voxel) const {
  const uint32_t base = voxels_[voxel], nx = uint32_t(n_[0]), ny = uint32_t(n_[1]);
  return {int(base % nx), int(base / nx % ny), int(base / (nx * ny))};
}

Transform SdfGrid::index_to_object() const {
  Matrix4 m = Matrix4::identity(), inverse = Matrix4::identity();
  for (int axis = 0; axis < 3; ++axis) {
    m.m[axis][axis] = 1.0 / (n_[size_t(axis)] - 1);
    inverse.m[axis][axis] = n_[size_t(axis)] - 1;
  }
  return Transform(m, inverse);
}

double SdfGrid::sample(int x, int y, int z) const {
  x = std::clamp(x, 0, n_[0] - 1);
  y = std::clamp(y, 0, n_[1] - 1);
  z = std::clamp(z, 0, n_[2] - 1);
  return (*values_)[(size_t(z) * size_t(n_[1]) + size_t(y)) * size_t(n_[0]) + size_t(x)];
}

VoxelCorners SdfGrid::corners(const std::array<int, 3>& c) const {
  VoxelCorners f;
  for (int i = 0; i < 8; ++i) f[size_t(i)] = sample(c[0] + (i & 1), c[1] + (i >> 1 & 1), c[2] + (i >> 2));
  return f;
}

std::optional<double> SdfGrid::intersect_voxel(uint32_t voxel, const Vec3d& o, const Vec3d& d, double t_near,
                                               double t_far) const {
  const std::array<int, 3> corner = voxel_corner(voxel);
  // The slabs. Face distances are computed from the face's own sample index, the same operations
  // for the two voxels sharing it, so both see the line cross it at the same t.
  double t_enter[3], t_leave[3];
  double t_begin = t_near, t_end = t_far;
  for (int a = 0; a < 3; ++a) {
    const double lower = corner[size_t(a)], upper = lower + 1;
    if (d[a] == 0) {
      if (!(o[a] >= lower && o[a] <= upper)) return std::nullopt;
      t_enter[a] = -std::numeric_limits<double>::infinity();
      t_leave[a] = std::numeric_limits<double>::infinity();
      continue;
    }
    const double t_lower = (lower - o[a]) / d[a], t_upper = (upper - o[a]) / d[a];
    t_enter[a] = d[a] > 0 ? t_lower : t_upper;
    t_leave[a] = d[a] > 0 ? t_upper : t_lower;
    t_begin = std::max(t_begin, t_enter[a]);
    t_end = std::min(t_end, t_leave[a]);
  }
  if (!(t_begin < t_end)) return std::nullopt;

  // Local points where the line enters and leaves, snapped onto the faces it crosses there (where
  // the interpolant is exact and shared with the neighbour); a start inside the voxel (at t_near)
  // is on no face.
  Vec3d begin, end;
  for (int a = 0; a < 3; ++a) {
    begin[a] = o[a] + t_begin * d[a] - corner[size_t(a)];
    end[a] = o[a] + t_end * d[a] - corner[size_t(a)];
    if (t_enter[a] == t_begin) begin[a] = d[a] > 0 ? 0 : 1;
    if (t_leave[a] == t_end) end[a] = d[a] > 0 ? 1 : 0;
  }
  begin = clamp01(begin);
  end = clamp01(end);
  const VoxelCorners f = corners(corner);
  const std::optional<double> s =
      first_cubic_root(trilinear_along_line(f, begin, d), 0, t_end - t_begin, trilinear(f, begin), trilinear(f, end));
  if (!s) return std::nullopt;
  const double t = t_begin + *s;
  if (!(t > t_near && t < t_far)) return std::nullopt;
  return t;
}

Vec3d SdfGrid::project_to_surface(uint32_t voxel, const Vec3d& p) const {
  const std::array<int, 3> corner = voxel_corner(voxel);
  const Vec3d origin{double(corner[0]), double(corner[1]), double(corner[2])};
  const VoxelCorners f = corners(corner);
  Vec3d local = clamp01(p - origin);
  const Vec3d g = trilinear_gradient(f, local);
  const double g2 = dot(g, g);
  if (g2 > 0) local = clamp01(local - g * (trilinear(f, local) / g2));
  return origin + local;
}

Vec3d SdfGrid::gradient(uint32_t voxel, const Vec3d& p) const {
  const std::array<int, 3> corner = voxel_corner(voxel);
  const Vec3d origin{double(corner[0]), double(corner[1]), double(corner[2])};
  const Vec3d g = trilinear_gradient(corners(corner), clamp01(p - origin));
  return {g.x * (n_[0] - 1), g.y * (n_[1] - 1), g.z * (n_[2] - 1)};
}

double SdfGrid::plane(int axis, int index, const std::array<int, 3>& cell, const Vec3d& w) const {
  const int b = (axis + 1) % 3, c = (axis + 2) % 3;
  double s[4];
  for (int i = 0; i < 4; ++i) {
    std::array<int, 3> at{};
    at[size_t(axis)] = index;
    at[size_t(b)] = cell[size_t(b)] + (i & 1);
    at[size_t(c)] = cell[size_t(c)] + (i >> 1);
    s[i] = sample(at[0], at[1], at[2]);
  }
  return lerp(lerp(s[0], s[1], w[b]), lerp(s[2], s[3], w[b]), w[c]);
}

Vec3d SdfGrid::smooth_normal(const Vec3d& p) const {
  // The eight voxels around the sample nearest to p have lower corners `first` and first + 1 per
  // axis; `blend` is p's position relative to their centres. `cell` is the voxel holding p.
  std::array<int, 3> first{}, cell{};
  Vec3d blend, w;
  for (int a = 0; a < 3; ++a) {
    const int n = n_[size_t(a)];
    first[size_t(a)] = int(std::floor(p[a] + 0.5)) - 1;
    blend[a] = p[a] - first[size_t(a)] - 0.5;
    cell[size_t(a)] = std::clamp(int(std::floor(p[a])), 0, n - 2);
    w[a] = p[a] - cell[size_t(a)];
  }
  // Per axis, the gradient component of the lower and the upper of the two voxel layers: the
  // difference across p's own cell, and the one across the neighbouring cell on the other voxel's
  // side (zero past the grid's edge, where the samples are clamped).
  Vec3d lower_layer, upper_layer;
  for (int a = 0; a < 3; ++a) {
    const int k = cell[size_t(a)];
    const bool p_in_upper = k != first[size_t(a)];
    const double g0 = plane(a, k, cell, w), g1 = plane(a, k + 1, cell, w);
    const double across_cell = g1 - g0;
    const double across_neighbour = p_in_upper ? g0 - plane(a, k - 1, cell, w) : plane(a, k + 2, cell, w) - g1;
    const double scale = n_[size_t(a)] - 1;  // to object space
    lower_layer[a] = (p_in_upper ? across_neighbour : across_cell) * scale;
    upper_layer[a] = (p_in_upper ? across_cell : across_neighbour) * scale;
  }
  // Voxels before the grid's start get no weight: the blend puts all of it on the upper layer.
  bool exists[3];
  for (int a = 0; a < 3; ++a) {
    exists[a] = first[size_t(a)] >= 0;
    if (!exists[a]) blend[a] = 1;
  }
  Vec3d normals[8];
  for (int i = 0; i < 8; ++i) {
    Vec3d g;
    bool valid = true;
    for (int a = 0; a < 3; ++a) {
      const bool upper = (i >> a & 1) != 0;
      g[a] = upper ? upper_layer[a] : lower_layer[a];
      valid = valid && (upper || exists[a]);
    }
    const double length = std::sqrt(dot(g, g));
    normals[i] = valid && length > 0 ? g * (1 / length) : Vec3d{};
  }
  const auto mix = [](const Vec3d& a, const Vec3d& b, double t) { return a * (1 - t) + b * t; };
  return mix(mix(mix(normals[0], normals[1], blend.x), mix(normals[2], normals[3], blend.x), blend.y),
             mix(mix(normals[4], normals[5], blend.x), mix(normals[6], normals[7], blend.x), blend.y), blend.z);
}

}  // namespace candela
