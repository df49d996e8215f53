// json_int (src/core/json_read.hpp) against nlohmann's own parse of the
// same text: every JSON integer in int's range comes back exactly, every
// fraction, out-of-range number and non-number gives nothing, for both
// nlohmann::json and ordered_json.
#include "core/json_read.hpp"

#include <gtest/gtest.h>

#include <climits>
#include <string>

namespace {

using touchdown::detail::json_int;
using touchdown::detail::json_int_problem;

template <class Json>
class JsonInt : public ::testing::Test {};
using Types = ::testing::Types<nlohmann::json, nlohmann::ordered_json>;
TYPED_TEST_SUITE(JsonInt, Types);

TYPED_TEST(JsonInt, IntegersInRangeComeBackExactly) {
  for (const long long v : {0LL, 1LL, -1LL, 640LL, static_cast<long long>(INT_MAX), static_cast<long long>(INT_MIN)}) {
    const auto got = json_int(TypeParam::parse(std::to_string(v)));
    ASSERT_TRUE(got.has_value()) << v;
    EXPECT_EQ(*got, v);
  }
}

TYPED_TEST(JsonInt, OutOfRangeFractionsAndOtherTypesGiveNothing) {
  const struct {
    const char* text;
    const char* problem;
  } cases[] = {
      {"2147483648", "integer out of range"},
      {"-2147483649", "integer out of range"},
      {"18446744073709551615", "integer out of range"},
      {"144444444444444444444444444444444444444444441", "expected an integer, got a fraction"},  // parsed as a double
      {"1.5", "expected an integer, got a fraction"},
      {"8.0", "expected an integer, got a fraction"},
      {"1e3", "expected an integer, got a fraction"},
      {"\"8\"", "expected an integer, got string"},
      {"null", "expected an integer, got null"},
      {"true", "expected an integer, got boolean"},
      {"[8]", "expected an integer, got array"},
  };
  for (const auto& c : cases) {
    const auto j = TypeParam::parse(c.text);
    EXPECT_FALSE(json_int(j).has_value()) << c.text;
    EXPECT_EQ(json_int_problem(j), c.problem) << c.text;
  }
}

}  // namespace
