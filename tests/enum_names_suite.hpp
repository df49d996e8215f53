#pragma once
// The typed suite that every EnumNames specialisation of the library runs
// (core/enum_names.hpp; issue 54): each module's enum_names_test.cpp
// instantiates it over its enums with
//
//     INSTANTIATE_TYPED_TEST_SUITE_P(Module, EnumNamesSuite, ::testing::Types<...>);
//
// and `EnumNames.EverySpecialisationRunsTheTypedSuite` (tests/core/
// enum_names_test.cpp) fails when a specialisation in include/ or src/ is
// in no such list.
#include <gtest/gtest.h>

#include <cctype>
#include <string>
#include <string_view>

#include "test_util.hpp"
#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::test {

template <typename E>
class EnumNamesSuite : public ::testing::Test {};
TYPED_TEST_SUITE_P(EnumNamesSuite);

// from_string(to_string(e)) == e for every enumerator, the module's
// to_string agreeing with the table, no two enumerators with one name.
TYPED_TEST_P(EnumNamesSuite, EveryEnumeratorRoundTripsThroughItsName) {
  expect_names_round_trip<TypeParam>();
  EXPECT_FALSE(EnumNames<TypeParam>::names.empty());
}

// A name can be listed and quoted in the refusal message: no comma, quote
// or line break, no space at either end. (Statuses are named as messages
// print them, "tips over"; a name may be empty: UnsafeReason::None.)
TYPED_TEST_P(EnumNamesSuite, NamesCanBeListedAndQuoted) {
  for (const std::string_view n : EnumNames<TypeParam>::names) {
    EXPECT_EQ(n.find_first_of(",'\"\n\r\t"), std::string_view::npos) << "'" << n << "'";
    if (!n.empty()) {
      EXPECT_TRUE(n.front() != ' ' && n.back() != ' ') << "'" << n << "'";
    }
  }
}

// Anything else is refused with the one message that lists every accepted
// name: an empty name (unless one enumerator is named so), a name with a
// trailing space, a name in another case.
TYPED_TEST_P(EnumNamesSuite, AnyOtherNameIsRefusedListingTheAcceptedNames) {
  const auto& names = EnumNames<TypeParam>::names;
  const auto is_a_name = [&](std::string_view s) {
    for (const std::string_view n : names) {
      if (n == s) return true;
    }
    return false;
  };
  const std::string expected = "expected one of " + enum_names_list<TypeParam>() + "; got '";
  if (!is_a_name("")) expect_bad_name<TypeParam>("", expected + "'");
  for (const std::string_view n : names) {
    const std::string name(n);
    if (!is_a_name(name + " ")) expect_bad_name<TypeParam>(name + " ", expected + name + " '");
    std::string other_case = name;
    for (char& c : other_case) {
      const auto u = static_cast<unsigned char>(c);
      c = static_cast<char>(std::islower(u) ? std::toupper(u) : std::tolower(u));
    }
    if (!is_a_name(other_case)) expect_bad_name<TypeParam>(other_case, expected + other_case + "'");
  }
}

// A value outside the enumeration (a cast from a bad integer) reads
// "unknown", never out of bounds.
TYPED_TEST_P(EnumNamesSuite, AValueOutsideTheEnumerationIsUnknown) {
  const auto past_the_end = static_cast<TypeParam>(EnumNames<TypeParam>::names.size());
  EXPECT_EQ(enum_name(past_the_end), "unknown");
}

REGISTER_TYPED_TEST_SUITE_P(EnumNamesSuite, EveryEnumeratorRoundTripsThroughItsName, NamesCanBeListedAndQuoted,
                            AnyOtherNameIsRefusedListingTheAcceptedNames, AValueOutsideTheEnumerationIsUnknown);

}  // namespace touchdown::test
