// An option with named values has one table of names, beside its enum in the lowest layer
// that reads it: each value's name, the words the help gives it, and other spellings the
// command line accepts. Everything that spells the values reads that table: the enum's
// parse and name functions, the .ray parser and writer, the CLI's check and help
// (app/scene_options.h, addEnumOption), and the messages. Adding a value is one row.
//
//   inline constexpr EnumName<Method> kMethodNames[] = {
//       {Method::Lightcuts, "lightcuts", "Walter et al. 2005"},
//       {Method::Course, "seed", "the course project's cuts"},
//       {Method::Course, "course"},  // an alias: accepted, never listed
//       {Method::Brute, "brute"}};
//
// A value's first row holds its name (written out, listed in the help and in messages, in
// the table's order); a later row for the same value is an alias.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"

namespace lc {

template <typename E>
struct EnumName {
  E value;
  const char* name;
  const char* about = nullptr;  // the help's words: "name (about)"; none, just "name"
};

namespace detail {
// Whether row i is the first for its value (a name, not an alias).
template <typename E, size_t N>
constexpr bool isListed(const EnumName<E> (&names)[N], size_t i) {
  for (size_t j = 0; j < i; ++j)
    if (names[j].value == names[i].value) return false;
  return true;
}

// The listed rows, each made a string by `item`, joined "a, b or c".
template <typename E, size_t N, typename F>
std::string joinListed(const EnumName<E> (&names)[N], F item) {
  std::vector<std::string> listed;
  for (size_t i = 0; i < N; ++i)
    if (isListed(names, i)) listed.push_back(item(names[i]));
  std::string s;
  for (size_t i = 0; i < listed.size(); ++i)
    s += (i == 0 ? "" : i + 1 == listed.size() ? " or " : ", ") + listed[i];
  return s;
}
}  // namespace detail

// The name of `value` ("?" for a value the table lacks).
template <typename E, size_t N>
constexpr const char* enumName(const EnumName<E> (&names)[N], E value) {
  for (const EnumName<E>& n : names)
    if (n.value == value) return n.name;
  return "?";
}

// The value a name or alias spells; none for another word.
template <typename E, size_t N>
constexpr std::optional<E> findEnum(const EnumName<E> (&names)[N], std::string_view name) {
  for (const EnumName<E>& n : names)
    if (name == n.name) return n.value;
  return std::nullopt;
}

// Every spelling accepted, aliases too, in the table's order (the CLI's check).
template <typename E, size_t N>
std::vector<std::string> enumSpellings(const EnumName<E> (&names)[N]) {
  std::vector<std::string> out;
  for (const EnumName<E>& n : names) out.emplace_back(n.name);
  return out;
}

// The names, aliases left out, as "a, b or c", each in `quote` ("\"a\" or \"b\"").
template <typename E, size_t N>
std::string enumChoices(const EnumName<E> (&names)[N], const char* quote = "") {
  return detail::joinListed(names, [&](const EnumName<E>& n) { return quote + std::string(n.name) + quote; });
}

// The help's list: "a (about a), b (about b) or c".
template <typename E, size_t N>
std::string enumHelp(const EnumName<E> (&names)[N]) {
  return detail::joinListed(names, [](const EnumName<E>& n) {
    return n.about ? std::string(n.name) + " (" + n.about + ")" : std::string(n.name);
  });
}

// The value `name` spells; else lc::Error "unknown WHAT 'name' (use a, b or c)".
template <typename E, size_t N>
E parseEnum(const EnumName<E> (&names)[N], std::string_view name, const char* what) {
  if (std::optional<E> v = findEnum(names, name)) return *v;
  throw Error(std::string("unknown ") + what + " " + quoteInput(name) + " (use " + enumChoices(names) + ")");
}

}  // namespace lc
