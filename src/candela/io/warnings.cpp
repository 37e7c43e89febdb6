// The scene readers' warnings (warnings.h).
#include "candela/io/warnings.h"

#include <fmt/format.h>

#include <map>

namespace candela {

namespace {

constexpr std::string_view kMarker = ": warning: ";

}  // namespace

void Warnings::warn(const SourceLocation& where, std::string_view message) { warn(where.to_string(), message); }

void Warnings::warn(std::string_view where, std::string_view message) {
  lines_.push_back(fmt::format("{}{}{}", where, kMarker, message));
}

void Warnings::print(std::FILE* out, int per_kind) const {
  // A kind is the text after the place (a line without a place is a kind of its own).
  std::map<std::string, int> seen;
  for (const std::string& line : lines_) {
    const size_t text = line.find(kMarker);
    const std::string kind = text == std::string::npos ? line : line.substr(text);
    if (++seen[kind] <= per_kind) std::fprintf(out, "%s\n", line.c_str());
  }
  for (const auto& [kind, count] : seen) {
    if (count <= per_kind) continue;
    const std::string what = kind.starts_with(kMarker) ? kind.substr(kMarker.size()) : kind;
    std::fprintf(out, "(%d more warnings like \"%s\")\n", count - per_kind, what.c_str());
  }
}

}  // namespace candela
