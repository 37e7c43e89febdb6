// PLY meshes through Assimp, after the checks Assimp lacks; triangle strips and extra per-vertex or
// per-face properties (mesh attributes) read here.
#include <assimp/Importer.hpp>
#include <assimp/mesh.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "candela/base/error.h"
#include "candela/io/mesh/mesh_common.h"

namespace candela::mesh {
namespace {

// Assimp's PLY reader trusts the file: it loops forever on a header cut short, allocates whatever
// counts the header declares, and reads past the end of (or asserts on) data cut short. So the header
// is parsed and the data measured against it here first; Assimp only sees files that hold everything
// their header declares.

struct PlyScalarType {
  uint8_t size = 0;  // bytes in a binary file
  bool is_signed = false;
  bool is_integer = false;
};

std::optional<PlyScalarType> ply_scalar_type(std::string_view name) {
  if (name == "char" || name == "int8") return PlyScalarType{1, true, true};
  if (name == "uchar" || name == "uint8") return PlyScalarType{1, false, true};
  if (name == "short" || name == "int16") return PlyScalarType{2, true, true};
  if (name == "ushort" || name == "uint16") return PlyScalarType{2, false, true};
  if (name == "int" || name == "int32") return PlyScalarType{4, true, true};
  if (name == "uint" || name == "uint32") return PlyScalarType{4, false, true};
  if (name == "float" || name == "float32") return PlyScalarType{4, true, false};
  if (name == "double" || name == "float64") return PlyScalarType{8, true, false};
  return std::nullopt;
}

struct PlyProperty {
  std::string name;
  PlyScalarType value;                       // the property's, or each list item's
  std::optional<PlyScalarType> list_length;  // set for list properties
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;

