#pragma once
// The scene readers' warnings: what a reader (pbrt-v4, Mitsuba 3, glTF, OBJ + MTL) reads but
// approximates or ignores, one line each, "<place>: warning: <what>", the place as the format names
// it ("file:line:column", "file:line", "file: at /json/pointer"). A reader appends to the Warnings
// its caller gives it; the caller prints them (print: at most three of each kind, as the command line
// does) or hands them on (the Python module's load_file, whose package warns with each).
#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "candela/base/error.h"

namespace candela {

class Warnings {
 public:
  // Appends "<where>: warning: <message>".
  void warn(const SourceLocation& where, std::string_view message);
  void warn(std::string_view where, std::string_view message);
  // Appends a line as it is, for a warning that names no place of its own.
  void add_line(std::string line) { lines_.push_back(std::move(line)); }

  const std::vector<std::string>& lines() const { return lines_; }
  bool empty() const { return lines_.empty(); }
  size_t size() const { return lines_.size(); }
  const std::string& operator[](size_t i) const { return lines_[i]; }
  auto begin() const { return lines_.begin(); }
  auto end() const { return lines_.end(); }

  // Writes the lines to `out`, at most `per_kind` of each kind (the same text at different places),
  // followed by a count of those left out per kind: "(2 more warnings like \"...\")".
  void print(std::FILE* out = stderr, int per_kind = 3) const;

 private:
  std::vector<std::string> lines_;
};

// Calls read(warnings) with Warnings of its own and prints them to stderr, whether it returns or
// throws (the warnings before an error may explain it).
template <typename Read>
auto read_printing_warnings(Read&& read) {
  Warnings warnings;
  try {
    auto result = read(warnings);
    warnings.print();
    return result;
  } catch (...) {
    warnings.print();
    throw;
  }
}

}  // namespace candela
