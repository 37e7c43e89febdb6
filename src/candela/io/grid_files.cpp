#include "candela/io/grid_files.h"

#include <fmt/format.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <fstream>
#include <mutex>
#include <unordered_set>

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
                   IndexToWorld index_to_world, const fs::path& file, const SourceLocation& where,
                   uint64_t max_samples) {
  // In 64 bits: a box from -2^31 to 2^31 - 1 spans 2^32 voxels on an axis, beyond int.
  std::array<int64_t, 3> extent;
  for (int a = 0; a < 3; ++a) extent[a] = int64_t(hi[a]) - int64_t(lo[a]) + 1;
  const bool too_many = extent[0] > int64_t(max_samples) || extent[1] > int64_t(max_samples) ||
                        extent[2] > int64_t(max_samples) ||
                        uint64_t(extent[0]) * uint64_t(extent[1]) > max_samples / uint64_t(extent[2]);
  if (too_many)
    fail(where, file, fmt::format("its active voxels span {} x {} x {} samples, more than the {} candela holds densely",
                                  extent[0], extent[1], extent[2], max_samples));
  VolumeDesc v;
  for (int a = 0; a < 3; ++a) v.resolution[a] = int(extent[a]);
  const uint64_t count = uint64_t(extent[0]) * uint64_t(extent[1]) * uint64_t(extent[2]);
  std::vector<float> values(count);
  size_t k = 0;
  // Counted from lo, not up to hi: hi may be INT_MAX, where ++x would overflow.
  for (int dz = 0; dz < v.resolution[2]; ++dz)
    for (int dy = 0; dy < v.resolution[1]; ++dy)
      for (int dx = 0; dx < v.resolution[0]; ++dx) values[k++] = value_at(lo[0] + dx, lo[1] + dy, lo[2] + dz);
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

VolumeDesc read_openvdb(const fs::path& file, const std::string& name, const SourceLocation& where,
                        uint64_t max_samples) {
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
                 file, where, max_samples);
  v.grid_name = name;
  return v;
}

// NanoVDB files are read here, not by NanoVDB's own reader (nanovdb/util/IO.h), which trusts the
// file (fuzz_nanovdb_reader, docs/reliability.md): it allocates the grid count, name lengths and grid
// sizes the file declares, reads a name without its NUL past its end, and follows a grid's node
// offsets as they are. Here each size is checked against the bytes left in the file before anything
// is allocated or read, and a grid's node offsets against its bytes before a value is looked up.
struct NanoVdbGrid {
  std::string name;
  uint64_t size = 0;      // bytes
  std::streamoff at = 0;  // where they start in the file
};

std::vector<NanoVdbGrid> nanovdb_grids(std::ifstream& in, const fs::path& file, const SourceLocation& where) {
  std::error_code ec;
  const uint64_t size = fs::file_size(file, ec);
  if (!in || ec) fail(where, file, "cannot open it");
  std::vector<NanoVdbGrid> grids;
  auto take = [&](void* to, uint64_t bytes, uint64_t& at, const char* what) {
    if (size - at < bytes) fail(where, file, fmt::format("it is cut short in {} at byte {}", what, at));
    in.read(static_cast<char*>(to), std::streamsize(bytes));
    if (!in) fail(where, file, fmt::format("cannot read {} at byte {}", what, at));
    at += bytes;
  };
  // Segments: a header, each grid's metadata and name, then the grids' bytes.
  for (uint64_t at = 0; at < size;) {
    nanovdb::io::Header header;
    take(&header, sizeof header, at, "a segment header");
    if (header.magic != NANOVDB_MAGIC_NUMBER) fail(where, file, fmt::format("no NanoVDB segment at byte {}", at - sizeof header));
    if (header.version.getMajor() != NANOVDB_MAJOR_VERSION_NUMBER)
      fail(where, file, fmt::format("it is NanoVDB version {}.{}.{}; candela reads {}.x", header.version.getMajor(),
                                    header.version.getMinor(), header.version.getPatch(), NANOVDB_MAJOR_VERSION_NUMBER));
    if (header.codec != nanovdb::io::Codec::NONE)
      fail(where, file, fmt::format("its grids are compressed (codec {}), which candela does not decode",
                                    int(header.codec)));
    const size_t first = grids.size();
    for (uint16_t g = 0; g < header.gridCount; ++g) {
      nanovdb::io::MetaData meta;
      take(&meta, sizeof meta, at, "a grid's metadata");
      if (meta.nameSize > size - at) fail(where, file, fmt::format("it is cut short in a grid's name at byte {}", at));
      std::string name(meta.nameSize, '\0');  // allocated once the file is known to hold it
      take(name.data(), meta.nameSize, at, "a grid's name");
      if (name.empty() || name.back() != '\0') fail(where, file, "a grid's name does not end in a NUL byte");
      if (meta.fileSize != meta.gridSize)
        fail(where, file, fmt::format("grid \"{}\" takes {} bytes in the file but {} in memory, which an "
                                      "uncompressed grid cannot", name.c_str(), meta.fileSize, meta.gridSize));
      grids.push_back({name.c_str(), meta.gridSize, 0});
    }
    for (size_t g = first; g < grids.size(); ++g) {
      if (size - at < grids[g].size)
        fail(where, file, fmt::format("grid \"{}\" of {} bytes runs past the end of the file", grids[g].name, grids[g].size));
      grids[g].at = std::streamoff(at);
      at += grids[g].size;
      in.seekg(std::streamoff(at));
    }
  }
  return grids;
}