  bool has_lists() const {
    return std::any_of(properties.begin(), properties.end(), [](const PlyProperty& p) { return p.list_length; });
  }
  bool has_scalar(std::string_view property_name) const {
    return std::any_of(properties.begin(), properties.end(),
                       [&](const PlyProperty& p) { return p.name == property_name && !p.list_length; });
  }
  uint64_t scalar_bytes() const {
    uint64_t bytes = 0;
    for (const PlyProperty& property : properties) bytes += property.value.size;
    return bytes;
  }
};

enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct PlyHeader {
  std::optional<PlyEncoding> encoding;
  size_t data_offset = 0;  // first byte after the "end_header" line
  size_t line_count = 0;   // lines up to and including "end_header"
  std::vector<PlyElement> elements;
};

std::string line_of(const std::vector<std::string_view>& words) {
  std::string line;
  for (const std::string_view word : words) (line += line.empty() ? "" : " ") += word;
  return line;
}

PlyScalarType ply_scalar_type_or_fail(std::string_view name) {
  const std::optional<PlyScalarType> type = ply_scalar_type(name);
  if (!type) fail_file_content("malformed PLY: unknown property type '{}' in the header", printable(name));
  return *type;
}

void read_ply_format(const std::vector<std::string_view>& words, PlyHeader& header) {
  // Assimp keeps the first format line and would read the data the wrong way (and leak on failing).
  if (header.encoding) fail_file_content("malformed PLY: the header has more than one format line");
  if (words.size() == 3 && words[1] == "ascii") header.encoding = PlyEncoding::Ascii;
  else if (words.size() == 3 && words[1] == "binary_little_endian") header.encoding = PlyEncoding::BinaryLittleEndian;
  else if (words.size() == 3 && words[1] == "binary_big_endian") header.encoding = PlyEncoding::BinaryBigEndian;
  else fail_file_content("malformed PLY: unknown format line '{}'", printable(line_of(words)));
}

void read_ply_element(const std::vector<std::string_view>& words, PlyHeader& header) {
  if (words.size() != 3) fail_file_content("malformed PLY: bad element line '{}'", printable(line_of(words)));
  // Assimp misreads a long name of digits as a count and allocates for it (tens of gigabytes).
  if (!(std::isalpha(static_cast<unsigned char>(words[1][0])) || words[1][0] == '_'))
    fail_file_content("malformed PLY: element name '{}' does not start with a letter", printable(words[1]));
  PlyElement element;
  element.name = printable(words[1]);  // kept for messages only
  const char* end = words[2].data() + words[2].size();
  const auto [stop, error] = std::from_chars(words[2].data(), end, element.count);
  if (error != std::errc() || stop != end)
    fail_file_content("malformed PLY: element '{}' has an invalid count '{}'", element.name, printable(words[2]));
  // Assimp reads a second element of a name over the first (and leaks the first one's data).
  for (const PlyElement& earlier : header.elements)
    if (earlier.name == element.name) fail_file_content("malformed PLY: element '{}' is declared twice", element.name);
  header.elements.push_back(element);
}

void read_ply_property(const std::vector<std::string_view>& words, PlyHeader& header) {
  if (header.elements.empty()) fail_file_content("malformed PLY: a property comes before any element");
  const bool list = words.size() >= 2 && words[1] == "list";
  if (words.size() != (list ? 5u : 3u)) fail_file_content("malformed PLY: bad property line '{}'", printable(line_of(words)));
  PlyProperty property;
  property.name = words.back();
  if (list) {
    property.list_length = ply_scalar_type_or_fail(words[2]);
    if (!property.list_length->is_integer) fail_file_content("malformed PLY: list length type '{}' is not an integer", printable(words[2]));
    property.value = ply_scalar_type_or_fail(words[3]);
  } else {
    property.value = ply_scalar_type_or_fail(words[1]);
  }
  header.elements.back().properties.push_back(property);
}

void check_ply_header_complete(const PlyHeader& header) {
  if (!header.encoding) fail_file_content("malformed PLY: the header has no format line");
  for (const PlyElement& element : header.elements) {
    if (element.count > 0 && element.properties.empty())
      fail_file_content("malformed PLY: element '{}' has no properties", element.name);
    // Assimp would read vertices without coordinates as all zero.
    if (element.name == "vertex" && !(element.has_scalar("x") && element.has_scalar("y") && element.has_scalar("z")))
      fail_file_content("malformed PLY: the 'vertex' element lacks an x, y or z property");
    // Assimp 5.2 turns a strip into the wrong triangles: strips become faces first (strips_as_faces).
    if (element.name == "tristrips" && element.count > 0 &&
        !(element.properties.size() == 1 && element.properties[0].list_length && element.properties[0].value.is_integer))
      fail_file_content("unsupported PLY: a 'tristrips' element must hold one list of vertex indices");
  }
  // Without a vertex element Assimp guesses which element holds the vertices and misreads the data.
  if (std::none_of(header.elements.begin(), header.elements.end(),
                   [](const PlyElement& e) { return e.name == "vertex"; }))
    fail_file_content("malformed PLY: the header declares no 'vertex' element");
}

PlyHeader read_ply_header(std::string_view bytes) {
  PlyHeader header;
  bool seen_magic = false;
  size_t line_start = 0;
  while (line_start < bytes.size()) {
    const size_t newline = bytes.find('\n', line_start);
    if (newline == std::string_view::npos) break;
    const std::string_view text = bytes.substr(line_start, newline - line_start);
    // A header is text. Assimp splits lines at a lone carriage return and ends strings at a NUL, where
    // candela's word splitting would not, so the two would read different headers: refuse control
    // bytes (a carriage return is allowed only right before the newline, as in CRLF files).
    for (size_t k = 0; k < text.size(); ++k) {
      const auto c = static_cast<unsigned char>(text[k]);
      if (c == '\r' && k + 1 != text.size())
        fail_file_content("malformed PLY: header line {} has a carriage return inside it", header.line_count + 1);
      if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f)
        fail_file_content("malformed PLY: header line {} has a control byte (0x{:02x}) in it", header.line_count + 1, c);
    }
    const std::vector<std::string_view> words = split_words(text);
    line_start = newline + 1;
    ++header.line_count;
    if (words.empty()) continue;
    if (!seen_magic) {
      if (words.size() != 1 || words[0] != "ply") break;
      seen_magic = true;
    } else if (words[0] == "format") {
      read_ply_format(words, header);
    } else if (words[0] == "element") {
      read_ply_element(words, header);
    } else if (words[0] == "property") {
      read_ply_property(words, header);
    } else if (words[0] == "end_header") {
      check_ply_header_complete(header);
      header.data_offset = line_start;
      return header;
    } else if (words[0] != "comment" && words[0] != "obj_info" && !header.elements.empty()) {
      // Assimp ends an element's property list at the first other line and skips the property lines
      // after it, so the two readers would disagree on the record size (the data would then be
      // misread, in one fuzzed file into an 8.5 GB allocation). Before the first element such a line
      // is harmless (Blender 2.4 broke its "Created by" comment over two lines) and is skipped.
      fail_file_content("malformed PLY: unrecognised header line '{}' after element '{}'", printable(line_of(words)),
           header.elements.back().name);
    }
  }
  fail_file_content("{}", seen_magic ? "truncated PLY: the header has no 'end_header' line"
                        : "malformed PLY: the file does not start with 'ply'");
}

[[noreturn]] void fail_ply_data_short(const PlyElement& element, uint64_t complete, size_t data_size) {
  if (element.count > data_size)
    fail_file_content("corrupt PLY header: it declares {} '{}' elements but only {} bytes of data follow it", element.count,
         element.name, data_size);
  fail_file_content("truncated PLY: the data ends after {} of the {} '{}' elements the header declares", complete, element.count,
       element.name);
}

bool fits(uint64_t at, uint64_t bytes, size_t size) { return at <= size && size - at >= bytes; }

// The raw bits of one binary value of `size` bytes at `at` (in bounds), in either byte order.
uint64_t read_binary_bits(std::string_view data, uint64_t at, unsigned size, bool big_endian) {
  uint64_t bits = 0;
  for (unsigned k = 0; k < size; ++k) bits = bits << 8 | static_cast<uint8_t>(data[at + (big_endian ? k : size - 1u - k)]);
  return bits;
}

uint64_t read_binary_list_length(std::string_view data, uint64_t at, PlyScalarType type, bool big_endian) {
  const uint64_t bits = read_binary_bits(data, at, type.size, big_endian);
  if (type.is_signed && (bits >> (8 * type.size - 1)) != 0) fail_file_content("malformed PLY: negative list length");
  return bits;
}

// Resource limits: before Assimp (or the scans below) allocate or loop per element, every element
// count is measured against the bytes after the header, so a corrupt header claiming billions of
// vertices or faces is refused at once. Each element needs at least: binary, its scalar properties
// plus the length fields of its lists (lists may be empty); ASCII, one value and a line break (2
// bytes; the very last line may lack its line break). Sums saturate instead of overflowing.
void check_ply_counts_fit_data(const PlyHeader& header, std::string_view data) {
  const bool ascii = header.encoding == PlyEncoding::Ascii;
  const uint64_t room = ascii ? uint64_t(data.size()) + 1 : uint64_t(data.size());
  uint64_t needed = 0;
  for (const PlyElement& element : header.elements) {
    if (element.count == 0) continue;
    uint64_t element_bytes = 2;
    if (!ascii) {
      element_bytes = 0;
      for (const PlyProperty& property : element.properties)
        element_bytes += property.list_length ? property.list_length->size : property.value.size;
    }
    uint64_t bytes = 0;
    if (!__builtin_mul_overflow(element.count, element_bytes, &bytes) && !__builtin_add_overflow(needed, bytes, &needed) &&
        needed <= room)
      continue;
    // A binary file that holds some of the elements is more likely cut short: the scan below says
    // exactly where its data ends ("truncated PLY").
    if (!ascii && element.count <= data.size()) return;
    fail_file_content("corrupt PLY header: it declares {} '{}' elements (at least {} bytes each in a{} file) but only {} bytes of "
         "data follow it",
         element.count, element.name, element_bytes, ascii ? "n ASCII" : " binary", data.size());
  }
}

void check_binary_ply_data(const PlyHeader& header, std::string_view data) {
  const bool big_endian = header.encoding == PlyEncoding::BinaryBigEndian;
  uint64_t at = 0;
  for (const PlyElement& element : header.elements) {
    if (element.count == 0) continue;
    if (!element.has_lists()) {  // fixed size: no need to visit every element
      const uint64_t fitting = (data.size() - at) / element.scalar_bytes();
      if (element.count > fitting) fail_ply_data_short(element, fitting, data.size());
      at += element.count * element.scalar_bytes();
      continue;
    }
    for (uint64_t i = 0; i < element.count; ++i) {
      for (const PlyProperty& property : element.properties) {
        if (!property.list_length) {
          at += property.value.size;
          continue;
        }
        if (!fits(at, property.list_length->size, data.size())) fail_ply_data_short(element, i, data.size());
        const uint64_t length = read_binary_list_length(data, at, *property.list_length, big_endian);
        at += property.list_length->size;
        if (!fits(at, 0, data.size()) || length > (data.size() - at) / property.value.size)
          fail_ply_data_short(element, i, data.size());
        at += length * property.value.size;
      }
      if (!fits(at, 0, data.size())) fail_ply_data_short(element, i, data.size());
    }
  }
}

// Assimp reads ASCII PLY one element per line; a line with fewer values than the header declares
// would be read as zeros (or make Assimp assert).
bool ascii_ply_line_holds(const PlyElement& element, std::string_view line, size_t line_number) {
  // Assimp also ends a line at a lone carriage return, where the words here run on: the two would
  // read different records (a fuzzed file made Assimp take a 30-digit number for a list length
  // and allocate 14 GB). A carriage return is allowed only right before the newline.
  if (const size_t cr = line.find('\r'); cr != std::string_view::npos && cr + 1 != line.size())
    fail_file_content("malformed PLY: line {} has a carriage return inside it", line_number);
  const std::vector<std::string_view> values = split_words(line);
  // Assimp would stop at a word that is no number with a message quoting raw bytes (and leak).
  for (const std::string_view value : values)
    if (!is_plain_number(value))
      fail_file_content("malformed PLY: line {}: '{}' is not a finite number", line_number, printable(value));
  size_t next = 0;
  for (const PlyProperty& property : element.properties) {
    if (next >= values.size()) return false;
    const std::string_view value = values[next++];
    if (!property.list_length) continue;
    uint64_t length = 0;
    const auto [stop, error] = std::from_chars(value.data(), value.data() + value.size(), length);
    if (error != std::errc() || stop != value.data() + value.size())
      fail_file_content("malformed PLY: line {}: '{}' is not a list length", line_number, printable(value));
    if (length > values.size() - next) return false;
    next += length;
  }
  return true;
}

void check_ascii_ply_data(const PlyHeader& header, std::string_view data) {
  size_t at = 0, line_number = header.line_count;
  // The next line that holds anything; Assimp skips blank ones too.
  const auto next_line = [&]() -> std::optional<std::string_view> {
    while (at < data.size()) {
      const size_t end = std::min(data.find('\n', at), data.size());
      const std::string_view line = data.substr(at, end - at);
      at = end + 1;
      ++line_number;
      if (line.find_first_not_of(" \t\r") != std::string_view::npos) return line;
    }
    return std::nullopt;
  };
  for (const PlyElement& element : header.elements) {
    for (uint64_t i = 0; i < element.count; ++i) {
      const std::optional<std::string_view> line = next_line();
      if (!line) fail_ply_data_short(element, i, data.size());
      if (!ascii_ply_line_holds(element, *line, line_number))
        fail_file_content("malformed PLY: line {} has fewer values than the header declares for a '{}' element", line_number,
             element.name);
    }
  }
}

std::string describe_elements(const PlyHeader& header) {
  std::string list;
  for (const PlyElement& element : header.elements)
    list += fmt::format("{}{} '{}'", list.empty() ? "" : ", ", element.count, element.name);
  return fmt::format(" (the header declares {})", list.empty() ? "no elements" : list);
}

bool has_triangles(const aiMesh& mesh) { return (mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) != 0; }

// Triangulation reads the positions of a polygon's corners, so indices are checked before it runs.
void check_assimp_face_indices(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices == 0) fail_file_content("malformed PLY: face {} has no vertices", f);
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= mesh.mNumVertices)
          fail_file_content("malformed PLY: face {} refers to vertex {} but there are {} vertices", f, face.mIndices[k],
               mesh.mNumVertices);
    }
  }
}

