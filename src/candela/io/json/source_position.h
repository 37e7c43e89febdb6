#pragma once
// JSON pointers (RFC 6901) and where they are in the source text: nlohmann::json keeps no source
// positions, so errors, and the SourceLocation of each scene entry, are found by walking the text
// again (source_position.cpp).
#include <fmt/format.h>

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "candela/base/error.h"

namespace candela::json {

// RFC 6901: '~' and '/' inside a key are written "~0" and "~1".
std::string escape_pointer_token(std::string_view key);

std::string child_pointer(const std::string& parent, std::string_view key);
std::string child_pointer(const std::string& parent, size_t index);

struct TextPosition {
  int line = 1, column = 1;
};

// 1-based line and (byte) column of `offset` in `text`.
TextPosition position_of(std::string_view text, size_t offset);

// A key repeated within one object, which nlohmann would silently collapse to the last one.
struct DuplicateKey {
  std::string pointer;
  size_t offset;
};
std::optional<DuplicateKey> first_duplicate_key(std::string_view text);

// Builds the SourceLocation of a JSON pointer and throws the SceneError.
class ErrorReporter {
 public:
  ErrorReporter(std::string_view text, std::string file_name) : text_(text), file_name_(std::move(file_name)) {}

  const std::string& file_name() const { return file_name_; }

  SourceLocation location_of_offset(size_t offset, std::string pointer = {}) const;

  // The text is scanned again for each location needed (an error, or a mesh file that may report
  // one); the places of all entries are found together by locate().
  SourceLocation location(const std::string& pointer) const;

  // Fills in the line and column of each location's key_path (those of this file) in one walk over
  // the text that enters only the objects and arrays on the way to them: the places of a scene's
  // entries cost one pass however many there are, where location() per entry would rescan the text
  // for each.
  void locate(const std::vector<SourceLocation*>& locations) const;

  template <typename... Args>
  [[noreturn]] void fail(const std::string& pointer, fmt::format_string<Args...> format, Args&&... args) const {
    throw_scene_error(location(pointer), format, std::forward<Args>(args)...);
  }

 private:
  std::string_view text_;
  std::string file_name_;
};

}  // namespace candela::json
