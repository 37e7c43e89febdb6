// Mitsuba's own mesh format: one or more meshes, each a little-endian uint16 0x041C, a uint16
// version (3 or 4) and one zlib stream holding: uint32 flags (0x1 vertex normals, 0x2 uvs, 0x8
// vertex colours, 0x10 face normals, 0x1000 / 0x2000 single / double precision); from version 4 a
// NUL-terminated name; uint64 vertex and triangle counts; positions, then the normals, uvs and
// colours the flags announce (3, 2, 3 numbers per vertex); 3 indices per triangle (uint32, or
// uint64 beyond 2^32 vertices, which is refused). The file ends with a table of where each mesh starts (uint32 in
// version 3, uint64 in version 4) and a uint32 count of meshes.
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/mesh/mesh_common.h"
#include "candela/scene/resource_limits.h"

namespace candela::mesh {
namespace {

constexpr uint16_t kSerializedMagic = 0x041C;
enum SerializedFlags : uint32_t {
  kHasNormals = 0x1,
  kHasUvs = 0x2,
  kHasColors = 0x8,
  kFaceNormals = 0x10,
  kSinglePrecision = 0x1000,
  kDoublePrecision = 0x2000,
};

template <typename T>
T little_endian(const char* p) {
  T v = 0;
  for (size_t k = 0; k < sizeof(T); ++k) v |= T(static_cast<uint8_t>(p[k])) << (8 * k);
  return v;
}

// Inflates the zlib stream starting at `at` until `want` bytes are out (or the stream ends), so a
// stream that claims more than it holds is noticed, and one that holds more is not read past need.
class SerializedInflater {
 public:
  SerializedInflater(std::string_view bytes, size_t at) {
    stream_.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data() + at));
    stream_.avail_in = uInt(std::min<size_t>(bytes.size() - at, std::numeric_limits<uInt>::max()));
    if (inflateInit(&stream_) != Z_OK) fail_file_content("zlib cannot start inflating");
  }
  ~SerializedInflater() { inflateEnd(&stream_); }
  SerializedInflater(const SerializedInflater&) = delete;
  SerializedInflater& operator=(const SerializedInflater&) = delete;

  // Makes out_ hold at least `want` bytes; false when the stream ends first.
  bool fill(size_t want) {
    while (out_.size() < want && !ended_) {
      const size_t have = out_.size(), step = std::min<size_t>(want - have, size_t(1) << 24);
      out_.resize(have + step);
      stream_.next_out = reinterpret_cast<Bytef*>(out_.data() + have);
      stream_.avail_out = uInt(step);
      const int status = inflate(&stream_, Z_NO_FLUSH);
      out_.resize(have + step - stream_.avail_out);
      if (status == Z_STREAM_END) ended_ = true;
      else if (status == Z_BUF_ERROR && stream_.avail_in == 0) ended_ = true;  // cut short
      else if (status != Z_OK) fail_file_content("corrupt .serialized file: zlib: {}", stream_.msg ? stream_.msg : "inflate failed");
    }
    return out_.size() >= want;
  }
  const std::string& data() const { return out_; }

 private:
  z_stream stream_{};
  std::string out_;
  bool ended_ = false;
};

}  // namespace