void append_assimp_mesh(const aiMesh& source, bool with_normals, bool with_uvs, TriangleMesh& mesh) {
  const uint64_t base = mesh.positions.size();
  if (base + source.mNumVertices > std::numeric_limits<uint32_t>::max())
    fail_file_content("too many vertices for 32-bit indices");
  for (unsigned i = 0; i < source.mNumVertices; ++i) {
    const aiVector3D& p = source.mVertices[i];
    mesh.positions.push_back({p.x, p.y, p.z});
    if (with_normals) {
      const aiVector3D& n = source.mNormals[i];
      mesh.normals.push_back({n.x, n.y, n.z});
    }
    if (with_uvs) {
      const aiVector3D& t = source.mTextureCoords[0][i];
      mesh.uvs.push_back({t.x, t.y});
    }
  }
  for (unsigned f = 0; f < source.mNumFaces; ++f) {
    const aiFace& face = source.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines: not surfaces
    for (unsigned k = 0; k < 3; ++k) mesh.indices.push_back(static_cast<uint32_t>(base + face.mIndices[k]));
  }
}

// ---- triangle strips (e.g. the Igea scan): rewritten as a 'face' element before Assimp reads the file

// A binary scalar at `at` as a signed 64-bit integer.
int64_t read_binary_integer(std::string_view data, uint64_t at, PlyScalarType type, bool big_endian) {
  uint64_t bits = 0;
  for (unsigned k = 0; k < type.size; ++k)
    bits = bits << 8 | static_cast<uint8_t>(data[at + (big_endian ? k : type.size - 1u - k)]);
  if (type.is_signed && type.size < 8 && (bits >> (8 * type.size - 1)) != 0) bits |= ~uint64_t(0) << (8 * type.size);
  return int64_t(bits);
}

