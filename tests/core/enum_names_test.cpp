#include "touchdown/core/enum_names.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <string_view>

#include "core/svg_plot.hpp"
#include "test_util.hpp"
#include "touchdown/core/cloud_io.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/mesh_io.hpp"

namespace touchdown_enum_names_test {
enum class Fruit { Apple, Pear, Quince };
}  // namespace touchdown_enum_names_test

template <>
struct touchdown::EnumNames<touchdown_enum_names_test::Fruit> {
  static constexpr std::array<std::string_view, 3> names{"apple", "pear", "quince"};
};

namespace touchdown {
namespace {

using touchdown_enum_names_test::Fruit;

TEST(EnumNames, EveryEnumeratorRoundTripsThroughItsName) {
  for (const Fruit f : {Fruit::Apple, Fruit::Pear, Fruit::Quince}) {
    EXPECT_EQ(from_string<Fruit>(enum_name(f)), f);
  }
  EXPECT_EQ(enum_name(Fruit::Pear), "pear");
  static_assert(enum_name(Fruit::Quince) == "quince");
}

TEST(EnumNames, AValueOutsideTheEnumerationIsUnknownNotAnOutOfBoundsRead) {
  EXPECT_EQ(enum_name(static_cast<Fruit>(3)), "unknown");
  EXPECT_EQ(enum_name(static_cast<Fruit>(-1)), "unknown");
}

TEST(EnumNames, AnUnknownNameThrowsInvalidArgumentListingTheAcceptedNames) {
  EXPECT_EQ(enum_names_list<Fruit>(), "apple, pear, quince");
  try {
    (void)from_string<Fruit>("Pear");  // case matters: files spell names one way
    FAIL() << "no exception";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(std::string(e.what()), "expected one of apple, pear, quince; got 'Pear'");
  }
  EXPECT_THROW((void)from_string<Fruit>(""), InvalidArgument);
  EXPECT_THROW((void)from_string<Fruit>("apple "), InvalidArgument);
}

TEST(EnumNames, EveryCoreEnumRoundTripsThroughItsName) {
  test::expect_names_round_trip<MeshFormat>();
  test::expect_names_round_trip<CloudFormat>();
  test::expect_names_round_trip<PcdEncoding>();
  test::expect_names_round_trip<PlyEncoding>();
  test::expect_names_round_trip<detail::SvgLegend::Flow>();
  // The names are the files' own spellings (PCD DATA, PLY format lines).
  EXPECT_EQ(to_string(PcdEncoding::BinaryCompressed), "binary_compressed");
  EXPECT_EQ(to_string(PlyEncoding::BinaryBigEndian), "binary_big_endian");
  test::expect_bad_name<PcdEncoding>("lz4", "expected one of ascii, binary, binary_compressed; got 'lz4'");
}

TEST(InternalInvariants, ABrokenAssertionAbortsNamingTheConditionAndWhere) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const int two = 2;
  EXPECT_DEATH(TD_ASSERT(two == 3), "internal error at .*enum_names_test.cpp:[0-9]+: two == 3");
  EXPECT_DEATH(TD_UNREACHABLE(), "internal error at .*: unreachable code reached");
  TD_ASSERT(two == 2);  // holds: no effect
}

}  // namespace
}  // namespace touchdown
