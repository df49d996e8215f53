#pragma once
/// \file
/// touchdown's exception types. Misuse and bad input throw one of these;
/// expected outcomes (no safe heading, pose not found, ...) are statuses in a
/// Result instead. Every message names the file, key or option at fault and
/// says what is wrong, on one line, so an app can print it as is.
#include <stdexcept>
#include <string>
#include <utility>

namespace touchdown {

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
