#include "candela/io/mesh/mesh_common.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <system_error>

#include "candela/base/error.h"

namespace candela::mesh {

std::string read_whole_file(const std::filesystem::path& file) {
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (status.type() == std::filesystem::file_type::not_found) fail_file_content("no such file");
  if (status.type() == std::filesystem::file_type::directory) fail_file_content("it is a directory, not a file");

  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, FileCloser> handle(std::fopen(file.c_str(), "rb"));
  if (!handle) fail_file_content("cannot open it: {}", std::strerror(errno));

  // Read in chunks rather than trusting a size from stat: works for pipes and files that change.
  std::string bytes;
  char chunk[1 << 16];
  size_t got = 0;
  while ((got = std::fread(chunk, 1, sizeof chunk, handle.get())) > 0) bytes.append(chunk, got);
  if (std::ferror(handle.get())) fail_file_content("read error: {}", std::strerror(errno));
  return bytes;
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  size_t at = 0;
  while (true) {
    at = line.find_first_not_of(" \t\r", at);
    if (at == std::string_view::npos) return words;
    const size_t end = std::min(line.find_first_of(" \t\r", at), line.size());
    words.push_back(line.substr(at, end - at));
    at = end;
  }
}

bool is_plain_number(std::string_view word) {
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  const size_t first_digit = !word.empty() && word.front() == '-' ? 1 : 0;
  if (word.size() <= first_digit || !(std::isdigit(static_cast<unsigned char>(word[first_digit])) || word[first_digit] == '.'))
    return false;
  double value = 0;
  const auto [stop, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  // Out of range (1e999) is still a number; it fails later as non-finite.
  return (error == std::errc() || error == std::errc::result_out_of_range) && stop == word.data() + word.size();
}

std::string printable(std::string_view text, size_t limit) {
  std::string shown;
  for (const char c : text.substr(0, limit)) shown += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (text.size() > limit) shown += "...";
  return shown;
}

namespace {
bool is_finite_uv(const Vec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); }
}  // namespace

void validate_mesh(const TriangleMesh& mesh) {
  if (mesh.indices.empty()) fail_file_content("the file contains no triangles");
  if (mesh.indices.size() % 3 != 0) fail_file_content("internal error: {} indices is not whole triangles", mesh.indices.size());
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
    fail_file_content("internal error: {} normals for {} vertices", mesh.normals.size(), mesh.positions.size());
  if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
    fail_file_content("internal error: {} uvs for {} vertices", mesh.uvs.size(), mesh.positions.size());
  for (size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= mesh.positions.size())
      fail_file_content("triangle {} refers to vertex {} but there are {} vertices", i / 3, mesh.indices[i], mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Point3& p = mesh.positions[i];
    if (!is_finite(p)) fail_file_content("vertex {} has a non-finite position ({}, {}, {})", i, p.x, p.y, p.z);
    if (!mesh.normals.empty() && !is_finite(mesh.normals[i]))
      fail_file_content("vertex {} has a non-finite normal ({}, {}, {})", i, mesh.normals[i].x, mesh.normals[i].y,
           mesh.normals[i].z);
    if (!mesh.uvs.empty() && !is_finite_uv(mesh.uvs[i]))
      fail_file_content("vertex {} has a non-finite texture coordinate ({}, {})", i, mesh.uvs[i].x, mesh.uvs[i].y);
  }
}

}  // namespace candela::mesh
