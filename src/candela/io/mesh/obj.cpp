// OBJ meshes through tinyobjloader, checked first where tinyobjloader would quietly read a broken
// file, and OBJ models with their MTL materials (obj_scene_reader.cpp).
#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/mesh/mesh_common.h"
#include "candela/io/mesh_io.h"
#include "candela/io/warnings.h"

namespace candela::mesh {
namespace {

// One corner of an OBJ face: OBJ indexes positions, uvs and normals separately.
struct ObjCorner {
  int position, uv, normal;
  bool operator==(const ObjCorner&) const = default;
};

struct ObjCornerHash {
  size_t operator()(const ObjCorner& c) const {
    uint64_t h = static_cast<uint32_t>(c.position);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<uint32_t>(c.uv);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<uint32_t>(c.normal);
    return static_cast<size_t>(h ^ (h >> 29));
  }
};

std::string first_line(std::string_view text) {
  while (!text.empty() && (text.front() == '\n' || text.front() == '\r')) text.remove_prefix(1);
  return std::string(text.substr(0, text.find_first_of("\r\n")));
}

void check_obj_index(int index, size_t count, const char* what, size_t face) {
  if (index < 0 || static_cast<size_t>(index) >= count)
    fail_file_content("malformed OBJ: face {} refers to {} {} but the file has {} of them", face + 1, what,
         index < 0 ? fmt::format("{} (before the first one)", index) : std::to_string(index + 1), count);
}

void check_obj_corners(const tinyobj::attrib_t& attrib, const std::vector<tinyobj::shape_t>& shapes) {
  const size_t positions = attrib.vertices.size() / 3, normals = attrib.normals.size() / 3,
               uvs = attrib.texcoords.size() / 2;
  size_t face = 0;
  for (const tinyobj::shape_t& shape : shapes) {
    size_t corner = 0;
    for (const unsigned char face_size : shape.mesh.num_face_vertices) {
      for (size_t k = 0; k < face_size; ++k) {
        const tinyobj::index_t& index = shape.mesh.indices[corner + k];
        check_obj_index(index.vertex_index, positions, "vertex", face);
        if (index.normal_index != -1) check_obj_index(index.normal_index, normals, "normal", face);
        if (index.texcoord_index != -1) check_obj_index(index.texcoord_index, uvs, "texture coordinate", face);
      }
      corner += face_size;
      ++face;
    }
  }
}

// tinyobjloader drops faces with bad indices it notices while triangulating and only warns about it;
// a mesh with faces silently missing is worse than an error.
void fail_on_dropped_obj_faces(const std::string& warnings) {
  for (const char* dropped : {"out of bounds", "invalid vertex index"}) {
    const size_t at = warnings.find(dropped);
    if (at == std::string::npos) continue;
    const size_t line_start = warnings.rfind('\n', at);
    fail_file_content("malformed OBJ: {}", first_line(std::string_view(warnings).substr(line_start == std::string::npos ? 0 : line_start)));
  }
}

// tinyobjloader reads "nan", "inf" or any other word where a number belongs, and a missing coordinate,
// as 0 without a word, which would quietly move a vertex; so v, vt and vn lines are checked here first.
void check_obj_vertex_line(const std::vector<std::string_view>& words, size_t line_number) {
  const size_t needed = words[0] == "vt" ? 1 : 3;
  if (words.size() - 1 < needed)
    fail_file_content("malformed OBJ: line {}: a '{}' line needs {} numbers, it has {}", line_number, words[0], needed,
         words.size() - 1);
  for (size_t k = 1; k < words.size(); ++k)
    if (!is_plain_number(words[k]))
      fail_file_content("malformed OBJ: line {}: '{}' is not a finite number", line_number, printable(words[k]));
}

// tinyobjloader reads a face index beyond int's range wrapped around (2^31 as an index before the
// first vertex, 10^20 as a valid one), so each index of an 'f' line is checked here first.
void check_obj_face_line(const std::vector<std::string_view>& words, size_t line_number) {
  constexpr int64_t kMaxIndex = std::numeric_limits<int>::max();
  for (size_t k = 1; k < words.size(); ++k) {
    // A corner is "v", "v/vt", "v//vn" or "v/vt/vn".
    std::string_view rest = words[k];
    while (true) {
      const size_t slash = rest.find('/');
      const std::string_view index = rest.substr(0, slash);
      int64_t value = 0;
      const std::errc error = std::from_chars(index.data(), index.data() + index.size(), value).ec;
      const bool beyond_int = error == std::errc() && (value > kMaxIndex || value < -kMaxIndex);
      if (error == std::errc::result_out_of_range || beyond_int)
        fail_file_content("malformed OBJ: line {}: face index '{}' is out of range (at most {} in size)", line_number,
                          printable(index), kMaxIndex);
      if (slash == std::string_view::npos) break;
      rest.remove_prefix(slash + 1);
    }
  }
}

void check_obj_lines(std::string_view text) {
  size_t line_number = 0, at = 0;
  while (at < text.size()) {
    const size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view line = text.substr(at, end - at);
    at = end + 1;
    ++line_number;
    const std::vector<std::string_view> words = split_words(line.substr(0, line.find('#')));
    if (!words.empty() && (words[0] == "v" || words[0] == "vt" || words[0] == "vn"))
      check_obj_vertex_line(words, line_number);
    else if (!words.empty() && words[0] == "f")
      check_obj_face_line(words, line_number);
  }
}

bool every_corner_has(const std::vector<tinyobj::shape_t>& shapes, int tinyobj::index_t::*attribute) {
  for (const tinyobj::shape_t& shape : shapes)
    for (const tinyobj::index_t& index : shape.mesh.indices)
      if (index.*attribute < 0) return false;
  return true;
}

class ObjMeshBuilder {
 public:
  ObjMeshBuilder(const tinyobj::attrib_t& attrib, bool with_normals, bool with_uvs)
      : attrib_(attrib), with_normals_(with_normals), with_uvs_(with_uvs) {}

