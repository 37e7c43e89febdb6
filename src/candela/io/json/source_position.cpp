#include "candela/io/json/source_position.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <set>
#include <unordered_map>
#include <unordered_set>

namespace candela::json {

std::string escape_pointer_token(std::string_view key) {
  std::string token;
  for (char c : key) {
    if (c == '~')
      token += "~0";
    else if (c == '/')
      token += "~1";
    else
      token += c;
  }
  return token;
}

std::string child_pointer(const std::string& parent, std::string_view key) {
  return parent + "/" + escape_pointer_token(key);
}

std::string child_pointer(const std::string& parent, size_t index) { return parent + "/" + std::to_string(index); }

TextPosition position_of(std::string_view text, size_t offset) {
  offset = std::min(offset, text.size());
  std::string_view before = text.substr(0, offset);
  size_t line_start = before.rfind('\n');
  int line = 1 + int(std::count(before.begin(), before.end(), '\n'));
  size_t column = line_start == std::string_view::npos ? offset + 1 : offset - line_start;
  return {line, int(column)};
}

namespace {

using Json = nlohmann::ordered_json;

// nlohmann::json keeps no source positions, so this walks the text (already validated by
// nlohmann) again: to find where the value at a JSON pointer starts, for messages, and to find keys
// repeated within one object, which nlohmann would silently collapse to the last one.
class SourceScanner {
 public:
  explicit SourceScanner(std::string_view text) : text_(text) {}

  // Offset of the value at `target`; for an object member, of its key.
  std::optional<size_t> offset_of(const std::string& target) {
    restart();
    if (target.empty()) {
      skip_whitespace();
      return pos_;
    }
    std::optional<size_t> found;
    std::string pointer;
    walk_value(pointer, [&](const std::string& entry, size_t offset) {
      if (entry == target) {
        found = offset;
        stop_ = true;
        return false;
      }
      return target.size() > entry.size() && target.starts_with(entry) && target[entry.size()] == '/';
    });
    return found;
  }

  // The offsets of several pointers (as offset_of finds each) in one walk, entering only the
  // objects and arrays on the way to one of them.
  std::unordered_map<std::string, size_t> offsets_of(const std::vector<std::string>& targets) {
    restart();
    std::unordered_map<std::string, size_t> found;
    std::unordered_set<std::string> wanted(targets.begin(), targets.end()), on_the_way;
    for (const std::string& target : targets)
      for (size_t slash = target.find('/', 1); slash != std::string::npos; slash = target.find('/', slash + 1))
        on_the_way.insert(target.substr(0, slash));
    if (wanted.erase("")) {
      skip_whitespace();
      found.emplace("", pos_);
      restart();
    }
    if (wanted.empty()) return found;
    std::string pointer;
    walk_value(pointer, [&](const std::string& entry, size_t offset) {
      if (wanted.count(entry) && found.emplace(entry, offset).second && found.size() == wanted.size() + found.count(""))
        stop_ = true;
      return !stop_ && on_the_way.count(entry) > 0;
    });
    return found;
  }

  struct Duplicate {
    std::string pointer;
    size_t offset;
  };
  std::optional<Duplicate> first_duplicate_key() {
    restart();
    check_duplicates_ = true;
    std::string pointer;
    walk_value(pointer, [](const std::string&, size_t) { return true; });
    return duplicate_;
  }

 private:
  // Deeper nesting is skipped without recursing, so hostile input cannot exhaust the stack.
  static constexpr int kMaxDepth = 256;

  void restart() {
    pos_ = text_.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // nlohmann accepts a UTF-8 byte order mark
    depth_ = 0;
    stop_ = false;
  }
  bool at(char c) const { return pos_ < text_.size() && text_[pos_] == c; }
  void skip_whitespace() {
    while (pos_ < text_.size() && std::string_view(" \t\r\n").find(text_[pos_]) != std::string_view::npos) ++pos_;
  }
  void skip_string() {
    ++pos_;  // opening quote
    while (pos_ < text_.size()) {
      char c = text_[pos_++];
      if (c == '\\')
        ++pos_;
      else if (c == '"')
        return;
    }
  }
  std::string read_string() {
    size_t start = pos_;
    skip_string();
    std::string_view raw = text_.substr(start, pos_ - start);
    if (raw.find('\\') == std::string_view::npos) return std::string(raw.substr(1, raw.size() - 2));
    return Json::parse(raw.begin(), raw.end()).get<std::string>();  // let nlohmann decode the escapes
  }
  void skip_scalar() {
    while (pos_ < text_.size() && std::string_view(",]} \t\r\n").find(text_[pos_]) == std::string_view::npos) ++pos_;
  }
  void skip_value() {
    skip_whitespace();
    if (at('"')) return skip_string();
    if (!at('{') && !at('[')) return skip_scalar();
    int depth = 0;
    while (pos_ < text_.size()) {
      char c = text_[pos_];
      if (c == '"') {
        skip_string();
        continue;
      }
      ++pos_;
      if (c == '{' || c == '[')
        ++depth;
      else if ((c == '}' || c == ']') && --depth == 0)
        return;
    }
  }

