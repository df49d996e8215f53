#include "touchdown/core/enum_names.hpp"

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <string_view>

#include "core/svg_plot.hpp"
#include "enum_names_suite.hpp"
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

using CoreEnums = ::testing::Types<MeshFormat, CloudFormat, PcdEncoding, PlyEncoding, detail::SvgLegend::Flow>;

// The last name of each `EnumNames<X>` specialisation ("Shape" for
// Solid::Shape) in the sources under `dir`, or of each type in the
// `::testing::Types<...>` lists of the typed suite's instantiations.
std::set<std::string> last_names(const std::string& text) {
  static const std::regex kIdentifier(R"([A-Za-z_][A-Za-z0-9_]*(::[A-Za-z_][A-Za-z0-9_]*)*)");
  std::set<std::string> names;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), kIdentifier); it != std::sregex_iterator(); ++it) {
    const std::string name = it->str();
    const auto colon = name.rfind("::");
    names.insert(colon == std::string::npos ? name : name.substr(colon + 2));
  }
  return names;
}

std::string file_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Issue 54: a typed suite over every specialisation, not hand lists that
// miss a module. The specialisations are read from include/ and src/ (a
// line that opens `struct [touchdown::]EnumNames<X>`; comments skipped),
// the tested types from every tests/*/enum_names_test.cpp's Types<> list.
TEST(EnumNames, EverySpecialisationRunsTheTypedSuite) {
  namespace fs = std::filesystem;
  const fs::path root = TOUCHDOWN_SOURCE_DIR;
  const std::regex opens(R"(^\s*struct\s+(touchdown::)?EnumNames<\s*([A-Za-z_][A-Za-z0-9_:]*)\s*>)");
  std::set<std::string> specialised;
  for (const char* dir : {"include", "src"}) {
    for (const auto& entry : fs::recursive_directory_iterator(root / dir)) {
      const std::string ext = entry.path().extension().string();
      if (!entry.is_regular_file() || (ext != ".hpp" && ext != ".cpp")) continue;
      std::istringstream lines(file_text(entry.path()));
      std::smatch m;
      for (std::string line; std::getline(lines, line);) {
        if (line.find("EnumNames<") == std::string::npos || !std::regex_search(line, m, opens)) continue;
        const std::set<std::string> one = last_names(m[2].str());
        specialised.insert(*one.begin());
      }
    }
  }
  std::set<std::string> tested;
  const std::regex instantiation(R"(using\s+\w+\s*=\s*::testing::Types<([^;]*)>;)");
  for (const auto& entry : fs::directory_iterator(root / "tests")) {
    const fs::path file = entry.path() / "enum_names_test.cpp";
    if (!entry.is_directory() || !fs::exists(file)) continue;
    const std::string text = file_text(file);
    ASSERT_NE(text.find("INSTANTIATE_TYPED_TEST_SUITE_P"), std::string::npos) << file;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), instantiation); it != std::sregex_iterator(); ++it) {
      const std::set<std::string> names = last_names((*it)[1].str());
      tested.insert(names.begin(), names.end());
    }
  }
  // The scan found the library's specialisations (47 on 2026-12-04), not none.
  EXPECT_GE(specialised.size(), 40U);
  for (const std::string& name : specialised) {
    EXPECT_TRUE(tested.count(name) == 1) << "EnumNames<" << name
                                         << "> is in no typed-suite list of tests/*/enum_names_test.cpp";
  }
}

TEST(EnumNames, CoreNamesAreTheFilesSpellings) {
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

// The typed suite is declared in touchdown::test; its instantiation must
// name it there (gtest pastes the suite's name into its own identifiers).
namespace touchdown::test {
INSTANTIATE_TYPED_TEST_SUITE_P(Core, EnumNamesSuite, CoreEnums);
}  // namespace touchdown::test
