#pragma once
// The first layer of the pbrt-v4 reader: pbrt text split into words, quoted strings and brackets,
// each knowing its file:line:column for messages.
#include <optional>
#include <string>
#include <string_view>

#include "candela/base/error.h"

namespace candela::pbrt {

SourceLocation location(const std::string& file, int line, int column);

enum class TokenKind { Word, String, OpenBracket, CloseBracket, End };

struct Token {
  TokenKind kind = TokenKind::End;
  std::string text;  // a word as written; a string without its quotes and with escapes decoded
  const std::string* file = nullptr;
  int line = 0;
  int column = 0;
};

SourceLocation at(const Token& token);

// How a token reads in an error message.
std::string describe(const Token& token);

// Splits pbrt text into words, quoted strings and brackets; '#' starts a comment to the end of the line.
class Tokenizer {
 public:
  Tokenizer(std::string text, std::string file_name);

  Token next();
  const Token& peek();

 private:
  bool at_end() const { return pos_ >= text_.size(); }
  char advance();
  void skip_space_and_comments();
  Token scan();
  void scan_string(Token& token);
  static char decode_escape(char c, const SourceLocation& where);

  std::string text_;
  std::string file_name_;
  size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;
  std::optional<Token> lookahead_;
};

// Numbers as pbrt writes them; rejects nan, inf and values beyond float range, which would only
// poison the renderer later.
std::optional<double> parse_number(std::string_view text);
std::optional<int> parse_integer(std::string_view text);

}  // namespace candela::pbrt
