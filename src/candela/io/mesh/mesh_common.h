#pragma once
// What the mesh readers (mesh/obj.cpp, mesh/ply.cpp, mesh/serialized.cpp) share: reading a file whole,
// splitting a line into words, showing the file's words in messages, and the checks every loaded
// mesh passes. Problems are FileContentError (base/error.h); load_mesh_file adds the places.
#include <filesystem>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "candela/base/error.h"
#include "candela/description/scene_desc.h"

namespace candela::mesh {

std::string read_whole_file(const std::filesystem::path& file);

// Whitespace-separated words of one line (both OBJ and PLY headers are word based).
std::vector<std::string_view> split_words(std::string_view line);

// A decimal number, as both formats write them: no nan, inf or hexadecimal, nothing after it.
bool is_plain_number(std::string_view word);

// Words from the file for messages: non-printable bytes of a broken or binary file shown as '?'.
std::string printable(std::string_view text, size_t limit = 40);

// Every index in range, every position, normal and uv finite, at least one triangle.
void validate_mesh(const TriangleMesh& mesh);

// Runs `load` (reading `file`), turning a FileContentError, or running out of memory, into the
// SceneError "cannot read mesh 'file': ..." at `referenced_from`, the place that named the file.
template <class Load>
auto with_mesh_file_errors(const std::filesystem::path& file, const SourceLocation& referenced_from, Load&& load) {
  try {
    return load();
  } catch (const FileContentError& problem) {
    throw_scene_error(referenced_from, "cannot read mesh '{}': {}", file.string(), problem.what());
  } catch (const std::bad_alloc&) {
    throw_scene_error(referenced_from, "cannot read mesh '{}': out of memory", file.string());
  }
}

// Each format's reader of the file's bytes (no checks of the result: validate_mesh does those).
TriangleMesh load_obj(const std::string& text);
TriangleMesh load_ply(const std::string& bytes);
TriangleMesh load_serialized(std::string_view bytes, int shape_index);

}  // namespace candela::mesh
