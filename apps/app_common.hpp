#pragma once
// Shared plumbing of the command-line apps: exit codes and error lines
// (DESIGN.md, app conventions): 0 success, 2 bad usage or input, 3 internal.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "core/format.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/version.hpp"

namespace touchdown::app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitInternal = 3;

/// Writes `text` to `path` (a StagedOutputs temporary); IoError naming
/// `what` when the write fails.
inline void write_text(const std::filesystem::path& path, const std::string& text, const std::string& what) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.flush();
  if (!out) throw touchdown::IoError(what + ": write failed");
}

/// An optional output option's path staged in `outputs` (checked now, before
/// any work); empty for an empty path.
inline std::filesystem::path stage(touchdown::StagedOutputs& outputs, const std::string& path,
                                   const std::string& option) {
  return path.empty() ? std::filesystem::path() : outputs.add(path, option);
}

/// Validator of an output path: it must end in `ext` (".svg", ".csv",
/// ".json"), so that a file named x.png never receives SVG text.
inline CLI::Validator output_extension(const std::string& ext) {
  return CLI::Validator(
      [ext](std::string& path) -> std::string {
        if (path.size() >= ext.size() && path.compare(path.size() - ext.size(), ext.size(), ext) == 0) return "";
        return "the file is written as " + ext.substr(1) + ": its name must end in " + ext + ", got " + path;
      },
      "*" + ext);
}

/// Validator of an option that names an enumerator of `E` (from_string):
/// --help lists the names; a bad name is refused naming the option and the
/// accepted names ("--agg: expected one of max, median; got 'mean'").
template <touchdown::NamedEnum E>
CLI::Validator one_of() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        try {
          (void)touchdown::from_string<E>(text);
          return "";
        } catch (const touchdown::InvalidArgument& e) {
          return e.what();
        }
      },
      "{" + touchdown::enum_names_list<E>() + "}");
}

/// Adds an option (or a positional, by its name) that sets `value` to the
/// enumerator it names; the default shown is `value`'s name.
template <touchdown::NamedEnum E>
CLI::Option* add_enum_option(CLI::App& app, const std::string& name, E& value, const std::string& description) {
  return app
      .add_option_function<std::string>(
          name, [&value](const std::string& text) { value = touchdown::from_string<E>(text); }, description)
      ->check(one_of<E>())
      ->default_str(std::string(touchdown::enum_name(value)));
}

/// As above, for a choice that may be left open: `open_name` ("any") leaves
/// `value` empty. --help lists the names and `open_name`; a bad name is
/// refused listing them ("--map: expected one of ground, lawn, any; got
/// 'moon'").
template <touchdown::NamedEnum E>
CLI::Option* add_enum_option(CLI::App& app, const std::string& name, std::optional<E>& value,
                             const std::string& open_name, const std::string& description) {
  const std::string names = touchdown::enum_names_list<E>() + ", " + open_name;
  return app
      .add_option_function<std::string>(
          name,
          [&value, open_name](const std::string& text) {
            value = text == open_name ? std::nullopt : std::optional<E>(touchdown::from_string<E>(text));
          },
          description)
      ->check(CLI::Validator(
          [names, open_name](std::string& text) -> std::string {
            try {
              if (text != open_name) (void)touchdown::from_string<E>(text);
              return "";
            } catch (const touchdown::InvalidArgument&) {
              return "expected one of " + names + "; got '" + text + "'";
            }
          },
          "{" + names + "}"))
      ->default_str(value ? std::string(touchdown::enum_name(*value)) : open_name);
}

/// Validator of a number option: finite and within [lo, hi] (`(` or `)`
/// with lo_open / hi_open). --help shows the range; a value outside it is
/// refused naming the option ("--slope: 95 is outside [0, 80)"). Vector
/// options check each element.
inline CLI::Validator number_in(double lo, double hi, bool lo_open = false, bool hi_open = false) {
  const std::string range = std::string(lo_open ? "(" : "[") + detail::format_general(lo) + ", " +
                            detail::format_general(hi) + (hi_open ? ")" : "]");
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return "";  // not a number: the option's own conversion says so
        const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
        return ok ? "" : text + " is outside " + range;
      },
      "in " + range);
}

