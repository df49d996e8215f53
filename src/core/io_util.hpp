#pragma once
// Internal helpers shared by the file parsers (not installed).
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <istream>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "format.hpp"  // format_exact: the number text of every writer
#include "touchdown/core/error.hpp"

namespace touchdown::detail {

[[noreturn]] inline void parse_fail(std::string_view source, const std::string& what) {
  throw ParseError(std::string(source) + ": " + what);
}

[[noreturn]] inline void parse_fail_line(std::string_view source, std::size_t line, const std::string& what) {
  throw ParseError(std::string(source) + ":" + std::to_string(line) + ": " + what);
}

inline std::string_view trim(std::string_view s) {
  const char* ws = " \t\r\n\v\f";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(ws);
  return s.substr(b, e - b + 1);
}

/// Splits on any of `separators`, skipping empty tokens.
inline void split(std::string_view s, std::vector<std::string_view>& out, std::string_view separators = " \t\r\n\v\f") {
  out.clear();
  std::size_t i = 0;
  while (i < s.size()) {
    const auto b = s.find_first_not_of(separators, i);
    if (b == std::string_view::npos) break;
    auto e = s.find_first_of(separators, b);
    if (e == std::string_view::npos) e = s.size();
    out.push_back(s.substr(b, e - b));
    i = e;
  }
}

/// Parses the whole token as a floating-point number ("nan" and "inf" too).
inline bool parse_double(std::string_view tok, double& value) {
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  if (tok.empty()) return false;
  const auto* end = tok.data() + tok.size();
  const auto r = std::from_chars(tok.data(), end, value);
  return r.ec == std::errc() && r.ptr == end;
}

template <typename Int>
inline bool parse_int(std::string_view tok, Int& value) {
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  if (tok.empty()) return false;
  const auto* end = tok.data() + tok.size();
  const auto r = std::from_chars(tok.data(), end, value);
  return r.ec == std::errc() && r.ptr == end;
}

/// Bytes left from the current position, or max() when the stream cannot seek.
inline std::uint64_t remaining_bytes(std::istream& in) {
  const auto here = in.tellg();
  if (here < 0) return std::numeric_limits<std::uint64_t>::max();
  in.seekg(0, std::ios::end);
  const auto end = in.tellg();
  in.seekg(here);
  if (end < here) return 0;
  return static_cast<std::uint64_t>(end - here);
}

/// Opens a regular file for binary reading or throws IoError naming it.
std::ifstream open_for_read(const std::filesystem::path& path);

/// The whole content of a file (IoError naming it when unreadable).
std::string read_text_file(const std::filesystem::path& path);

/// Writes `text` to `path` (binary, replacing what was there): the one
/// writer of a whole text or binary file. IoError "SHOWN: cannot write"
/// when it cannot be opened, "SHOWN: write failed" when a write fails;
/// SHOWN is `shown` (an option name, the file's place in a dataset, or the
/// final path of a staged temporary), `path` itself when empty.
void write_text_file(const std::filesystem::path& path, std::string_view text, const std::string& shown = {});

/// Reads one line (without '\n' or a trailing '\r'); false at end of stream.
inline bool read_line(std::istream& in, std::string& line) {
  if (!std::getline(in, line)) return false;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

}  // namespace touchdown::detail
