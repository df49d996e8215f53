// The number-text styles of src/core/format.hpp: each against hand-written
// text and against what the code it replaced printed (ostream at precision 6
// or 17, std::fixed, printf), including -0, tiny and huge values, NaN,
// infinities, half-way rounding and trimming.
#include "core/format.hpp"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>

#include "touchdown/core/error.hpp"

namespace {

using touchdown::detail::count_noun;
using touchdown::detail::format_exact;
using touchdown::detail::format_fixed;
using touchdown::detail::format_general;
using touchdown::detail::format_trimmed;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// What the replaced formatters did: `ostream << v` at a precision, with or
// without std::fixed.
std::string stream_general(double v, int precision) {
  std::ostringstream os;
  os << std::setprecision(precision) << v;
  return os.str();
}
std::string stream_fixed(double v, int decimals) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(decimals) << v;
  return os.str();
}

// Values with every kind of text: integers, fractions, tiny, huge, halves.
std::vector<double> sample_values() {
  std::vector<double> v = {0.0,  1.0,   -1.0, 0.1,   -0.1,      0.5,   2.5,    0.125,     0.375, 2.675, 1.0 / 3,
                           1e-7, -1e-7, 1e21, -1e21, 123456789, 1e300, 5e-324, 9.9999995, 0.05,  359.95};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(-10, 10);
  std::uniform_int_distribution<int> exponent(-12, 12);
  for (int i = 0; i < 2000; ++i) v.push_back(mantissa(rng) * std::pow(10.0, exponent(rng)));
  return v;
}

TEST(FormatExact, ShortestTextThatReadsBack) {
  EXPECT_EQ(format_exact(0.1), "0.1");
  EXPECT_EQ(format_exact(2.0), "2");
  EXPECT_EQ(format_exact(-0.0), "-0");  // the sign is part of the value
  EXPECT_EQ(format_exact(1e-7), "1e-07");
  EXPECT_EQ(format_exact(1e21), "1e+21");
  EXPECT_EQ(format_exact(kNaN), "nan");
  EXPECT_EQ(format_exact(kInf), "inf");
  EXPECT_EQ(format_exact(-kInf), "-inf");
  for (const double v : sample_values()) {
    const std::string s = format_exact(v);
    double back = 0;
    std::from_chars(s.data(), s.data() + s.size(), back);
    EXPECT_EQ(back, v) << s;
    EXPECT_EQ(std::signbit(back), std::signbit(v)) << s;
  }
}

TEST(FormatExact, FloatIntoABuffer) {
  char buf[32];
  EXPECT_EQ(format_exact(0.1f, buf), "0.1");
  EXPECT_EQ(format_exact(-1.5f, buf), "-1.5");
  EXPECT_EQ(format_exact(3.4028235e38f, buf), "3.4028235e+38");
}

TEST(FormatGeneral, SixSignificantDigitsAsAStreamPrints) {
  EXPECT_EQ(format_general(0.1), "0.1");
  EXPECT_EQ(format_general(1.0 / 3), "0.333333");
  EXPECT_EQ(format_general(2.0), "2");
  EXPECT_EQ(format_general(1e-7), "1e-07");
  EXPECT_EQ(format_general(1e21), "1e+21");
  EXPECT_EQ(format_general(123456789), "1.23457e+08");
  EXPECT_EQ(format_general(0.0000125), "1.25e-05");
  EXPECT_EQ(format_general(kNaN), "nan");
  EXPECT_EQ(format_general(kInf), "inf");
  EXPECT_EQ(format_general(-kInf), "-inf");
  for (const double v : sample_values()) {
    EXPECT_EQ(format_general(v), stream_general(v, 6));
    EXPECT_EQ(format_general(v, 17), stream_general(v, 17));
  }
}

TEST(FormatGeneral, NegativeZeroPrintsAsZero) {
  EXPECT_EQ(format_general(-0.0), "0");
  EXPECT_EQ(format_general(-0.0, 17), "0");
  EXPECT_EQ(format_general(-1e-300), "-1e-300");  // not zero: keeps its sign
}

TEST(FormatGeneral, OtherPrecisions) {
  EXPECT_EQ(format_general(0.2222, 2), "0.22");
  EXPECT_EQ(format_general(123, 2), "1.2e+02");
  EXPECT_EQ(format_general(0.1, 17), "0.10000000000000001");
  EXPECT_EQ(format_general(2.5, 1), "2");  // half-way: to even
  EXPECT_EQ(format_general(3.5, 1), "4");
}