/// Adds a random-seed option: a non-negative integer. CLI11 alone would
/// take "-1" for a std::uint64_t as 2^64 - 1; this refuses it
/// ("--seed: must be >= 0, got -1").
inline CLI::Option* add_seed_option(CLI::App& app, const std::string& name, std::uint64_t& seed,
                                    const std::string& description) {
  return app.add_option(name, seed, description)
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            const auto first = text.find_first_not_of(" \t");
            return first != std::string::npos && text[first] == '-' ? "must be >= 0, got " + text : "";
          },
          "integer >= 0"))
      ->capture_default_str();
}

// Numbers in summaries, tables and CSV columns: detail::format_fixed
// (core/format.hpp), as every app prints them.
using detail::format_fixed;

// "1 segment", "2 segments": a count and its noun in messages (core/format.hpp).
using detail::count_noun;

/// `v` rounded to 3 decimals for JSON output (no negative zero).
inline double round3(double v) { return std::round(v * 1e3) / 1e3 + 0.0; }

/// A memory or disk estimate for an error line: "0.22 GB", "3.5 GB", "106 GB".
inline std::string gigabytes(double bytes) {
  const double gb = bytes / 1e9;
  return (gb < 10 ? detail::format_general(gb, 2) : format_fixed(gb, 0)) + " GB";
}

/// A large count for an error line, three significant digits: "4.07e10", "1e10".
inline std::string large_count(double v) {
  if (!(v >= 1e6)) return format_fixed(v, 0);
  int exponent = static_cast<int>(std::floor(std::log10(v)));
  double mantissa = std::round(v / std::pow(10.0, exponent) * 100) / 100;
  if (mantissa >= 10) {  // 9.999e9 rounds to 10e9
    mantissa /= 10;
    ++exponent;
  }
  return detail::format_general(mantissa) + "e" + std::to_string(exponent);
}

/// One progress bar with an ETA on stderr, for work over about a second
/// (DESIGN.md). Draw it only when stderr is a terminal (`on_terminal()`);
/// close() the line before printing anything else.
class ProgressBar {
 public:
  void draw(std::size_t done, std::size_t total) {
    // The first call draws (a 0/total line shows the work has started).
    if (drawn_ && done != total && done < last_drawn_ + std::max<std::size_t>(1, total / 200)) return;
    drawn_ = true;
    last_drawn_ = done;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const int width = 40, filled = static_cast<int>(width * done / std::max<std::size_t>(1, total));
    std::cerr << "\r[" << std::string(static_cast<std::size_t>(filled), '#')
              << std::string(static_cast<std::size_t>(width - filled), '.') << "] " << done << "/" << total;
    if (done > 0 && done < total) {
      const double left = elapsed * static_cast<double>(total - done) / static_cast<double>(done);
      std::cerr << "  " << static_cast<long>(std::ceil(left)) << " s left ";
    } else {
      std::cerr << "  " << std::fixed << std::setprecision(1) << elapsed << " s      ";
    }
    std::cerr << std::flush;
    open_ = done != total;
    if (done == total) std::cerr << "\n";
  }

  void close() {
    if (open_) std::cerr << "\n";
    open_ = false;
  }

  [[nodiscard]] static bool on_terminal() { return isatty(STDERR_FILENO) != 0; }

 private:
  bool open_ = false, drawn_ = false;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::size_t last_drawn_ = 0;
};

/// Prints each warning of a loaded file (a reader's `warnings`) on stderr
/// as "APP: warning: FILE:LINE: key: ..."; the run continues.
inline void print_warnings(const std::string& app, const std::vector<std::string>& warnings) {
  for (const auto& w : warnings) std::cerr << app << ": warning: " << w << "\n";
}

/// Parses the command line and runs `body`, mapping exceptions to one line
/// on stderr and the conventional exit codes.
template <typename Body>
int run(CLI::App& app, int argc, char** argv, Body&& body) {
  app.set_version_flag("--version", "touchdown " + touchdown::version());
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << app.get_name() << ": " << e.what() << " (see --help)\n";
    return kExitBadInput;
  }
  try {
    return body();
  } catch (const touchdown::Error& e) {
    std::cerr << app.get_name() << ": " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << app.get_name() << ": internal error: " << e.what() << "\n";
    return kExitInternal;
  }
}

}  // namespace touchdown::app
