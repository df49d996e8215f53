#pragma once
/// \file
/// touchdown's errors, in three tiers: internal invariants (TD_ASSERT,
/// TD_UNREACHABLE: a bug if broken); misuse and bad input (one of the
/// exception types below); expected outcomes (no safe heading, pose not
/// found, ...), which are statuses in a Result instead. Every message names the file, key or option at fault and
/// says what is wrong, on one line, so an app can print it as is.
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>

namespace touchdown {

/// \name Internal invariants
/// The first of the three tiers of errors (docs/architecture.md): a
/// condition that only a bug in touchdown can break — never bad input, never
/// an expected outcome. Checked in every build type (an invariant is cheap or
/// it does not belong in a hot loop); a broken one prints the condition and
/// where, then aborts, so a fuzzer or a test finds it at once.
/// @{
#define TD_ASSERT(condition) \
  ((condition) ? static_cast<void>(0) : ::touchdown::detail::invariant_broken(#condition, __FILE__, __LINE__))
/// Marks code that cannot be reached (a switch over every enumerator).
#define TD_UNREACHABLE() ::touchdown::detail::invariant_broken("unreachable code reached", __FILE__, __LINE__)
/// @}

namespace detail {
[[noreturn]] inline void invariant_broken(const char* what, const char* file, int line) {
  std::fprintf(stderr, "touchdown: internal error at %s:%d: %s\n", file, line, what);
  std::abort();
}
}  // namespace detail

/// Base of every exception touchdown throws on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A file could not be opened, read, written or renamed.
class IoError : public Error {
 public:
  using Error::Error;
};

/// A file's content is malformed (syntax, counts, truncation, values).
class ParseError : public Error {
 public:
  using Error::Error;
};

/// An option or configuration value is invalid.
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

/// The failing tail of every Options::validate(std::string* why): stores
/// `message` ("field: what is wrong") in *why when why is given, returns false.
inline bool invalid(std::string* why, std::string message) {
  if (why) *why = std::move(message);
  return false;
}

}  // namespace touchdown