TriangleMesh load_serialized(std::string_view bytes, int shape_index) {
  if (bytes.size() >= 2 && little_endian<uint16_t>(bytes.data()) != kSerializedMagic)
    fail_file_content("not a Mitsuba .serialized file (it does not start with 0x041C)");
  if (bytes.size() < 8) fail_file_content("truncated .serialized file: {} bytes", bytes.size());
  const uint16_t version = little_endian<uint16_t>(bytes.data() + 2);
  if (version != 3 && version != 4) fail_file_content("unsupported .serialized version {} (3 and 4 are)", version);
  // The table of mesh offsets at the end of the file.
  const uint32_t count = little_endian<uint32_t>(bytes.data() + bytes.size() - 4);
  const size_t offset_size = version == 3 ? 4 : 8;
  if (count == 0 || uint64_t(count) * offset_size > bytes.size() - 4)
    fail_file_content("corrupt or truncated .serialized file: the table of meshes at its end (count {}) does not fit in its {} bytes",
         count, bytes.size());
  if (shape_index < 0 || uint32_t(shape_index) >= count)
    fail_file_content("shape_index {} is out of range: the file holds {} mesh{}", shape_index, count, count == 1 ? "" : "es");
  const char* entry = bytes.data() + bytes.size() - 4 - size_t(count - shape_index) * offset_size;
  const uint64_t at = version == 3 ? little_endian<uint32_t>(entry) : little_endian<uint64_t>(entry);
  if (at >= bytes.size() || bytes.size() - at <= 4 || little_endian<uint16_t>(bytes.data() + at) != kSerializedMagic)
    fail_file_content("corrupt .serialized file: mesh {} does not start where the table says (byte {})", shape_index, at);

  SerializedInflater in(bytes, size_t(at) + 4);
  const auto truncated = [&] { fail_file_content("truncated .serialized file: mesh {} ends early", shape_index); };
  if (!in.fill(4)) truncated();
  const uint32_t flags = little_endian<uint32_t>(in.data().data());
  size_t header = 4;
  if (version == 4) {  // the mesh's name, NUL-terminated
    while (true) {
      if (!in.fill(header + 1)) truncated();
      if (in.data()[header++] == '\0') break;
      if (header > 4096) fail_file_content("corrupt .serialized file: mesh {} has no end to its name", shape_index);
    }
  }
  if (!in.fill(header + 16)) truncated();
  const uint64_t vertices = little_endian<uint64_t>(in.data().data() + header);
  const uint64_t triangles = little_endian<uint64_t>(in.data().data() + header + 8);
  header += 16;
  const bool doubles = (flags & kDoublePrecision) != 0;
  // Indices are uint64 only beyond 2^32 vertices, which candela's uint32 indices cannot hold anyway.
  if (vertices > std::numeric_limits<uint32_t>::max())
    fail_file_content("mesh {} has {} vertices; candela indexes at most 2^32", shape_index, vertices);
  const uint64_t real = doubles ? 8 : 4, index = 4;
  const uint64_t per_vertex =
      real * (3 + ((flags & kHasNormals) ? 3 : 0) + ((flags & kHasUvs) ? 2 : 0) + ((flags & kHasColors) ? 3 : 0));
  uint64_t vertex_bytes = 0, index_bytes = 0, total = 0;
  if (__builtin_mul_overflow(vertices, per_vertex, &vertex_bytes) ||
      __builtin_mul_overflow(triangles, 3 * index, &index_bytes) ||
      __builtin_add_overflow(vertex_bytes, index_bytes, &total) || total > available_memory_bytes())
    fail_file_content("mesh {} declares {} vertices and {} triangles: more than this machine's memory", shape_index, vertices,
         triangles);
  if (!in.fill(header + size_t(total))) truncated();

  const char* p = in.data().data() + header;
  const auto number = [&]() {
    float v = doubles ? float(std::bit_cast<double>(little_endian<uint64_t>(p)))
                      : std::bit_cast<float>(little_endian<uint32_t>(p));
    p += real;
    return v;
  };
  TriangleMesh mesh;
  mesh.positions.resize(size_t(vertices));
  for (Point3& v : mesh.positions) v = {number(), number(), number()};
  if (flags & kHasNormals) {
    mesh.normals.resize(size_t(vertices));
    for (Normal3& n : mesh.normals) n = {number(), number(), number()};
    if (flags & kFaceNormals) mesh.normals.clear();  // the file asks for flat shading
  }
  if (flags & kHasUvs) {
    mesh.uvs.resize(size_t(vertices));
    for (Vec2& t : mesh.uvs) t = {number(), number()};
  }
  if (flags & kHasColors) {
    TriangleMesh::Attribute color{"color", false, 3, {}};
    color.values.resize(size_t(vertices) * 3);
    for (float& c : color.values) c = number();
    mesh.attributes.push_back(std::move(color));
  }
  mesh.indices.resize(size_t(triangles) * 3);
  for (uint32_t& i : mesh.indices) {
    i = little_endian<uint32_t>(p);
    p += index;
  }
  return mesh;
}

}  // namespace candela::mesh
