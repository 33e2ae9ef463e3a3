#include "io/ray_lexer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace lc::io {
namespace {

// Tokens are views of the text they were read from: the texts lexed here are kept for the
// test's lifetime, as the parser keeps its file's while it parses.
std::vector<Token> lexAll(const std::string& text) {
  static std::vector<std::unique_ptr<std::string>> kept;
  kept.push_back(std::make_unique<std::string>(text));
  RayLexer lex(*kept.back(), "t.ray");
  std::vector<Token> out;
  for (;;) {
    Token t = lex.next();
    out.push_back(t);
    if (t.kind == TokenKind::End) return out;
  }
}

std::string lexError(const std::string& text) {
  try {
    lexAll(text);
  } catch (const Error& e) {
    return e.what();
  }
  return "<no error>";
}

TEST(RayLexer, TokensCarryLineAndColumn) {
  auto t = lexAll("camera {\n  position = (1, -2.5, +3e2);\n}");
  ASSERT_EQ(t.size(), 14u);
  EXPECT_EQ(t[0].kind, TokenKind::Ident);
  EXPECT_EQ(t[0].text, "camera");
  EXPECT_EQ(t[0].line, 1);
  EXPECT_EQ(t[0].column, 1);
  EXPECT_TRUE(t[1].isPunct('{'));
  EXPECT_EQ(t[1].column, 8);
  EXPECT_EQ(t[2].text, "position");
  EXPECT_EQ(t[2].line, 2);
  EXPECT_EQ(t[2].column, 3);
  EXPECT_TRUE(t[3].isPunct('='));
  EXPECT_EQ(t[3].column, 12);
  EXPECT_TRUE(t[4].isPunct('('));
  EXPECT_EQ(t[5].kind, TokenKind::Number);
  EXPECT_EQ(t[5].number, 1.0);
  EXPECT_EQ(t[5].column, 15);
  EXPECT_TRUE(t[6].isPunct(','));
  EXPECT_EQ(t[7].number, -2.5);
  EXPECT_EQ(t[7].text, "-2.5");
  EXPECT_EQ(t[7].column, 18);
  EXPECT_EQ(t[9].number, 300.0);
  EXPECT_EQ(t[9].text, "+3e2");
  EXPECT_EQ(t[9].column, 24);
  EXPECT_TRUE(t[10].isPunct(')'));
  EXPECT_TRUE(t[11].isPunct(';'));
  EXPECT_TRUE(t[12].isPunct('}'));
  EXPECT_EQ(t[12].line, 3);
  EXPECT_EQ(t[12].column, 1);
  EXPECT_EQ(t[13].kind, TokenKind::End);
}

TEST(RayLexer, AllPunctuation) {
  auto t = lexAll("(){},=;");
  ASSERT_EQ(t.size(), 8u);
  const char expected[] = "(){},=;";
  for (int i = 0; i < 7; ++i) {
    EXPECT_TRUE(t[size_t(i)].isPunct(expected[i])) << i;
    EXPECT_EQ(t[size_t(i)].column, i + 1);
  }
  EXPECT_EQ(t[7].kind, TokenKind::End);
  EXPECT_EQ(t[7].column, 8);
}

TEST(RayLexer, LineComments) {
  auto t = lexAll("a // comment ( { \"\n  b// another\nc");
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[0].text, "a");
  EXPECT_EQ(t[1].text, "b");
  EXPECT_EQ(t[1].line, 2);
  EXPECT_EQ(t[1].column, 3);
  EXPECT_EQ(t[2].text, "c");
  EXPECT_EQ(t[2].line, 3);
}

TEST(RayLexer, BlockCommentsSpanLines) {
  auto t = lexAll("a /* x\n y * / ** \n */ b /**/c/***/d");
  ASSERT_EQ(t.size(), 5u);
  EXPECT_EQ(t[1].text, "b");
  EXPECT_EQ(t[1].line, 3);
  EXPECT_EQ(t[1].column, 5);
  EXPECT_EQ(t[2].text, "c");
  EXPECT_EQ(t[3].text, "d");
}