// The triangles of strips given as one index list with -1 ending each strip: (a, b, c), (c, b, d),
// (c, d, e), ... every other triangle reversed so that all keep the strip's orientation; triangles
// with a repeated vertex (the joints of strips stitched by repetition) are dropped.
void append_strip_triangles(const std::vector<int64_t>& list, std::vector<std::array<int64_t, 3>>& out) {
  size_t start = 0;
  for (size_t i = 0; i <= list.size(); ++i) {
    if (i < list.size() && list[i] >= 0) continue;
    for (size_t k = start; k + 2 < i; ++k) {
      std::array<int64_t, 3> t = (k - start) % 2 == 0 ? std::array<int64_t, 3>{list[k], list[k + 1], list[k + 2]}
                                                      : std::array<int64_t, 3>{list[k + 1], list[k], list[k + 2]};
      if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) out.push_back(t);
    }
    start = i + 1;
  }
}

// The same PLY with every 'tristrips' element replaced by a 'face' element of its triangles (the file
// has been checked to hold all its data).
std::string strips_as_faces(const std::string& bytes, const PlyHeader& header) {
  const std::string_view data = std::string_view(bytes).substr(header.data_offset);
  const bool ascii = header.encoding == PlyEncoding::Ascii, big_endian = header.encoding == PlyEncoding::BinaryBigEndian;
  // Each element's data: its bytes (copied as they are), or the triangles of its strips.
  struct Part {
    std::string_view raw;
    bool strips = false;
    std::vector<std::array<int64_t, 3>> triangles;
  };
  std::vector<Part> parts;
  uint64_t at = 0;
  for (const PlyElement& element : header.elements) {
    Part part;
    part.strips = element.name == "tristrips" && element.count > 0;
    const uint64_t begin = at;
    std::vector<int64_t> list;
    for (uint64_t i = 0; i < element.count; ++i) {
      if (ascii) {
        size_t end = at;
        do {  // the next line that holds anything
          at = end;
          end = std::min(data.find('\n', at), data.size());
          if (data.substr(at, end - at).find_first_not_of(" \t\r") != std::string_view::npos) break;
          end += 1;
        } while (end <= data.size());
        if (part.strips) {
          const std::vector<std::string_view> words = split_words(data.substr(at, end - at));
          for (size_t w = 1; w < words.size(); ++w) {
            int64_t v = 0;
            std::from_chars(words[w].data(), words[w].data() + words[w].size(), v);
            list.push_back(v);
          }
          list.push_back(-1);
        }
        at = end + 1;
        continue;
      }
      for (const PlyProperty& property : element.properties) {
        if (!property.list_length) {
          at += property.value.size;
          continue;
        }
        const uint64_t length = read_binary_list_length(data, at, *property.list_length, big_endian);
        at += property.list_length->size;
        for (uint64_t k = 0; k < length; ++k, at += property.value.size)
          if (part.strips) list.push_back(read_binary_integer(data, at, property.value, big_endian));
        if (part.strips) list.push_back(-1);
      }
    }
    if (part.strips) append_strip_triangles(list, part.triangles);
    else part.raw = data.substr(std::min<uint64_t>(begin, data.size()), std::min<uint64_t>(at, data.size()) - std::min<uint64_t>(begin, data.size()));
    parts.push_back(std::move(part));
  }
  // The header, with each strips element and its property lines replaced.
  std::string out;
  const std::string_view head = std::string_view(bytes).substr(0, header.data_offset);
  size_t element_index = 0, line_at = 0;
  bool skipping = false;
  while (line_at < head.size()) {
    const size_t end = std::min(head.find('\n', line_at), head.size());
    const std::string_view line = head.substr(line_at, std::min(end + 1, head.size()) - line_at);
    line_at = end + 1;
    const std::vector<std::string_view> words = split_words(line);
    if (!words.empty() && words[0] == "element") {
      const Part& part = parts[element_index++];
      skipping = part.strips;
      if (skipping) {
        out += fmt::format("element face {}\nproperty list uchar int vertex_indices\n", part.triangles.size());
        continue;
      }
    } else if (!words.empty() && words[0] != "property") {
      skipping = false;
    }
    if (!skipping) out += line;
  }
  for (const Part& part : parts) {
    if (!part.strips) {
      out += part.raw;
      continue;
    }
    for (const auto& t : part.triangles) {
      if (ascii) {
        out += fmt::format("3 {} {} {}\n", t[0], t[1], t[2]);
        continue;
      }
      out += char(3);
      for (int64_t v : t) {
        const uint32_t u = uint32_t(int32_t(v));
        for (int k = 0; k < 4; ++k) out += char(big_endian ? (u >> (8 * (3 - k))) & 0xff : (u >> (8 * k)) & 0xff);
      }
    }
  }
  return out;
}

