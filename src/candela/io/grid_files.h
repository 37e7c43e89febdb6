#pragma once
// Volume grids from files, as media read them: Mitsuba's .vol, OpenVDB's .vdb (what Blender and
// Houdini write) and NanoVDB's .nvdb (what pbrt-v4's "nanovdb" medium reads). Sparse grids become
// dense ones over the bounding box of their active voxels; a VolumeDesc's samples sit at voxel
// centres, as VDB's do, so the grid's unit cube spans that box grown by half a voxel on every side,
// and beyond the active voxels the value fades to the background (VolumeBorder::Zero; backgrounds
// other than 0 are refused).
#include <filesystem>
#include <string>
#include <vector>

#include "candela/base/error.h"
#include "candela/description/scene_desc.h"

namespace candela {

// More dense samples than this are refused (4 GiB of floats): a sparse grid so large would need a
// sparse representation, which candela does not have yet.
inline constexpr uint64_t kMaxDenseGridSamples = uint64_t(1) << 30;

// The grid `grid_name` of `file` (.vdb or .nvdb: a float grid; .vol: the whole file, `grid_name`
// ignored), with to_world mapping its unit cube to the file's world space (.vol: the identity, as
// Mitsuba places it). Throws SceneError "<referenced_from>: cannot read volume grid 'FILE': <why>"
// for a missing or malformed file, a missing grid (naming the grids there are), a grid that is not
// of floats, a non-zero background, or more than `max_dense_samples` samples (a sparse grid's few
// bytes can span that many: the fuzz target asks for fewer than libFuzzer's memory limit holds).
VolumeDesc read_grid_file(const std::filesystem::path& file, const std::string& grid_name,
                          const SourceLocation& referenced_from, uint64_t max_dense_samples = kMaxDenseGridSamples);

// The names of the grids in a .vdb or .nvdb file (empty for .vol), for messages and warnings.
std::vector<std::string> grid_names_in_file(const std::filesystem::path& file, const SourceLocation& referenced_from);

// Writes `values` (nx ny nz floats, x fastest) as a float grid named `grid_name` in an OpenVDB
// (.vdb) or NanoVDB (.nvdb) file, voxel (i, j, k) at index (i, j, k) + offset, with a uniform voxel
// size; zeros are left inactive. For tests, examples and benchmarks that make their own clouds.
void write_grid_file(const std::filesystem::path& file, const std::string& grid_name, const std::array<int, 3>& resolution,
                     const std::vector<float>& values, float voxel_size, const std::array<int, 3>& offset = {0, 0, 0});
// The same with several grids of the same placement in one file ("density" and "temperature").
struct NamedGridValues {
  std::string name;
  std::vector<float> values;
};
void write_grid_file(const std::filesystem::path& file, const std::vector<NamedGridValues>& grids,
                     const std::array<int, 3>& resolution, float voxel_size, const std::array<int, 3>& offset = {0, 0, 0});

}  // namespace candela
