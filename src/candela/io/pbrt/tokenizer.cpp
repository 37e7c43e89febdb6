#include "candela/io/pbrt/tokenizer.h"

#include <fmt/format.h>

#include <cfloat>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <utility>

namespace candela::pbrt {

SourceLocation location(const std::string& file, int line, int column) {
  SourceLocation where;
  where.file = file;
  where.line = line;
  where.column = column;
  return where;
}

SourceLocation at(const Token& token) { return location(*token.file, token.line, token.column); }

std::string describe(const Token& token) {
  switch (token.kind) {
    case TokenKind::Word: return token.text;
    case TokenKind::String: return fmt::format("\"{}\"", token.text);
    case TokenKind::OpenBracket: return "\"[\"";
    case TokenKind::CloseBracket: return "\"]\"";
    case TokenKind::End: break;
  }
  return "the end of the file";
}

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

}  // namespace

Tokenizer::Tokenizer(std::string text, std::string file_name)
    : text_(std::move(text)), file_name_(std::move(file_name)) {
  if (text_.starts_with("\xEF\xBB\xBF")) pos_ = 3;  // a UTF-8 byte-order mark some editors write
}

Token Tokenizer::next() {
  if (!lookahead_) return scan();
  Token token = std::move(*lookahead_);
  lookahead_.reset();
  return token;
}

const Token& Tokenizer::peek() {
  if (!lookahead_) lookahead_ = scan();
  return *lookahead_;
}

char Tokenizer::advance() {
  char c = text_[pos_++];
  if (c == '\n') {
    ++line_;
    column_ = 1;
  } else {
    ++column_;
  }
  return c;
}

void Tokenizer::skip_space_and_comments() {
  while (!at_end()) {
    char c = text_[pos_];
    if (is_space(c)) {
      advance();
    } else if (c == '#') {
      while (!at_end() && text_[pos_] != '\n') advance();
    } else {
      return;
    }
  }
}

Token Tokenizer::scan() {
  skip_space_and_comments();
  Token token;
  token.file = &file_name_;
  token.line = line_;
  token.column = column_;
  if (at_end()) return token;
  char c = text_[pos_];
  if (c == '[' || c == ']') {
    advance();
    token.kind = c == '[' ? TokenKind::OpenBracket : TokenKind::CloseBracket;
    token.text = c;
  } else if (c == '"') {
    scan_string(token);
  } else {
    size_t start = pos_;
    while (!at_end() && !is_space(text_[pos_]) && text_[pos_] != '"' && text_[pos_] != '[' &&
           text_[pos_] != ']')
      advance();
    token.kind = TokenKind::Word;
    token.text.assign(text_, start, pos_ - start);
  }
  return token;
}

// A string must close on the line it opens, as in pbrt: that catches a missing quote early.
void Tokenizer::scan_string(Token& token) {
  token.kind = TokenKind::String;
  advance();  // the opening quote
  while (true) {
    if (at_end() || text_[pos_] == '\n')
      throw_scene_error(at(token), "unterminated string: a string must end with '\"' on the line it starts");
    int escape_line = line_, escape_column = column_;
    char c = advance();
    if (c == '"') return;
    if (c != '\\') {
      token.text += c;
      continue;
    }
    if (at_end() || text_[pos_] == '\n')
      throw_scene_error(at(token), "unterminated string: a string must end with '\"' on the line it starts");
    token.text += decode_escape(advance(), location(file_name_, escape_line, escape_column));
  }
}

char Tokenizer::decode_escape(char c, const SourceLocation& where) {
  switch (c) {
    case 'b': return '\b';
    case 'f': return '\f';
    case 'n': return '\n';
    case 'r': return '\r';
    case 't': return '\t';
    case '\\': return '\\';
    case '\'': return '\'';
    case '"': return '"';
    default: break;
  }
  throw_scene_error(where, "unknown escape sequence '\\{}' in a string", c);
}

namespace {

// All of `text` read as one T (a leading '+' allowed, as pbrt's own parser does), or nothing.
template <typename T>
std::optional<T> read_whole(std::string_view text) {
  if (text.starts_with('+')) text.remove_prefix(1);
  if (text.empty() || text[0] == '+') return std::nullopt;
  T value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

}  // namespace

std::optional<double> parse_number(std::string_view text) {
  std::optional<double> value = read_whole<double>(text);
  if (!value || !std::isfinite(*value) || std::abs(*value) > FLT_MAX) return std::nullopt;
  return value;
}

std::optional<int> parse_integer(std::string_view text) {
  std::optional<int64_t> value = read_whole<int64_t>(text);
  if (!value || *value < INT_MIN || *value > INT_MAX) return std::nullopt;
  return static_cast<int>(*value);
}

}  // namespace candela::pbrt
