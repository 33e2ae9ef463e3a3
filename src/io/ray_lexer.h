// Tokenizer for the SBT .ray scene format (docs/SCENE_FORMAT.md, "Lexical rules").
// Tokens are produced on demand (one token of look-ahead), each with its 1-based line
// and column, so that every parse error can point at the exact place in the file.
#pragma once

#include <string>
#include <string_view>

#include "core/error.h"

namespace lc::io {

enum class TokenKind {
  Ident,   // identifier or quoted string ("..." reads as an identifier)
  Number,  // finite number; `text` keeps the spelling (integers are re-read from it)
  Bool,    // unquoted `true` / `false`
  Punct,   // one of ( ) { } , = ;
  End,     // end of input
};

struct Token {
  TokenKind kind = TokenKind::End;
  // Views into the lexer's text, which outlives the tokens, or for a folded alias a
  // literal: a token allocates nothing (a scene of 2M point lights has 50M of them).
  std::string_view text;  // as written (without the quotes of a string)
  std::string_view word;  // identifiers: the canonical spelling (aliases folded: colour -> color)
  bool quoted = false; // identifier came from "..."
  double number = 0;   // Number
  bool boolean = false;  // Bool
  char punct = 0;      // Punct
  int line = 0, column = 0;

  bool isPunct(char c) const { return kind == TokenKind::Punct && punct == c; }
  bool isWord(std::string_view w) const { return kind == TokenKind::Ident && word == w; }
  // "'foo'", "number 1.5", "'('", "string \"x\"", "end of file": the Y of "expected X, got Y".
  std::string describe() const;
};

// The canonical spelling of a keyword: `colour` -> `color`, `polymesh` -> `trimesh`,
// `quaternian` -> `quaternion`, `texcoords`/`tex_coords` -> `texture_uv`; others unchanged.
std::string_view canonicalKeyword(std::string_view word);

class RayLexer {
 public:
  // `text` must outlive the lexer; `file` names the input in error locations.
  RayLexer(std::string_view text, std::string file);

  // The next token without consuming it. Throws lc::Error on malformed input.
  const Token& peek();
  // Consumes and returns the next token.
  Token next();

  const std::string& file() const { return file_; }
  // How far the lexer has read, of how much text (the parser's progress).
  size_t offset() const { return pos_; }
  size_t size() const { return text_.size(); }
  SourceLoc loc(const Token& t) const { return SourceLoc{file_, t.line, t.column}; }
  SourceLoc loc(int line, int column) const { return SourceLoc{file_, line, column}; }

 private:
  void scan(Token& out);
  void skipSpaceAndComments();
  [[noreturn]] void fail(int line, int column, const std::string& msg) const;
  char at(size_t i) const { return i < text_.size() ? text_[i] : '\0'; }
  void advance();  // one character, tracking line/column

  std::string_view text_;
  std::string file_;
  size_t pos_ = 0;
  int line_ = 1, column_ = 1;
  Token ahead_;
  bool haveAhead_ = false;
};

}  // namespace lc::io