  // `enter(pointer, offset)` sees every member and element and says whether to walk into it.
  template <class Enter>
  void walk_value(std::string& pointer, const Enter& enter) {
    skip_whitespace();
    if (depth_ >= kMaxDepth || (!at('{') && !at('['))) return skip_value();
    ++depth_;
    if (at('{'))
      walk_object(pointer, enter);
    else
      walk_array(pointer, enter);
    --depth_;
  }

  // One member or element, named by `pointer` (its parent's pointer is `parent_length` long): walked
  // into if `enter` says so, else skipped; then the comma after it.
  template <class Enter>
  void walk_entry(std::string& pointer, size_t parent_length, size_t offset, const Enter& enter) {
    if (enter(pointer, offset))
      walk_value(pointer, enter);
    else
      skip_value();
    pointer.resize(parent_length);
    skip_whitespace();
    if (at(',')) ++pos_;
  }

  template <class Enter>
  void walk_object(std::string& pointer, const Enter& enter) {
    ++pos_;  // '{'
    std::set<std::string> keys;
    for (skip_whitespace(); !stop_ && pos_ < text_.size() && !at('}'); skip_whitespace()) {
      size_t key_offset = pos_;
      std::string key = read_string();
      skip_whitespace();
      ++pos_;  // ':'
      size_t parent_length = pointer.size();
      pointer += '/' + escape_pointer_token(key);
      if (check_duplicates_ && !keys.insert(key).second) {
        duplicate_ = Duplicate{pointer, key_offset};
        stop_ = true;
        return;
      }
      walk_entry(pointer, parent_length, key_offset, enter);
    }
    ++pos_;  // '}'
  }

  template <class Enter>
  void walk_array(std::string& pointer, const Enter& enter) {
    ++pos_;  // '['
    size_t index = 0;
    for (skip_whitespace(); !stop_ && pos_ < text_.size() && !at(']'); skip_whitespace(), ++index) {
      size_t parent_length = pointer.size();
      pointer += '/' + std::to_string(index);
      walk_entry(pointer, parent_length, pos_, enter);
    }
    ++pos_;  // ']'
  }

  std::string_view text_;
  size_t pos_ = 0;
  int depth_ = 0;
  bool stop_ = false;
  bool check_duplicates_ = false;
  std::optional<Duplicate> duplicate_;
};

}  // namespace

std::optional<DuplicateKey> first_duplicate_key(std::string_view text) {
  if (auto duplicate = SourceScanner(text).first_duplicate_key()) return DuplicateKey{duplicate->pointer, duplicate->offset};
  return std::nullopt;
}

SourceLocation ErrorReporter::location_of_offset(size_t offset, std::string pointer) const {
  TextPosition position = position_of(text_, offset);
  return {file_name_, position.line, position.column, std::move(pointer)};
}

SourceLocation ErrorReporter::location(const std::string& pointer) const {
  if (auto offset = SourceScanner(text_).offset_of(pointer)) return location_of_offset(*offset, pointer);
  return {file_name_, 0, 0, pointer};
}

void ErrorReporter::locate(const std::vector<SourceLocation*>& locations) const {
  std::vector<std::string> targets;
  for (const SourceLocation* where : locations)
    if (where->file == file_name_) targets.push_back(where->key_path);
  std::unordered_map<std::string, size_t> offsets = SourceScanner(text_).offsets_of(targets);
  // Offsets to lines and columns in one sweep over the text, in the order of the offsets.
  std::vector<std::pair<size_t, SourceLocation*>> found;
  for (SourceLocation* where : locations) {
    if (where->file != file_name_) continue;
    auto it = offsets.find(where->key_path);
    if (it != offsets.end()) found.emplace_back(it->second, where);
  }
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  size_t at = 0, line_start = 0;
  int line = 1;
  for (const auto& [offset, where] : found) {
    for (size_t end = std::min(offset, text_.size()); at < end; ++at)
      if (text_[at] == '\n') {
        ++line;
        line_start = at + 1;
      }
    where->line = line;
    where->column = int(std::min(offset, text_.size()) - line_start) + 1;
  }
}

}  // namespace candela::json
