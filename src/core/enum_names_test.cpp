#include "core/enum_names.h"

#include <gtest/gtest.h>

namespace lc {
namespace {

enum class Fruit { Apple, Pear, Plum };
constexpr EnumName<Fruit> kFruitNames[] = {{Fruit::Pear, "pear", "the default"},
                                           {Fruit::Apple, "apple", "crisp"},
                                           {Fruit::Apple, "pomme"},  // an alias
                                           {Fruit::Plum, "plum"}};

TEST(EnumNames, NameIsAValuesFirstRow) {
  EXPECT_STREQ(enumName(kFruitNames, Fruit::Apple), "apple");
  EXPECT_STREQ(enumName(kFruitNames, Fruit::Plum), "plum");
  EXPECT_STREQ(enumName(kFruitNames, Fruit(7)), "?");
  static_assert(*findEnum(kFruitNames, "pear") == Fruit::Pear);  // usable at compile time
}

TEST(EnumNames, AliasesAreAcceptedButNeverListed) {
  EXPECT_EQ(findEnum(kFruitNames, "pomme"), Fruit::Apple);
  EXPECT_EQ(findEnum(kFruitNames, "Apple"), std::nullopt);  // names are case-sensitive
  EXPECT_EQ(findEnum(kFruitNames, ""), std::nullopt);
  EXPECT_EQ(enumSpellings(kFruitNames), (std::vector<std::string>{"pear", "apple", "pomme", "plum"}));
  EXPECT_EQ(enumChoices(kFruitNames), "pear, apple or plum");
  EXPECT_EQ(enumChoices(kFruitNames, "\""), "\"pear\", \"apple\" or \"plum\"");
  EXPECT_EQ(enumHelp(kFruitNames), "pear (the default), apple (crisp) or plum");
}

TEST(EnumNames, TwoAndOneNames) {
  enum class Two { A, B };
  constexpr EnumName<Two> two[] = {{Two::A, "a"}, {Two::B, "b", "bee"}};
  EXPECT_EQ(enumChoices(two), "a or b");
  EXPECT_EQ(enumHelp(two), "a or b (bee)");
  constexpr EnumName<Two> one[] = {{Two::A, "a"}};
  EXPECT_EQ(enumChoices(one), "a");
}

TEST(EnumNames, ParseNamesTheWordAndTheChoices) {
  EXPECT_EQ(parseEnum(kFruitNames, "pomme", "fruit"), Fruit::Apple);
  try {
    parseEnum(kFruitNames, "kiwi\x1b", "fruit");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "unknown fruit 'kiwi\\x1b' (use pear, apple or plum)");
  }
}

}  // namespace
}  // namespace lc