// ---------------------------------------------------------------- PLY extra properties
// Vertex and face properties beyond the geometry (colours, scalar fields, per-face ids) become
// TriangleMesh::attributes, as Mitsuba's mesh attributes define them: "name_0 name_1 name_2" group
// into one 3-channel attribute "name", "r g b" / "red green blue" into "color", any other property
// is a 1-channel attribute of its own name. Attributes follow the file's vertex and face order,
// which Assimp does not keep, so a file that has any is read here, after the checks above made
// sure its data holds everything the header declares; polygons become fans, as Assimp makes them.

bool is_geometry_property(const std::string& element, const std::string& name) {
  static const std::array<const char*, 14> vertex = {"x", "y", "z", "nx", "ny", "nz", "u", "v", "s", "t",
                                                     "texture_u", "texture_v", "texture_s", "texture_t"};
  if (element == "vertex")
    return std::any_of(vertex.begin(), vertex.end(), [&](const char* g) { return name == g; });
  return name == "vertex_indices" || name == "vertex_index";
}

struct PropertyGroup {
  std::string name;
  std::vector<size_t> columns;
};

std::vector<PropertyGroup> attribute_groups(const PlyElement& element) {
  std::vector<PropertyGroup> groups;
  for (size_t i = 0; i < element.properties.size(); ++i) {
    const PlyProperty& p = element.properties[i];
    if (p.list_length || is_geometry_property(element.name, p.name)) continue;
    std::string base = p.name;
    if (p.name == "r" || p.name == "g" || p.name == "b" || p.name == "red" || p.name == "green" || p.name == "blue")
      base = "color";
    else if (size_t us = p.name.rfind('_');
             us != std::string::npos && us + 2 == p.name.size() && std::isdigit(static_cast<unsigned char>(p.name.back())))
      base = p.name.substr(0, us);
    auto it = std::find_if(groups.begin(), groups.end(), [&](const PropertyGroup& g) { return g.name == base; });
    if (it == groups.end()) groups.push_back({base, {i}});
    else it->columns.push_back(i);
  }
  // Only 1- and 3-channel attributes exist.
  std::erase_if(groups, [](const PropertyGroup& g) { return g.columns.size() != 1 && g.columns.size() != 3; });
  return groups;
}