  void add_face(const tinyobj::index_t* corners, size_t count) {
    // Fan for anything tinyobjloader left as a polygon; its own triangulation already gives triangles.
    for (size_t k = 1; k + 1 < count; ++k) {
      mesh_.indices.push_back(vertex_for(corners[0]));
      mesh_.indices.push_back(vertex_for(corners[k]));
      mesh_.indices.push_back(vertex_for(corners[k + 1]));
    }
  }

  TriangleMesh take() { return std::move(mesh_); }

 private:
  // Corners with the same (position, uv, normal) become one vertex, so shared vertices stay shared.
  // Attributes that are being dropped do not take part, so they cannot split a vertex.
  uint32_t vertex_for(const tinyobj::index_t& index) {
    const ObjCorner key{index.vertex_index, with_uvs_ ? index.texcoord_index : -1,
                        with_normals_ ? index.normal_index : -1};
    const auto [slot, inserted] = vertex_of_corner_.try_emplace(key, 0);
    if (!inserted) return slot->second;
    if (mesh_.positions.size() >= std::numeric_limits<uint32_t>::max())
      fail_file_content("too many distinct vertices for 32-bit indices");
    slot->second = static_cast<uint32_t>(mesh_.positions.size());
    const float* p = &attrib_.vertices[3 * static_cast<size_t>(key.position)];
    mesh_.positions.push_back({p[0], p[1], p[2]});
    if (with_normals_) {
      const float* n = &attrib_.normals[3 * static_cast<size_t>(key.normal)];
      mesh_.normals.push_back({n[0], n[1], n[2]});
    }
    if (with_uvs_) {
      const float* t = &attrib_.texcoords[2 * static_cast<size_t>(key.uv)];
      mesh_.uvs.push_back({t[0], t[1]});
    }
    return slot->second;
  }

