#include "io/ray_lexer.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace lc::io {

namespace {

bool isDigit(char c) { return c >= '0' && c <= '9'; }
bool isIdentStart(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool isIdentChar(char c) { return isIdentStart(c) || isDigit(c) || c == '-'; }

// A printable rendering of one input byte for "unexpected character" messages.
std::string showChar(char c) {
  unsigned char u = static_cast<unsigned char>(c);
  if (u >= 0x21 && u < 0x7f) return std::string("'") + c + "'";
  char buf[16];
  std::snprintf(buf, sizeof buf, "byte 0x%02X", u);
  return buf;
}

}  // namespace

std::string Token::describe() const {
  switch (kind) {
    case TokenKind::Ident:
      return quoted ? "string \"" + escapeInput(text) + "\"" : quoteInput(text);
    case TokenKind::Number:
      return "number " + std::string(text);
    case TokenKind::Bool:
      return quoteInput(text);
    case TokenKind::Punct:
      return std::string("'") + punct + "'";
    case TokenKind::End:
      break;
  }
  return "end of file";
}

std::string_view canonicalKeyword(std::string_view w) {
  if (w == "colour") return "color";
  if (w == "polymesh") return "trimesh";
  if (w == "quaternian") return "quaternion";
  if (w == "texcoords" || w == "tex_coords") return "texture_uv";
  return w;
}

RayLexer::RayLexer(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {
  // Editors on Windows may prepend a UTF-8 byte-order mark; it is not part of the text.
  if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;
}

void RayLexer::fail(int line, int column, const std::string& msg) const {
  throw Error(SourceLoc{file_, line, column}, msg);
}

void RayLexer::advance() {
  if (pos_ >= text_.size()) return;
  if (text_[pos_] == '\n') {
    ++line_;
    column_ = 1;
  } else {
    ++column_;
  }
  ++pos_;
}

void RayLexer::skipSpaceAndComments() {
  for (;;) {
    char c = at(pos_);
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v') {
      advance();
    } else if (c == '/' && at(pos_ + 1) == '/') {
      while (pos_ < text_.size() && text_[pos_] != '\n') advance();
    } else if (c == '/' && at(pos_ + 1) == '*') {
      // Block comments do not nest (C style); an unterminated one is reported at its start.
      int l = line_, col = column_;
      advance();
      advance();
      for (;;) {
        if (pos_ >= text_.size()) fail(l, col, "unterminated comment");
        if (text_[pos_] == '*' && at(pos_ + 1) == '/') {
          advance();
          advance();
          break;
        }
        advance();
      }
    } else {
      return;
    }
  }
}

void RayLexer::scan(Token& t) {
  skipSpaceAndComments();
  t = Token{};
  t.line = line_;
  t.column = column_;
  if (pos_ >= text_.size()) {
    t.kind = TokenKind::End;
    return;
  }
  char c = text_[pos_];
  switch (c) {
    case '(': case ')': case '{': case '}': case ',': case '=': case ';':
      t.kind = TokenKind::Punct;
      t.punct = c;
      advance();
      return;
    default:
      break;
  }

  if (c == '"') {
    // No escapes and no newlines: the course tokenizers had neither.
    advance();
    size_t start = pos_;
    while (pos_ < text_.size() && text_[pos_] != '"' && text_[pos_] != '\n') advance();
    if (pos_ >= text_.size() || text_[pos_] != '"') fail(t.line, t.column, "unterminated string");
    t.kind = TokenKind::Ident;
    t.quoted = true;
    t.text = text_.substr(start, pos_ - start);
    t.word = t.text;
    advance();
    return;
  }

  if (isIdentStart(c)) {
    size_t start = pos_;
    while (isIdentChar(at(pos_))) advance();
    t.text = text_.substr(start, pos_ - start);
    if (t.text == "true" || t.text == "false") {
      t.kind = TokenKind::Bool;
      t.boolean = t.text == "true";
      t.word = t.text;
    } else {
      t.kind = TokenKind::Ident;
      t.word = canonicalKeyword(t.text);
    }
    return;
  }

  // Numbers: [+-] digits [. digits] [(e|E) [+-] digits], or [+-] . digits ...
  bool signedStart = (c == '-' || c == '+');
  size_t p = pos_ + (signedStart ? 1 : 0);
  if (isDigit(at(p)) || (at(p) == '.' && isDigit(at(p + 1)))) {
    size_t start = pos_;
    while (isDigit(at(p))) ++p;
    if (at(p) == '.') {
      ++p;
      while (isDigit(at(p))) ++p;
    }
    if (at(p) == 'e' || at(p) == 'E') {
      size_t q = p + 1;
      if (at(q) == '+' || at(q) == '-') ++q;
      if (isDigit(at(q))) {
        while (isDigit(at(q))) ++q;
        p = q;
      }
    }
    // "1abc", "1e", "1.2.3": a number glued to more word characters is malformed.
    size_t end = p;
    while (isIdentStart(at(end)) || isDigit(at(end)) || at(end) == '.') ++end;
    const std::string_view spelled = text_.substr(start, end - start);
    if (end != p) fail(t.line, t.column, "malformed number " + quoteInput(spelled) + "");
    while (pos_ < p) advance();

    // from_chars is locale-independent but rejects a leading '+'.
    const char* b = spelled.data() + (spelled[0] == '+' ? 1 : 0);
    const char* e = spelled.data() + spelled.size();
    double v = 0;
    auto [ptr, ec] = std::from_chars(b, e, v);
    if (ec == std::errc::result_out_of_range) {
      // Overflow is an error; underflow reads as the nearest representable value.
      errno = 0;
      v = std::strtod(std::string(b, e).c_str(), nullptr);  // strtod reads to a terminator
      if (std::isinf(v)) fail(t.line, t.column, "number " + quoteInput(spelled) + " is out of range");
    } else if (ec != std::errc() || ptr != e) {
      fail(t.line, t.column, "malformed number " + quoteInput(spelled) + "");
    }
    t.kind = TokenKind::Number;
    t.text = spelled;
    t.number = v;
    return;
  }

  fail(t.line, t.column, "unexpected character " + showChar(c));
}

const Token& RayLexer::peek() {
  if (!haveAhead_) {
    scan(ahead_);
    haveAhead_ = true;
  }
  return ahead_;
}

Token RayLexer::next() {
  peek();
  haveAhead_ = false;
  return std::move(ahead_);
}

}  // namespace lc::io