const PlyElement* find_element(const PlyHeader& header, std::string_view name) {
  for (const PlyElement& e : header.elements)
    if (e.name == name) return &e;
  return nullptr;
}

bool has_ply_attributes(const PlyHeader& header) {
  if (find_element(header, "tristrips")) return false;  // strips carry no per-face values to keep
  const PlyElement* vertex = find_element(header, "vertex");
  const PlyElement* face = find_element(header, "face");
  return (vertex && !attribute_groups(*vertex).empty()) || (face && !attribute_groups(*face).empty());
}

// Sequential reader of the data's numbers, binary or ASCII (one record per non-blank line, as
// Assimp reads it: values beyond the declared ones are ignored).
class PlyNumbers {
 public:
  PlyNumbers(const PlyHeader& header, std::string_view data) : header_(header), data_(data) {}
  void begin_record() {
    if (header_.encoding != PlyEncoding::Ascii) return;
    at_ = line_end_ == 0 ? 0 : line_end_ + 1;
    while (at_ < data_.size()) {
      line_end_ = std::min(data_.find('\n', at_), data_.size());
      if (data_.substr(at_, line_end_ - at_).find_first_not_of(" \t\r") != std::string_view::npos) return;
      at_ = line_end_ + 1;
    }
    fail_file_content("truncated PLY: the data ends early");
  }
  double next(PlyScalarType type) {
    if (header_.encoding == PlyEncoding::Ascii) {
      const std::string_view line = data_.substr(0, line_end_);
      const size_t start = line.find_first_not_of(" \t\r", at_);
      if (start == std::string_view::npos) fail_file_content("malformed PLY: a line has fewer values than the header declares");
      size_t end = line.find_first_of(" \t\r", start);
      if (end == std::string_view::npos) end = line.size();
      at_ = end;
      double v = 0;
      std::from_chars(data_.data() + start, data_.data() + end, v);
      return v;
    }
    if (!fits(at_, type.size, data_.size())) fail_file_content("truncated PLY: the data ends early");
    const uint64_t bits = read_binary_bits(data_, at_, type.size, header_.encoding == PlyEncoding::BinaryBigEndian);
    at_ += type.size;
    if (!type.is_integer) return type.size == 4 ? double(std::bit_cast<float>(uint32_t(bits))) : std::bit_cast<double>(bits);
    if (type.is_signed && type.size < 8 && (bits >> (8 * type.size - 1)))
      return double(int64_t(bits) - (int64_t(1) << (8 * type.size)));
    return double(bits);
  }

