#pragma once
// Every problem with user input is a SceneError whose message names the place:
//   "scene.pbrt:12:5: Shape \"sphere\": \"radius\" must be a positive float"
//   "scene.json: at /shapes/3/radius: expected a positive number, got -1"
#include <fmt/format.h>

#include <functional>
#include <stdexcept>
#include <string>

namespace candela {

struct SourceLocation {
  std::string file;      // as the user named it
  int line = 0;          // 1-based; 0 = unknown
  int column = 0;        // 1-based; 0 = unknown
  std::string key_path;  // JSON pointer for JSON scenes, e.g. /shapes/3/radius

  std::string to_string() const {
    std::string s = file.empty() ? "<input>" : file;
    if (line > 0) s += fmt::format(":{}", line);
    if (line > 0 && column > 0) s += fmt::format(":{}", column);
    if (!key_path.empty()) s += fmt::format(": at {}", key_path);
    return s;
  }
};

// Names the place of entry i of a description list (a texture, a material) in messages; empty
// = the entries' places are not known.
using EntryPlace = std::function<std::string(size_t index)>;

class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <typename... Args>
[[noreturn]] void throw_scene_error(const SourceLocation& where, fmt::format_string<Args...> format,
                                    Args&&... args) {
  throw SceneError(where.to_string() + ": " + fmt::format(format, std::forward<Args>(args)...));
}

// A problem found inside a data file (a mesh, a volume grid) by a reader that does not know which
// scene entry referenced the file: the caller adds that place and the file's name and throws a
// SceneError, so every failure reaches the user as one message.
class FileContentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <typename... Args>
[[noreturn]] void fail_file_content(fmt::format_string<Args...> format, Args&&... args) {
  throw FileContentError(fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace candela
