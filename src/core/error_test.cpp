// quoteInput / escapeInput (issue 23: messages echoed raw input: 100 MB identifiers, ESC
// bytes and newlines reached the terminal).
#include "core/error.h"

#include <gtest/gtest.h>

namespace lc {
namespace {

TEST(QuoteInput, EscapesControlCharacters) {
  EXPECT_EQ(quoteInput("abc"), "'abc'");
  EXPECT_EQ(quoteInput("a\x1b[31mb"), "'a\\x1b[31mb'");
  EXPECT_EQ(quoteInput("line\nnext\ttab\r"), "'line\\nnext\\ttab\\r'");
  EXPECT_EQ(quoteInput(std::string("nul\0x", 5)), "'nul\\x00x'");
  EXPECT_EQ(quoteInput("\x7f"), "'\\x7f'");
  EXPECT_EQ(quoteInput("caf\xc3\xa9"), "'caf\xc3\xa9'");  // UTF-8 is left alone
}

TEST(QuoteInput, ShortensLongInput) {
  std::string big(100'000'000, 'x');
  std::string q = quoteInput(big);
  EXPECT_EQ(q, "'" + std::string(80, 'x') + "...'");
  EXPECT_EQ(quoteInput(std::string(80, 'y')), "'" + std::string(80, 'y') + "'");
}

TEST(QuoteInput, LocationsEscapeTheFileName) {
  SourceLoc loc{"a\nb.ray", 2, 3};
  EXPECT_EQ(loc.str(), "a\\nb.ray:2:3");
}

}  // namespace
}  // namespace lc
