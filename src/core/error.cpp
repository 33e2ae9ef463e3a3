#include "core/error.h"

#include <algorithm>

namespace lc {

std::string escapeInput(std::string_view s, size_t maxLen) {
  static const char* hex = "0123456789abcdef";
  std::string out;
  size_t n = std::min(s.size(), maxLen);
  for (size_t i = 0; i < n; ++i) {
    unsigned char c = static_cast<unsigned char>(s[i]);
    if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c == '\r') out += "\\r";
    else if (c < 0x20 || c == 0x7f) {
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += char(c);
    }
  }
  if (s.size() > maxLen) out += "...";
  return out;
}

std::string quoteInput(std::string_view s, size_t maxLen) { return "'" + escapeInput(s, maxLen) + "'"; }

std::string SourceLoc::str() const {
  // Escaped, not shortened: the location must still name the file.
  std::string s = file.empty() ? std::string("<input>") : escapeInput(file, 4096);
  if (line > 0) {
    s += ":" + std::to_string(line);
    if (column > 0) s += ":" + std::to_string(column);
  }
  return s;
}

}  // namespace lc
