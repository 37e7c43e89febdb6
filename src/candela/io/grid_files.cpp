#include "candela/io/grid_files.h"

#include <fmt/format.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <mutex>

#include "candela/geometry/sdf_grid.h"

namespace candela {

namespace fs = std::filesystem;

namespace {

void initialize_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

std::string lower_extension(const fs::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

[[noreturn]] void fail(const SourceLocation& where, const fs::path& file, const std::string& why) {
  throw_scene_error(where, "cannot read volume grid '{}': {}", file.string(), why);
}

std::string joined(const std::vector<std::string>& names) {
  if (names.empty()) return "none";
  return fmt::format("\"{}\"", fmt::join(names, "\", \""));
}

// The dense grid over the index box [lo, hi] of `value_at`, placed by `index_to_world` (an affine map
// from VDB index space, voxel centres at integer coordinates).
template <typename ValueAt, typename IndexToWorld>
VolumeDesc densify(const std::array<int, 3>& lo, const std::array<int, 3>& hi, ValueAt value_at,
                   IndexToWorld index_to_world, const fs::path& file, const SourceLocation& where) {
  VolumeDesc v;
  uint64_t count = 1;
  for (int a = 0; a < 3; ++a) {
    v.resolution[a] = hi[a] - lo[a] + 1;
    count *= uint64_t(v.resolution[a]);
  }
  if (count > kMaxDenseGridSamples)
    fail(where, file, fmt::format("its active voxels span {} x {} x {} = {} samples, more than the {} candela holds "
                                  "densely", v.resolution[0], v.resolution[1], v.resolution[2], count,
                                  kMaxDenseGridSamples));
  std::vector<float> values(count);
  size_t k = 0;
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x) values[k++] = value_at(x, y, z);
  v.values = std::make_shared<const std::vector<float>>(std::move(values));
  v.channels = 1;
  v.border = VolumeBorder::Zero;
  v.filename = file.string();
  // The unit cube spans [lo - 1/2, hi + 1/2] in index space; the file's transform takes it on.
  const Point3 o = index_to_world(Point3(float(lo[0]) - 0.5f, float(lo[1]) - 0.5f, float(lo[2]) - 0.5f));
  Vec3 axes[3];
  for (int a = 0; a < 3; ++a) {
    Point3 corner(float(lo[0]) - 0.5f, float(lo[1]) - 0.5f, float(lo[2]) - 0.5f);
    corner[a] += float(v.resolution[a]);
    axes[a] = index_to_world(corner) - o;
  }
  Matrix4 m = Matrix4::identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.m[r][c] = axes[c][r];
    m.m[r][3] = o[r];
  }
  std::optional<Transform> t = Transform::from_matrix(m);
  if (!t) fail(where, file, "its transform is singular");
  v.to_world = *t;
  v.file_to_world = *t;
  return v;
}

VolumeDesc read_openvdb(const fs::path& file, const std::string& name, const SourceLocation& where) {
  initialize_openvdb();
  openvdb::GridBase::Ptr base;
  std::vector<std::string> names;
  try {
    openvdb::io::File in(file.string());
    in.open();
    for (auto it = in.beginName(); it != in.endName(); ++it) names.push_back(it.gridName());
    if (std::find(names.begin(), names.end(), name) != names.end()) base = in.readGrid(name);
    in.close();
  } catch (const std::exception& e) {
    fail(where, file, e.what());
  }
  if (!base) fail(where, file, fmt::format("it has no grid \"{}\" (its grids: {})", name, joined(names)));
  auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  if (!grid) fail(where, file, fmt::format("grid \"{}\" holds {}, not floats", name, base->valueType()));
  if (grid->background() != 0.0f)
    fail(where, file, fmt::format("grid \"{}\" has the background value {}; only 0 (nothing outside the active "
                                  "voxels) is supported", name, grid->background()));
  if (!grid->transform().isLinear()) fail(where, file, fmt::format("grid \"{}\" has a non-linear (frustum) transform", name));
  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  if (box.empty()) fail(where, file, fmt::format("grid \"{}\" has no active voxels", name));
  auto accessor = grid->getConstAccessor();
  const openvdb::math::Transform& xform = grid->transform();
  VolumeDesc v = densify({box.min().x(), box.min().y(), box.min().z()}, {box.max().x(), box.max().y(), box.max().z()},
                 [&](int x, int y, int z) { return accessor.getValue(openvdb::Coord(x, y, z)); },
                 [&](const Point3& p) {
                   openvdb::Vec3d w = xform.indexToWorld(openvdb::Vec3d(p.x, p.y, p.z));
                   return Point3(float(w.x()), float(w.y()), float(w.z()));
                 },
                 file, where);
  v.grid_name = name;
  return v;
}

VolumeDesc read_nanovdb(const fs::path& file, const std::string& name, const SourceLocation& where) {
  nanovdb::GridHandle<nanovdb::HostBuffer> handle;
  std::vector<std::string> names;
  try {
    for (const auto& meta : nanovdb::io::readGridMetaData(file.string())) names.push_back(meta.gridName);
    if (std::find(names.begin(), names.end(), name) != names.end()) handle = nanovdb::io::readGrid(file.string(), name);
  } catch (const std::exception& e) {
    fail(where, file, e.what());
  }
  if (!handle) fail(where, file, fmt::format("it has no grid \"{}\" (its grids: {})", name, joined(names)));
  const nanovdb::NanoGrid<float>* grid = handle.grid<float>();
  if (!grid) fail(where, file, fmt::format("grid \"{}\" does not hold floats", name));
  if (grid->tree().background() != 0.0f)
    fail(where, file, fmt::format("grid \"{}\" has the background value {}; only 0 is supported", name,
                                  grid->tree().background()));
  const nanovdb::CoordBBox box = grid->indexBBox();
  if (box.empty()) fail(where, file, fmt::format("grid \"{}\" has no active voxels", name));
  auto accessor = grid->getAccessor();
  VolumeDesc v = densify({box.min()[0], box.min()[1], box.min()[2]}, {box.max()[0], box.max()[1], box.max()[2]},
                 [&](int x, int y, int z) { return accessor.getValue(nanovdb::Coord(x, y, z)); },
                 [&](const Point3& p) {
                   nanovdb::Vec3d w = grid->indexToWorld(nanovdb::Vec3d(p.x, p.y, p.z));
                   return Point3(float(w[0]), float(w[1]), float(w[2]));
                 },
                 file, where);
  v.grid_name = name;
  return v;
}

}  // namespace