  const tinyobj::attrib_t& attrib_;
  bool with_normals_, with_uvs_;
  TriangleMesh mesh_;
  std::unordered_map<ObjCorner, uint32_t, ObjCornerHash> vertex_of_corner_;
};

// Parses OBJ text (and the MTL library text, which may be empty) with every check above.
tinyobj::ObjReader parse_obj(const std::string& text, const std::string& mtl_text) {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  check_obj_lines(text);
  // Parsing from strings makes tinyobjloader ignore `mtllib`: the caller reads the library (or not),
  // so a missing or misplaced .mtl file cannot fail the load of the geometry.
  if (!reader.ParseFromString(text, mtl_text, config))
    fail_file_content("malformed OBJ: {}", printable(first_line(reader.Error()), 200));
  check_obj_corners(reader.GetAttrib(), reader.GetShapes());
  fail_on_dropped_obj_faces(reader.Warning());
  size_t corner_count = 0;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) corner_count += shape.mesh.indices.size();
  if (corner_count == 0) fail_file_content("the OBJ file contains no triangles (no 'f' faces)");
  return reader;
}

// The faces of the OBJ whose material is `material` (every face when material is std::nullopt).
TriangleMesh obj_faces(const tinyobj::ObjReader& reader, std::optional<int> material) {
  const std::vector<tinyobj::shape_t>& shapes = reader.GetShapes();
  ObjMeshBuilder builder(reader.GetAttrib(), every_corner_has(shapes, &tinyobj::index_t::normal_index),
                         every_corner_has(shapes, &tinyobj::index_t::texcoord_index));
  for (const tinyobj::shape_t& shape : shapes) {
    size_t corner = 0;
    for (size_t face = 0; face < shape.mesh.num_face_vertices.size(); ++face) {
      const unsigned char face_size = shape.mesh.num_face_vertices[face];
      if (!material || shape.mesh.material_ids[face] == *material) builder.add_face(&shape.mesh.indices[corner], face_size);
      corner += face_size;
    }
  }
  return builder.take();
}

RGB rgb_of(const float c[3]) { return {c[0], c[1], c[2]}; }

// The `mtllib` file names of an OBJ text (the rest of each mtllib line, as tinyobjloader takes it).
std::vector<std::string> mtl_libraries(std::string_view text) {
  std::vector<std::string> names;
  size_t at = 0;
  while (at < text.size()) {
    const size_t end = std::min(text.find('\n', at), text.size());
    std::string_view line = text.substr(at, end - at);
    at = end + 1;
    const std::vector<std::string_view> words = split_words(line.substr(0, line.find('#')));
    if (words.size() >= 2 && words[0] == "mtllib")
      for (size_t k = 1; k < words.size(); ++k) names.emplace_back(words[k]);
  }
  return names;
}

}  // namespace

TriangleMesh load_obj(const std::string& text) { return obj_faces(parse_obj(text, ""), std::nullopt); }

}  // namespace candela::mesh

namespace candela {

using namespace mesh;  // the helpers above

ObjModel load_obj_model(const std::filesystem::path& file, const SourceLocation& referenced_from, Warnings& warnings) {
  return mesh::with_mesh_file_errors(file, referenced_from, [&] {
    const std::string text = read_whole_file(file);
    ObjModel model;
    std::string mtl_text;
    for (const std::string& name : mtl_libraries(text)) {
      const std::filesystem::path library = file.parent_path() / name;
      try {
        mtl_text += read_whole_file(library) + "\n";
      } catch (const FileContentError& problem) {
        warnings.add_line(fmt::format("material library '{}': {}; its materials are diffuse grey", library.string(),
                                      problem.what()));
      }
    }
    const tinyobj::ObjReader reader = parse_obj(text, mtl_text);
    for (const tinyobj::material_t& m : reader.GetMaterials()) {
      ObjMaterial om;
      om.name = m.name;
      om.diffuse = rgb_of(m.diffuse);
      om.specular = rgb_of(m.specular);
      om.emission = rgb_of(m.emission);
      om.transmission_filter = rgb_of(m.transmittance);
      om.shininess = m.shininess;
      om.ior = m.ior;
      om.dissolve = m.dissolve;
      om.illum = m.illum;
      if (!m.diffuse_texname.empty()) om.diffuse_map = (file.parent_path() / m.diffuse_texname).string();
      model.materials.push_back(std::move(om));
    }
    // One mesh per material that faces use (-1: faces without a material).
    std::vector<int> used;
    for (const tinyobj::shape_t& shape : reader.GetShapes())
      for (int id : shape.mesh.material_ids)
        if (std::find(used.begin(), used.end(), id) == used.end()) used.push_back(id);
    std::sort(used.begin(), used.end());
    for (int id : used) {
      if (id >= int(model.materials.size())) fail_file_content("internal error: material {} of {}", id, model.materials.size());
      TriangleMesh mesh = obj_faces(reader, id);
      if (mesh.indices.empty()) continue;
      validate_mesh(mesh);
      model.parts.push_back({id, std::move(mesh)});
    }
    if (model.parts.empty()) fail_file_content("the OBJ file contains no triangles");
    return model;
  });
}

}  // namespace candela