TEST(FormatFixed, PrintfDecimals) {
  EXPECT_EQ(format_fixed(2.5, 2), "2.50");
  EXPECT_EQ(format_fixed(2.0, 0), "2");
  EXPECT_EQ(format_fixed(1e-7, 3), "0.000");
  EXPECT_EQ(format_fixed(1e21, 0), "1000000000000000000000");
  EXPECT_EQ(format_fixed(kNaN, 2), "nan");
  EXPECT_EQ(format_fixed(kInf, 2), "inf");
  EXPECT_EQ(format_fixed(-kInf, 2), "-inf");
  // Half-way: the binary value decides; exact halves go to even.
  EXPECT_EQ(format_fixed(0.125, 2), "0.12");
  EXPECT_EQ(format_fixed(0.375, 2), "0.38");
  EXPECT_EQ(format_fixed(2.675, 2), "2.67");  // 2.67499999...
  EXPECT_EQ(format_fixed(0.5, 0), "0");
  EXPECT_EQ(format_fixed(1.5, 0), "2");
  for (const double v : sample_values()) {
    EXPECT_EQ(format_fixed(v, 3), stream_fixed(v, 3));
    EXPECT_EQ(format_fixed(v, 0), stream_fixed(v, 0));
  }
}

TEST(FormatFixed, KeepsTheSignOfAZeroAsPrintfDoes) {
  EXPECT_EQ(format_fixed(-0.0, 1), "-0.0");
  EXPECT_EQ(format_fixed(-0.001, 2), "-0.00");
  EXPECT_EQ(format_fixed(-0.0 + 0.0, 1), "0.0");  // the caller's way to a plain zero
}

TEST(FormatTrimmed, DropsTrailingZerosAndPoint) {
  EXPECT_EQ(format_trimmed(1.5, 3), "1.5");  // "1.500"
  EXPECT_EQ(format_trimmed(2.0, 3), "2");    // "2.000"
  EXPECT_EQ(format_trimmed(0.25, 3), "0.25");
  EXPECT_EQ(format_trimmed(100, 1), "100");  // zeros before the point stay
  EXPECT_EQ(format_trimmed(100, 0), "100");
  EXPECT_EQ(format_trimmed(1e21, 1), "1000000000000000000000");
  EXPECT_EQ(format_trimmed(1e-7, 7), "0.0000001");
  EXPECT_EQ(format_trimmed(1e-7, 3), "0");
  EXPECT_EQ(format_trimmed(0.25, 1), "0.2");  // exact half: to even
  EXPECT_EQ(format_trimmed(0.35, 1), "0.3");  // 0.34999999...
  EXPECT_EQ(format_trimmed(-1.25, 1), "-1.2");
  EXPECT_EQ(format_trimmed(kNaN, 1), "nan");
  EXPECT_EQ(format_trimmed(kInf, 1), "inf");
  EXPECT_EQ(format_trimmed(-kInf, 1), "-inf");
}

TEST(FormatTrimmed, NeverASignedZero) {
  EXPECT_EQ(format_trimmed(-0.0, 1), "0");
  EXPECT_EQ(format_trimmed(-0.0, 0), "0");
  EXPECT_EQ(format_trimmed(-0.04, 1), "0");
  EXPECT_EQ(format_trimmed(-0.4, 0), "0");
  EXPECT_EQ(format_trimmed(-0.06, 1), "-0.1");
}

TEST(FormatTrimmed, IsFixedWithoutTrailingZeros) {
  for (const double v : sample_values()) {
    std::string s = stream_fixed(v, 6);  // std::to_string's text, trimmed as render.cpp did
    while (s.size() > 1 && s.back() == '0') s.pop_back();
    if (!s.empty() && s.back() == '.') s.pop_back();
    if (s == "-0") s = "0";
    EXPECT_EQ(format_trimmed(v, 6), s);
  }
}

TEST(Format, RefusesPrecisionOutOfRange) {
  EXPECT_THROW((void)format_fixed(1, -1), touchdown::InvalidArgument);
  EXPECT_THROW((void)format_fixed(1, 18), touchdown::InvalidArgument);
  EXPECT_THROW((void)format_trimmed(1, 18), touchdown::InvalidArgument);
  EXPECT_THROW((void)format_general(1, 0), touchdown::InvalidArgument);
  EXPECT_THROW((void)format_general(1, 18), touchdown::InvalidArgument);
  EXPECT_EQ(format_fixed(1e308, 17).size(), 309u + 1 + 17);
}

TEST(CountNoun, SingularForOneOnly) {
  EXPECT_EQ(count_noun(1, "segment"), "1 segment");
  EXPECT_EQ(count_noun(0, "segment"), "0 segments");
  EXPECT_EQ(count_noun(2, "segment"), "2 segments");
  EXPECT_EQ(count_noun(-1, "run"), "-1 runs");
  EXPECT_EQ(count_noun(1, "moving object"), "1 moving object");
  EXPECT_EQ(count_noun(3, "child", "children"), "3 children");
  EXPECT_EQ(count_noun(1, "child", "children"), "1 child");
}

}  // namespace