TEST(RayLexer, BlockCommentsDoNotNest) {
  // The first */ ends the comment; the second is then a stray '*'.
  EXPECT_EQ(lexError("/* /* */ */"), "t.ray:1:10: error: unexpected character '*'");
}

TEST(RayLexer, UnterminatedCommentIsReportedAtItsStart) {
  EXPECT_EQ(lexError("a\n  b /* never\nclosed"), "t.ray:2:5: error: unterminated comment");
  EXPECT_EQ(lexError("/*"), "t.ray:1:1: error: unterminated comment");
}

TEST(RayLexer, QuotedStringsAreIdentifiers) {
  auto t = lexAll("name = \"my material\"; x = \"\"");
  ASSERT_EQ(t.size(), 8u);
  EXPECT_EQ(t[2].kind, TokenKind::Ident);
  EXPECT_TRUE(t[2].quoted);
  EXPECT_EQ(t[2].text, "my material");
  EXPECT_EQ(t[2].column, 8);
  EXPECT_EQ(t[6].kind, TokenKind::Ident);
  EXPECT_EQ(t[6].text, "");
  EXPECT_EQ(t[6].describe(), "string \"\"");
}

TEST(RayLexer, QuotedStringsAreNotAliased) {
  auto t = lexAll("colour \"colour\"");
  EXPECT_EQ(t[0].word, "color");
  EXPECT_EQ(t[1].word, "colour");
  EXPECT_FALSE(t[1].isWord("color"));
}

TEST(RayLexer, UnterminatedString) {
  EXPECT_EQ(lexError("x = \"abc"), "t.ray:1:5: error: unterminated string");
  EXPECT_EQ(lexError("x = \"abc\n\""), "t.ray:1:5: error: unterminated string");
}

TEST(RayLexer, Numbers) {
  auto t = lexAll("0 12 -3 +4 .5 -.25 1. 1e-5 2E+3 6.02e23 -0 1e-999");
  ASSERT_EQ(t.size(), 13u);
  const double want[] = {0, 12, -3, 4, 0.5, -0.25, 1, 1e-5, 2000, 6.02e23, -0.0, 0};
  for (int i = 0; i < 12; ++i) {
    EXPECT_EQ(t[size_t(i)].kind, TokenKind::Number) << i;
    EXPECT_EQ(t[size_t(i)].number, want[i]) << i;
  }
  EXPECT_TRUE(std::signbit(t[10].number));
  EXPECT_EQ(t[3].text, "+4");
}

TEST(RayLexer, NumberOverflowIsAnError) {
  EXPECT_EQ(lexError("x = (1, 1e999, 2)"), "t.ray:1:9: error: number '1e999' is out of range");
  EXPECT_EQ(lexError("-1e400"), "t.ray:1:1: error: number '-1e400' is out of range");
}

TEST(RayLexer, MalformedNumbers) {
  EXPECT_EQ(lexError("\n 1abc"), "t.ray:2:2: error: malformed number '1abc'");
  EXPECT_EQ(lexError("1.2.3"), "t.ray:1:1: error: malformed number '1.2.3'");
  EXPECT_EQ(lexError("1e"), "t.ray:1:1: error: malformed number '1e'");
  EXPECT_EQ(lexError("(3x)"), "t.ray:1:2: error: malformed number '3x'");
}

TEST(RayLexer, SignWithoutDigitsIsUnexpected) {
  EXPECT_EQ(lexError("a = - 1"), "t.ray:1:5: error: unexpected character '-'");
  EXPECT_EQ(lexError("+x"), "t.ray:1:1: error: unexpected character '+'");
}

TEST(RayLexer, IdentifiersWithDashesDigitsUnderscores) {
  auto t = lexAll("SBT-raytracer _a1-b2_ x9");
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[0].text, "SBT-raytracer");
  EXPECT_EQ(t[1].text, "_a1-b2_");
  EXPECT_EQ(t[2].text, "x9");
  // A dash cannot start an identifier but a number may follow one: "a -1" is two tokens.
  auto u = lexAll("a -1");
  EXPECT_EQ(u[1].kind, TokenKind::Number);
  EXPECT_EQ(u[1].number, -1);
}