 private:
  const PlyHeader& header_;
  std::string_view data_;
  size_t at_ = 0, line_end_ = 0;
};

TriangleMesh load_ply_with_attributes(std::string_view bytes, const PlyHeader& header) {
  PlyNumbers numbers(header, bytes.substr(header.data_offset));
  // The first vertex and face elements' records, flat: a row per record, a column per property (lists
  // hold 0 there), and each face's vertex indices, face f's at [face_starts[f], face_starts[f + 1]).
  // Flat arrays rather than a vector per record: millions of small allocations, freed after loading,
  // would leave the heap fragmented and the process larger for the whole render.
  const PlyElement* vertex = find_element(header, "vertex");
  const PlyElement* face = find_element(header, "face");
  std::vector<double> vertex_values, face_values;
  std::vector<uint32_t> face_indices;
  std::vector<size_t> face_starts{0};
  for (const PlyElement& e : header.elements) {
    const bool is_vertex = &e == vertex, is_face = &e == face;
    std::vector<double>* values = is_vertex ? &vertex_values : is_face ? &face_values : nullptr;
    if (values) values->reserve(e.count * e.properties.size());  // the counts were checked against the data
    for (uint64_t r = 0; r < e.count; ++r) {
      numbers.begin_record();
      bool has_indices = false;
      for (const PlyProperty& p : e.properties) {
        if (!p.list_length) {
          const double value = numbers.next(p.value);
          if (values) values->push_back(value);
          continue;
        }
        if (values) values->push_back(0.0);
        // One index list per face record: the first vertex_indices list (any other list is ignored).
        const bool keep = is_face && !has_indices && is_geometry_property("face", p.name);
        const auto n = uint64_t(numbers.next(*p.list_length));
        for (uint64_t j = 0; j < n; ++j) {
          const double index = numbers.next(p.value);
          if (!(index >= 0 && index <= double(std::numeric_limits<uint32_t>::max())))
            fail_file_content("malformed PLY: face {} has a vertex index {}", r, index);
          if (keep) face_indices.push_back(uint32_t(index));
        }
        has_indices = has_indices || keep;
      }
      if (is_face) face_starts.push_back(face_indices.size());  // a record without indices has none
    }
  }
  const size_t vertex_width = vertex->properties.size();
  auto column = [&](std::initializer_list<const char*> names) -> int {
    for (const char* n : names)
      for (size_t i = 0; i < vertex_width; ++i)
        if (vertex->properties[i].name == n && !vertex->properties[i].list_length) return int(i);
    return -1;
  };
  const int x = column({"x"}), y = column({"y"}), z = column({"z"});
  const int nx = column({"nx"}), ny = column({"ny"}), nz = column({"nz"});
  const int u = column({"u", "s", "texture_u", "texture_s"}), v = column({"v", "t", "texture_v", "texture_t"});
  TriangleMesh mesh;
  const size_t vertex_count = vertex->count;
  auto at = [&](size_t row, auto column) { return float(vertex_values[row * vertex_width + size_t(column)]); };
  mesh.positions.reserve(vertex_count);
  for (size_t row = 0; row < vertex_count; ++row) {
    mesh.positions.push_back({at(row, x), at(row, y), at(row, z)});
    if (nx >= 0 && ny >= 0 && nz >= 0) mesh.normals.push_back({at(row, nx), at(row, ny), at(row, nz)});
    if (u >= 0 && v >= 0) mesh.uvs.push_back({at(row, u), at(row, v)});
  }
  size_t triangle_count = 0;
  for (size_t f = 0; f + 1 < face_starts.size(); ++f)
    triangle_count += std::max<size_t>(face_starts[f + 1] - face_starts[f], 2) - 2;
  mesh.indices.reserve(3 * triangle_count);
  std::vector<size_t> face_of_triangle;
  face_of_triangle.reserve(triangle_count);
  for (size_t f = 0; f + 1 < face_starts.size(); ++f) {
    const uint32_t* indices = face_indices.data() + face_starts[f];
    for (size_t k = 1; k + 1 < face_starts[f + 1] - face_starts[f]; ++k) {
      for (uint32_t index : {indices[0], indices[k], indices[k + 1]}) mesh.indices.push_back(index);
      face_of_triangle.push_back(f);
    }
  }
  if (mesh.indices.empty()) fail_file_content("the PLY file contains no triangles{}", describe_elements(header));
  for (const PropertyGroup& g : attribute_groups(*vertex)) {
    TriangleMesh::Attribute a{g.name, false, int(g.columns.size()), {}};
    for (size_t row = 0; row < vertex_count; ++row)
      for (size_t c : g.columns) a.values.push_back(at(row, c));
    mesh.attributes.push_back(std::move(a));
  }
  if (face)
    for (const PropertyGroup& g : attribute_groups(*face)) {
      TriangleMesh::Attribute a{g.name, true, int(g.columns.size()), {}};
      for (size_t f : face_of_triangle)
        for (size_t c : g.columns) a.values.push_back(float(face_values[f * face->properties.size() + c]));
      mesh.attributes.push_back(std::move(a));
    }
  return mesh;
}

}  // namespace

