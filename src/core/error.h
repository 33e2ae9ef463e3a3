// Errors that reach the user. Every input error carries a source location so the
// message reads "file:line:column: error: what was expected".
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace lc {

struct SourceLoc {
  std::string file;  // as the user named it (or the resolved path of an included file)
  int line = 0;      // 1-based; 0 = unknown
  int column = 0;    // 1-based; 0 = unknown
  std::string str() const;  // "file:line:column" (parts that are unknown are left out)
};

// A user-facing error: bad input, a missing file, a limit exceeded, an unwritable output.
// The CLI prints what() and exits with a non-zero status; nothing is written.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& msg) : std::runtime_error(msg) {}
  Error(const SourceLoc& loc, const std::string& msg)
      : std::runtime_error(loc.str() + ": error: " + msg), loc_(loc), bare_(msg) {}
  const SourceLoc& loc() const { return loc_; }
  // The message without its location prefix.
  const std::string& bare() const { return bare_.empty() ? bare_ = what() : bare_; }

 private:
  SourceLoc loc_;
  mutable std::string bare_;
};

// Input echoed in a message, made safe for a terminal and a one-line message: control
// characters escaped (\n, \t, \r, \x1b ...), at most `maxLen` bytes of the input kept (then
// "..."), in single quotes. quoteInput("a\x1bb") == "'a\\x1bb'". escapeInput: the same
// without the quotes (file names in locations).
std::string escapeInput(std::string_view s, size_t maxLen = 80);
std::string quoteInput(std::string_view s, size_t maxLen = 80);

// Thrown when a render is interrupted (SIGINT/SIGTERM).
class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

}  // namespace lc