TEST(RayLexer, Aliases) {
  auto t = lexAll("color colour trimesh polymesh quaternian quaternion texture_uv texcoords tex_coords diffuse");
  EXPECT_EQ(t[0].word, "color");
  EXPECT_EQ(t[1].word, "color");
  EXPECT_EQ(t[1].text, "colour");
  EXPECT_EQ(t[2].word, "trimesh");
  EXPECT_EQ(t[3].word, "trimesh");
  EXPECT_EQ(t[4].word, "quaternion");
  EXPECT_EQ(t[5].word, "quaternion");
  EXPECT_EQ(t[6].word, "texture_uv");
  EXPECT_EQ(t[7].word, "texture_uv");
  EXPECT_EQ(t[8].word, "texture_uv");
  EXPECT_EQ(t[9].word, "diffuse");
  EXPECT_EQ(canonicalKeyword("polymesh"), "trimesh");
  EXPECT_EQ(canonicalKeyword("sphere"), "sphere");
}

TEST(RayLexer, Booleans) {
  auto t = lexAll("true false \"true\" True");
  EXPECT_EQ(t[0].kind, TokenKind::Bool);
  EXPECT_TRUE(t[0].boolean);
  EXPECT_EQ(t[1].kind, TokenKind::Bool);
  EXPECT_FALSE(t[1].boolean);
  EXPECT_EQ(t[2].kind, TokenKind::Ident);  // quoted: a string
  EXPECT_EQ(t[3].kind, TokenKind::Ident);  // case-sensitive
}

TEST(RayLexer, UnexpectedCharacters) {
  EXPECT_EQ(lexError("a\n  @"), "t.ray:2:3: error: unexpected character '@'");
  EXPECT_EQ(lexError("a \x01"), "t.ray:1:3: error: unexpected character byte 0x01");
  EXPECT_EQ(lexError("[1]"), "t.ray:1:1: error: unexpected character '['");
  EXPECT_EQ(lexError("a / b"), "t.ray:1:3: error: unexpected character '/'");
}

TEST(RayLexer, CrLfAndTabs) {
  auto t = lexAll("a\r\n\tb\r\n  c");
  EXPECT_EQ(t[1].line, 2);
  EXPECT_EQ(t[1].column, 2);  // a tab is one column
  EXPECT_EQ(t[2].line, 3);
  EXPECT_EQ(t[2].column, 3);
}

TEST(RayLexer, ByteOrderMarkIsSkipped) {
  auto t = lexAll("\xEF\xBB\xBFSBT-raytracer 1.0");
  EXPECT_EQ(t[0].text, "SBT-raytracer");
  EXPECT_EQ(t[0].column, 1);
}

TEST(RayLexer, PeekDoesNotConsume) {
  RayLexer lex("a b", "t.ray");
  EXPECT_EQ(lex.peek().text, "a");
  EXPECT_EQ(lex.peek().text, "a");
  EXPECT_EQ(lex.next().text, "a");
  EXPECT_EQ(lex.next().text, "b");
  EXPECT_EQ(lex.next().kind, TokenKind::End);
  EXPECT_EQ(lex.next().kind, TokenKind::End);  // stays at the end
  EXPECT_EQ(lex.loc(Token{}).str(), "t.ray");
}

TEST(RayLexer, EndOfInputPosition) {
  auto t = lexAll("ab\n  ");
  EXPECT_EQ(t[1].kind, TokenKind::End);
  EXPECT_EQ(t[1].line, 2);
  EXPECT_EQ(t[1].column, 3);
  EXPECT_EQ(t[1].describe(), "end of file");
}

TEST(RayLexer, Describe) {
  auto t = lexAll("foo 1.50 ( \"s\" true");
  EXPECT_EQ(t[0].describe(), "'foo'");
  EXPECT_EQ(t[1].describe(), "number 1.50");
  EXPECT_EQ(t[2].describe(), "'('");
  EXPECT_EQ(t[3].describe(), "string \"s\"");
  EXPECT_EQ(t[4].describe(), "'true'");
}

}  // namespace
}  // namespace lc::io