VolumeDesc read_grid_file(const fs::path& file, const std::string& grid_name, const SourceLocation& referenced_from) {
  const std::string ext = lower_extension(file);
  if (ext == ".vdb") return read_openvdb(file, grid_name, referenced_from);
  if (ext == ".nvdb") return read_nanovdb(file, grid_name, referenced_from);
  VolumeGrid grid = read_volume_grid(file, referenced_from);
  VolumeDesc v;
  v.resolution = grid.resolution;
  v.channels = grid.channels;
  v.values = std::make_shared<const std::vector<float>>(std::move(grid.values));
  v.filename = file.string();
  return v;
}

std::vector<std::string> grid_names_in_file(const fs::path& file, const SourceLocation& referenced_from) {
  std::vector<std::string> names;
  const std::string ext = lower_extension(file);
  try {
    if (ext == ".vdb") {
      initialize_openvdb();
      openvdb::io::File in(file.string());
      in.open();
      for (auto it = in.beginName(); it != in.endName(); ++it) names.push_back(it.gridName());
    } else if (ext == ".nvdb") {
      for (const auto& meta : nanovdb::io::readGridMetaData(file.string())) names.push_back(meta.gridName);
    }
  } catch (const std::exception& e) {
    fail(referenced_from, file, e.what());
  }
  return names;
}

void write_grid_file(const fs::path& file, const std::vector<NamedGridValues>& grids, const std::array<int, 3>& resolution,
                     float voxel_size, const std::array<int, 3>& offset) {
  initialize_openvdb();
  openvdb::GridPtrVec vdb_grids;
  std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> nano_grids;
  const bool nano = lower_extension(file) == ".nvdb";
  for (const NamedGridValues& named : grids) {
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setName(named.name);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel_size));
    auto accessor = grid->getAccessor();
    size_t k = 0;
    for (int z = 0; z < resolution[2]; ++z)
      for (int y = 0; y < resolution[1]; ++y)
        for (int x = 0; x < resolution[0]; ++x, ++k)
          if (named.values[k] != 0)
            accessor.setValue(openvdb::Coord(x + offset[0], y + offset[1], z + offset[2]), named.values[k]);
    if (nano)
      nano_grids.push_back(nanovdb::openToNanoVDB(*grid));
    else
      vdb_grids.push_back(grid);
  }
  if (nano) {
    nanovdb::io::writeGrids(file.string(), nano_grids);
  } else {
    openvdb::io::File out(file.string());
    out.write(vdb_grids);
    out.close();
  }
}

void write_grid_file(const fs::path& file, const std::string& grid_name, const std::array<int, 3>& resolution,
                     const std::vector<float>& values, float voxel_size, const std::array<int, 3>& offset) {
  write_grid_file(file, {{grid_name, values}}, resolution, voxel_size, offset);
}

}  // namespace candela
