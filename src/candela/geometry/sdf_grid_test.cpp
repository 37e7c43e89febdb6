// The SDF grid's pieces on their own: Mitsuba's .vol files (a round trip, and every way a file can be
// wrong), the trilinear interpolant and the cubic it becomes along a line, the cubic's first root,
// and the smooth normal's continuity. Rays through the whole Scene are in scene/sdf_grid_shape_test.cpp.
#include "candela/geometry/sdf_grid.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "candela/sampling/rng.h"

namespace candela {
namespace {

namespace fs = std::filesystem;

// One folder per test process (ctest runs tests in parallel processes).
fs::path temp_file(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("candela_sdf_grid_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

const SourceLocation kWhere{"scene.xml", 7, 3, {}};

// The message of the SceneError that reading `file` as an SDF grid throws ("" when none).
std::string sdf_error(const fs::path& file) {
  try {
    read_sdf_grid_file(file, kWhere, SdfNormals::Smooth);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// A .vol file of the given bytes.
fs::path raw_file(const std::string& name, const std::string& bytes) {
  fs::path file = temp_file(name);
  std::ofstream(file, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  return file;
}

// A one-channel grid whose values are x + y + z - 1.5 over [0,1]^3: a plane through its middle.
VolumeGrid small_sdf(int nx, int ny, int nz) {
  VolumeGrid grid;
  grid.resolution = {nx, ny, nz};
  const auto coordinate = [](int i, int n) { return n > 1 ? float(i) / float(n - 1) : 0.0f; };
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        grid.values.push_back(coordinate(x, nx) + coordinate(y, ny) + coordinate(z, nz) - 1.5f);
  return grid;
}

std::string as_bytes(const VolumeGrid& grid) {
  fs::path file = temp_file("bytes.vol");
  write_volume_grid(file, grid);
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void put_i32(std::string& bytes, size_t at, int32_t value) {
  for (int i = 0; i < 4; ++i) bytes[at + size_t(i)] = char((uint32_t(value) >> (8 * i)) & 0xff);
}

TEST(VolumeGridFile, RoundTripsResolutionChannelsBoundsAndValues) {
  VolumeGrid grid;
  grid.resolution = {3, 4, 5};
  grid.channels = 2;
  grid.bounds = {-1, -2, -3, 4, 5, 6};
  Rng rng(1, 2);
  for (int i = 0; i < 3 * 4 * 5 * 2; ++i) grid.values.push_back(rng.next_float() * 20 - 10);
  const fs::path file = temp_file("round_trip.vol");
  write_volume_grid(file, grid);
  EXPECT_EQ(fs::file_size(file), 48 + grid.values.size() * 4);
  VolumeGrid back = read_volume_grid(file, kWhere);
  EXPECT_EQ(back.resolution, grid.resolution);
  EXPECT_EQ(back.channels, 2);
  EXPECT_EQ(back.bounds, grid.bounds);
  EXPECT_EQ(back.values, grid.values);
}

TEST(VolumeGridFile, ReadsMitsubasTorus) {
  const fs::path torus =
      fs::path(CANDELA_SHARED_DIR) / "scenes/mitsuba-tests/docs/scenes/sdfgrid/torus_sdfgrid.vol";
  if (!fs::exists(torus)) GTEST_SKIP() << "no shared Mitsuba data";
  SdfGridShape shape = read_sdf_grid_file(torus, kWhere, SdfNormals::Analytic);
  EXPECT_EQ(shape.resolution, (std::array<int, 3>{40, 40, 40}));
  EXPECT_EQ(shape.values->size(), 40u * 40 * 40);
  EXPECT_EQ(shape.normals, SdfNormals::Analytic);
  EXPECT_EQ(shape.filename, torus.string());
  EXPECT_GT(count_surface_voxels(shape), 1000u);
}

TEST(VolumeGridFile, EveryProblemIsASceneErrorNamingTheFile) {
  const std::string good = as_bytes(small_sdf(4, 4, 4));
  // Each case: a file, and words its message must contain.
  struct Case {
    std::string name, bytes, expect;
  };
  std::vector<Case> cases;
  cases.push_back({"empty.vol", "", "truncated"});
  cases.push_back({"short_header.vol", good.substr(0, 30), "truncated"});
  cases.push_back({"short_values.vol", good.substr(0, good.size() - 5), "truncated"});
  std::string magic = good;
  magic[0] = 'X';
  cases.push_back({"magic.vol", magic, "VOL"});
  std::string version = good;
  version[3] = 2;
  cases.push_back({"version.vol", version, "version 2"});
  std::string encoding = good;
  put_i32(encoding, 4, 2);
  cases.push_back({"encoding.vol", encoding, "encoding 2"});
  std::string zero_axis = good;
  put_i32(zero_axis, 12, 0);
  cases.push_back({"zero_axis.vol", zero_axis, "resolution along y is 0"});
  std::string huge = good;
  for (size_t at : {8, 12, 16}) put_i32(huge, at, 100000);
  cases.push_back({"huge.vol", huge, "more than"});
  std::string lying = good;  // more samples than the file holds: refused before allocating them
  put_i32(lying, 16, 1000);
  cases.push_back({"lying.vol", lying, "truncated"});
  std::string channels = as_bytes([] {
    VolumeGrid g = small_sdf(2, 2, 2);
    g.channels = 3;
    g.values.resize(24, 0.5f);
    return g;
  }());
  cases.push_back({"channels.vol", channels, "3 channels"});
  cases.push_back({"flat.vol", as_bytes(small_sdf(4, 1, 4)), "fewer than 2 samples"});
  VolumeGrid nan_grid = small_sdf(3, 3, 3);
  nan_grid.values[13] = std::numeric_limits<float>::quiet_NaN();
  cases.push_back({"nan.vol", as_bytes(nan_grid), "sample (1, 1, 1) is nan"});
  VolumeGrid inf_grid = small_sdf(3, 3, 3);
  inf_grid.values[2] = std::numeric_limits<float>::infinity();
  cases.push_back({"inf.vol", as_bytes(inf_grid), "must be finite"});
  VolumeGrid outside = small_sdf(3, 3, 3);
  for (float& v : outside.values) v = std::abs(v) + 0.1f;
  cases.push_back({"no_surface.vol", as_bytes(outside), "no voxel holds a surface"});

  for (const Case& c : cases) {
    const fs::path file = raw_file(c.name, c.bytes);
    const std::string error = sdf_error(file);
    EXPECT_NE(error.find("scene.xml:7:3"), std::string::npos) << c.name << ": " << error;
    EXPECT_NE(error.find(file.string()), std::string::npos) << c.name << ": " << error;
    EXPECT_NE(error.find(c.expect), std::string::npos) << c.name << ": " << error;
  }
  const std::string missing = sdf_error(temp_file("does_not_exist.vol"));
  EXPECT_NE(missing.find("no such file"), std::string::npos) << missing;
  const std::string directory = sdf_error(fs::temp_directory_path());
  EXPECT_NE(directory.find("directory"), std::string::npos) << directory;
  // The good file itself reads.
  EXPECT_EQ(sdf_error(raw_file("good.vol", good)), "");
}

TEST(SdfGridProblem, NamesInMemoryGridsThatCannotBeRendered) {
  SdfGridShape grid;
  grid.resolution = {2, 2, 2};
  EXPECT_NE(sdf_grid_problem(grid).find("0 values"), std::string::npos);
  grid.values = std::make_shared<const std::vector<float>>(std::vector<float>{-1, 1, -1, 1, -1, 1, -1, 1});
  EXPECT_EQ(sdf_grid_problem(grid), "");
  grid.resolution = {2, 4, 1};
  EXPECT_NE(sdf_grid_problem(grid).find("fewer than 2"), std::string::npos);
}

// ---------------------------------------------------------------- the interpolant

VoxelCorners random_corners(Rng& rng) {
  VoxelCorners f;
  for (double& v : f) v = 2 * rng.next_float() - 1;
  return f;
}

TEST(SdfTrilinear, ReproducesCornersAndGivesBothVoxelsTheSameValueOnTheirFace) {
  Rng rng(3, 4);
  for (int trial = 0; trial < 200; ++trial) {
    const VoxelCorners f = random_corners(rng);
    for (int i = 0; i < 8; ++i)
      EXPECT_EQ(trilinear(f, {double(i & 1), double(i >> 1 & 1), double(i >> 2)}), f[size_t(i)]);
    // The voxel above along each axis shares the face: its lower corners are this one's upper ones.
    for (int axis = 0; axis < 3; ++axis) {
      VoxelCorners above = random_corners(rng);
      const int bit = 1 << axis;
      for (int i = 0; i < 8; ++i)
        if (!(i & bit)) above[size_t(i)] = f[size_t(i | bit)];
      Vec3d p{rng.next_float(), rng.next_float(), rng.next_float()}, q = p;
      p[axis] = 1;
      q[axis] = 0;
      EXPECT_EQ(trilinear(f, p), trilinear(above, q)) << "axis " << axis;
    }
  }
}

TEST(SdfTrilinear, TheCubicAlongALineAndTheGradientAgreeWithTheInterpolant) {
  Rng rng(5, 6);
  for (int trial = 0; trial < 500; ++trial) {
    const VoxelCorners f = random_corners(rng);
    const Vec3d o{rng.next_float(), rng.next_float(), rng.next_float()};
    const Vec3d d{2 * rng.next_float() - 1, 2 * rng.next_float() - 1, 2 * rng.next_float() - 1};
    const std::array<double, 4> c = trilinear_along_line(f, o, d);
    for (double s : {0.0, 0.3, -0.7, 1.4}) {
      const double cubic = ((c[3] * s + c[2]) * s + c[1]) * s + c[0];
      EXPECT_NEAR(cubic, trilinear(f, o + d * s), 1e-12) << trial;
    }
    // Central differences of the interpolant (exact for its linear dependence on each coordinate).
    const Vec3d g = trilinear_gradient(f, o);
    for (int a = 0; a < 3; ++a) {
      Vec3d lo = o, hi = o;
      lo[a] -= 1e-3;
      hi[a] += 1e-3;
      EXPECT_NEAR(g[a], (trilinear(f, hi) - trilinear(f, lo)) / 2e-3, 1e-9) << trial << " axis " << a;
    }
  }
}

// ---------------------------------------------------------------- the root finder

std::array<double, 4> cubic_with_roots(double a, double b, double c, double scale = 1) {
  // scale (s - a)(s - b)(s - c)
  return {-scale * a * b * c, scale * (a * b + a * c + b * c), -scale * (a + b + c), scale};
}

double eval(const std::array<double, 4>& c, double s) { return ((c[3] * s + c[2]) * s + c[1]) * s + c[0]; }

std::optional<double> root_in(const std::array<double, 4>& c, double s0, double s1) {
  return first_cubic_root(c, s0, s1, eval(c, s0), eval(c, s1));
}

TEST(SdfCubicRoot, FindsTheFirstOfThreeKnownRoots) {
  const auto c = cubic_with_roots(0.2, 0.5, 0.9, -3);
  EXPECT_NEAR(*root_in(c, 0, 1), 0.2, 1e-12);      // three roots inside: the first
  EXPECT_NEAR(*root_in(c, 0.3, 1), 0.5, 1e-12);    // two inside, same signs at the ends
  EXPECT_NEAR(*root_in(c, 0.6, 1), 0.9, 1e-12);
  EXPECT_NEAR(*root_in(c, 0.35, 0.6), 0.5, 1e-12);
  EXPECT_FALSE(root_in(c, 0.55, 0.85));  // between roots: no zero
  // A zero given at the start (as a voxel face's value) is the root, exactly.
  EXPECT_EQ(*first_cubic_root(c, 0.2, 0.4, 0.0, eval(c, 0.4)), 0.2);
}

TEST(SdfCubicRoot, TouchingZeroDegenerateCubicsAndNoRoot) {
  // (s - 0.5)^2 (s + 1): touches zero at 0.5 without changing sign.
  EXPECT_NEAR(*root_in(cubic_with_roots(0.5, 0.5, -1), 0, 1), 0.5, 1e-7);
  EXPECT_FALSE(root_in({1, 0, 0, 1}, 0, 1));            // s^3 + 1
  EXPECT_NEAR(*root_in({-0.3, 0, 1, 0}, 0, 1), std::sqrt(0.3), 1e-12);  // a quadratic
  EXPECT_NEAR(*root_in({0.25, -1, 0, 0}, 0, 1), 0.25, 1e-12);           // a line
  EXPECT_FALSE(root_in({0.25, 0, 0, 0}, 0, 1));                         // a constant
  EXPECT_EQ(*root_in({0, 0, 0, 0}, 0, 1), 0);                           // zero everywhere: at once
}

TEST(SdfCubicRoot, RandomCubicsWithKnownRootsToNearDoublePrecision) {
  Rng rng(7, 8);
  for (int trial = 0; trial < 5000; ++trial) {
    double r[3] = {3 * rng.next_float() - 1, 3 * rng.next_float() - 1, 3 * rng.next_float() - 1};
    std::sort(r, r + 3);
    const double scale = (rng.next_float() < 0.5 ? -1 : 1) * (0.01 + 100 * rng.next_float());
    const auto c = cubic_with_roots(r[0], r[1], r[2], scale);
    const double s0 = 2 * rng.next_float() - 0.5, s1 = s0 + 0.05 + rng.next_float();
    double expected = std::numeric_limits<double>::quiet_NaN();
    for (double root : r)
      if (root >= s0 && root <= s1) {
        expected = root;
        break;
      }
    std::optional<double> found = root_in(c, s0, s1);
    // Roots closer together than this are a double root to the iteration: either may be found.
    const bool close = std::abs(r[1] - r[0]) < 1e-4 || std::abs(r[2] - r[1]) < 1e-4;
    if (close) continue;
    if (std::isnan(expected)) {
      EXPECT_FALSE(found) << trial;
    } else {
      ASSERT_TRUE(found) << trial;
      EXPECT_NEAR(*found, expected, 1e-9 * (1 + std::abs(expected))) << trial;
    }
  }
}

// ---------------------------------------------------------------- the grid

// A sphere's signed distance on an n^3 grid over [0,1]^3.
SdfGridShape sphere_grid(int n, double radius) {
  std::vector<float> values;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double dx = double(x) / (n - 1) - 0.5, dy = double(y) / (n - 1) - 0.5, dz = double(z) / (n - 1) - 0.5;
        values.push_back(float(std::sqrt(dx * dx + dy * dy + dz * dz) - radius));
      }
  SdfGridShape shape;
  shape.resolution = {n, n, n};
  shape.values = std::make_shared<const std::vector<float>>(std::move(values));
  return shape;
}

TEST(SdfGrid, SurfaceVoxelsAreThoseWithCornersOfBothSigns) {
  SdfGridShape shape;
  shape.resolution = {3, 2, 2};
  // Only the voxel at x = 0 has a negative corner; a zero corner makes the other one hold surface too.
  shape.values = std::make_shared<const std::vector<float>>(std::vector<float>{-1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1});
  EXPECT_EQ(SdfGrid(shape).voxel_count(), 1u);
  shape.values = std::make_shared<const std::vector<float>>(std::vector<float>{-1, 1, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1});
  SdfGrid grid(shape);
  ASSERT_EQ(grid.voxel_count(), 2u);
  EXPECT_EQ(grid.voxel_corner(1), (std::array<int, 3>{1, 0, 0}));
}

// The corners of voxel c of an n^3 grid.
VoxelCorners voxel_corners(const SdfGridShape& shape, int n, const std::array<int, 3>& c) {
  VoxelCorners f;
  for (int i = 0; i < 8; ++i) {
    const int x = c[0] + (i & 1), y = c[1] + (i >> 1 & 1), z = c[2] + (i >> 2);
    f[size_t(i)] = (*shape.values)[size_t((z * n + y) * n + x)];
  }
  return f;
}

TEST(SdfGrid, SmoothNormalsAreContinuousAcrossVoxelFacesWhereAnalyticOnesAreNot) {
  const int n = 17;
  const SdfGridShape shape = sphere_grid(n, 0.3);
  const SdfGrid grid(shape);
  Rng rng(9, 10);
  double largest_smooth_jump = 0, largest_analytic_jump = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    // A point on a sample plane across a random axis (a voxel face), or on a plane halfway between
    // two (where the eight blended voxels change), and its neighbours a hair to either side.
    const int axis = int(rng.next_u32() % 3);
    Vec3d p{1 + (n - 3) * double(rng.next_float()), 1 + (n - 3) * double(rng.next_float()),
            1 + (n - 3) * double(rng.next_float())};
    const bool on_face = trial % 2 == 0;
    p[axis] = std::floor(p[axis]) + (on_face ? 0 : 0.5);
    Vec3d below = p, above = p;
    below[axis] -= 1e-9;
    above[axis] += 1e-9;
    const Vec3d step = grid.smooth_normal(below) - grid.smooth_normal(above);
    largest_smooth_jump = std::max(largest_smooth_jump, std::sqrt(dot(step, step)));
    if (on_face) {
      // The gradients of the two voxels' interpolants on their shared face.
      std::array<int, 3> upper{int(p.x), int(p.y), int(p.z)}, lower = upper;
      lower[size_t(axis)] -= 1;
      Vec3d local{p.x - upper[0], p.y - upper[1], p.z - upper[2]}, local_lower = local;
      local_lower[axis] = 1;
      const Vec3d jump = trilinear_gradient(voxel_corners(shape, n, lower), local_lower) -
                         trilinear_gradient(voxel_corners(shape, n, upper), local);
      largest_analytic_jump = std::max(largest_analytic_jump, std::sqrt(dot(jump, jump)) * (n - 1));
    }
  }
  EXPECT_LT(largest_smooth_jump, 1e-6);
  EXPECT_GT(largest_analytic_jump, 1e-2);  // the trilinear gradient's normal component jumps at faces
}

}  // namespace
}  // namespace candela