TriangleMesh load_ply(const std::string& original) {
  const PlyHeader original_header = read_ply_header(original);
  {
    const std::string_view data = std::string_view(original).substr(original_header.data_offset);
    check_ply_counts_fit_data(original_header, data);
    if (original_header.encoding == PlyEncoding::Ascii) check_ascii_ply_data(original_header, data);
    else check_binary_ply_data(original_header, data);
  }
  if (has_ply_attributes(original_header)) return load_ply_with_attributes(original, original_header);
  const bool has_strips = std::any_of(original_header.elements.begin(), original_header.elements.end(),
                                      [](const PlyElement& e) { return e.name == "tristrips" && e.count > 0; });
  const std::string rewritten = has_strips ? strips_as_faces(original, original_header) : std::string();
  const std::string& bytes = has_strips ? rewritten : original;
  const PlyHeader header = has_strips ? read_ply_header(bytes) : original_header;

  Assimp::Importer importer;
  if (!importer.ReadFileFromMemory(bytes.data(), bytes.size(), 0, "ply"))
    fail_file_content("malformed PLY: {}", printable(importer.GetErrorString(), 200));
  check_assimp_face_indices(*importer.GetScene());
  // No normal generation and no vertex joining: the mesh is exactly what the file holds.
  const aiScene* scene = importer.ApplyPostProcessing(aiProcess_Triangulate);
  if (!scene) fail_file_content("malformed PLY: {}", printable(importer.GetErrorString(), 200));

  bool with_normals = true, with_uvs = true, any_triangles = false;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& source = *scene->mMeshes[m];
    if (!has_triangles(source)) continue;
    any_triangles = true;
    with_normals = with_normals && source.HasNormals();
    with_uvs = with_uvs && source.HasTextureCoords(0);
  }
  if (!any_triangles) fail_file_content("the PLY file contains no triangles{}", describe_elements(header));

  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m)
    if (has_triangles(*scene->mMeshes[m])) append_assimp_mesh(*scene->mMeshes[m], with_normals, with_uvs, mesh);
  return mesh;
}

}  // namespace candela::mesh
