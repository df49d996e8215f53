#include "format.hpp"

#include <charconv>
#include <cstdio>

#include "touchdown/core/error.hpp"

namespace touchdown::detail {
namespace {

// printf with one double and a precision: the text of every %g and %f here.
// 17 digits of precision fit: the longest %f of a double is ~330 characters.
std::string printf_double(const char* format, int precision, double v) {
  if (precision < 0 || precision > 17) throw InvalidArgument("number format: precision must be in [0, 17]");
  char buf[400];
  const int n = std::snprintf(buf, sizeof buf, format, precision, v);
  return {buf, static_cast<std::size_t>(n)};
}

}  // namespace

std::string format_exact(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return {buf, static_cast<std::size_t>(r.ptr - buf)};
}

std::string_view format_exact(float v, char (&buf)[32]) {
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return {buf, static_cast<std::size_t>(r.ptr - buf)};
}

std::string format_general(double v, int significant) {
  if (significant < 1) throw InvalidArgument("number format: significant digits must be in [1, 17]");
  return printf_double("%.*g", significant, v + 0.0);
}

std::string format_fixed(double v, int decimals) { return printf_double("%.*f", decimals, v); }

std::string format_trimmed(double v, int decimals) {
  std::string s = printf_double("%.*f", decimals, v);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  return s == "-0" ? "0" : s;
}

std::string count_noun(long long n, std::string_view noun, std::string_view plural) {
  std::string s = std::to_string(n) + " ";
  if (n == 1) return s.append(noun);
  if (!plural.empty()) return s.append(plural);
  return s.append(noun).append("s");
}

}  // namespace touchdown::detail