// Why the bytes of a NanoVDB float grid cannot be read safely, or "": the grid's header, and every
// node offset from the tree down to the leaves, which must land inside the bytes, aligned as NanoVDB
// aligns its nodes.
std::string nanovdb_grid_problem(const nanovdb::HostBuffer& bytes) {
  using Grid = nanovdb::NanoGrid<float>;
  using Root = nanovdb::NanoRoot<float>;
  using Upper = nanovdb::NanoUpper<float>;
  using Lower = nanovdb::NanoLower<float>;
  const uint8_t* begin = bytes.data();
  const int64_t size = int64_t(bytes.size());
  if (size < int64_t(sizeof(Grid) + sizeof(nanovdb::NanoTree<float>))) return "it is shorter than a grid's header";
  const Grid& grid = *reinterpret_cast<const Grid*>(begin);
  if (!grid.isValid()) return "its header has no NanoVDB magic number";
  if (grid.gridSize() != uint64_t(size))
    return fmt::format("its header says {} bytes, the file {}", grid.gridSize(), size);
  if (grid.gridType() != nanovdb::GridType::Float) return "it does not hold floats";
  // The node of `node_size` bytes at `offset` from `from`, or nullptr when it is not inside the bytes.
  auto node_at = [&](const void* from, int64_t offset, uint64_t node_size) -> const uint8_t* {
    const int64_t base = static_cast<const uint8_t*>(from) - begin;  // in [0, size]
    if (offset < -base || offset > size - base - int64_t(node_size) || (base + offset) % NANOVDB_DATA_ALIGNMENT != 0)
      return nullptr;
    return begin + base + offset;
  };
  const auto& tree = *reinterpret_cast<const nanovdb::TreeData<3>*>(&grid.tree());
  const auto* root = reinterpret_cast<const Root*>(node_at(&tree, int64_t(tree.mNodeOffset[3]), sizeof(Root)));
  if (!root || !node_at(root, sizeof(Root), uint64_t(root->tileCount()) * sizeof(typename Root::Tile)))
    return "its root node lies outside it";
  // Each node is checked once however many parents name it, so a crafted file cannot make the
  // check itself take long.
  std::unordered_set<const void*> checked;
  auto children_inside = [&]<typename Node, typename Child>(const Node* node, const Child*) {
    for (auto n = node->data()->mChildMask.beginOn(); n; ++n)
      if (!node_at(node, node->data()->mTable[*n].child, sizeof(Child))) return false;
    return true;
  };
  for (uint32_t i = 0; i < root->tileCount(); ++i) {
    const auto* tile = root->data()->tile(i);
    if (!tile->isChild()) continue;
    const auto* upper = reinterpret_cast<const Upper*>(node_at(root, tile->child, sizeof(Upper)));
    if (!upper || (checked.insert(upper).second && !children_inside(upper, static_cast<const Lower*>(nullptr))))
      return "a node offset points outside it";
    for (auto n = upper->data()->mChildMask.beginOn(); n; ++n) {
      const auto* lower = upper->data()->getChild(*n);
      if (checked.insert(lower).second && !children_inside(lower, static_cast<const nanovdb::NanoLeaf<float>*>(nullptr)))
        return "a node offset points outside it";
    }
  }
  return "";
}

VolumeDesc read_nanovdb(const fs::path& file, const std::string& name, const SourceLocation& where,
                        uint64_t max_samples) {
  std::ifstream in(file, std::ios::binary);
  std::vector<std::string> names;
  const NanoVdbGrid* found = nullptr;
  const std::vector<NanoVdbGrid> grids = nanovdb_grids(in, file, where);
  for (const NanoVdbGrid& g : grids) {
    names.push_back(g.name);
    if (!found && g.name == name) found = &g;
  }
  if (!found) fail(where, file, fmt::format("it has no grid \"{}\" (its grids: {})", name, joined(names)));
  nanovdb::HostBuffer bytes = nanovdb::HostBuffer::create(found->size);
  in.clear();
  in.seekg(found->at);
  in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(found->size));
  if (!in) fail(where, file, fmt::format("cannot read grid \"{}\"", name));
  if (std::string problem = nanovdb_grid_problem(bytes); problem == "it does not hold floats")
    fail(where, file, fmt::format("grid \"{}\" does not hold floats", name));
  else if (!problem.empty())
    fail(where, file, fmt::format("grid \"{}\" is corrupt: {}", name, problem));
  const auto* grid = reinterpret_cast<const nanovdb::NanoGrid<float>*>(bytes.data());
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
                 file, where, max_samples);
  v.grid_name = name;
  return v;
}

}  // namespace

VolumeDesc read_grid_file(const fs::path& file, const std::string& grid_name, const SourceLocation& referenced_from,
                          uint64_t max_dense_samples) {
  const std::string ext = lower_extension(file);
  if (ext == ".vdb") return read_openvdb(file, grid_name, referenced_from, max_dense_samples);
  if (ext == ".nvdb") return read_nanovdb(file, grid_name, referenced_from, max_dense_samples);
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
      std::ifstream in(file, std::ios::binary);
      for (const NanoVdbGrid& grid : nanovdb_grids(in, file, referenced_from)) names.push_back(grid.name);
    }
  } catch (const SceneError&) {
    throw;  // nanovdb_grids' own, which names the file already
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
