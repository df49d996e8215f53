#pragma once
// Shared plumbing of the command-line apps: exit codes and error lines
// (docs/architecture.md, "Conventions": apps): 0 success, 2 bad usage or input, 3 internal.
#include <pthread.h>
#include <signal.h>
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
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/format.hpp"
#include "core/io_util.hpp"
#include "core/json_number.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/child_processes.hpp"
#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/core/version.hpp"

namespace touchdown::app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitInternal = 3;

/// Writes `text` to `path` (a StagedOutputs temporary); IoError naming
/// `what` (the option or final path) when the write fails.
inline void write_text(const std::filesystem::path& path, const std::string& text, const std::string& what) {
  touchdown::detail::write_text_file(path, text, what);
}

/// An optional output option's path staged in `outputs` (checked now, before
/// any work); empty for an empty path.
inline std::filesystem::path stage(touchdown::StagedOutputs& outputs, const std::string& path,
                                   const std::string& option) {
  return path.empty() ? std::filesystem::path() : outputs.add(path, option);
}

/// An output directory that the app creates (a results directory, a
/// dataset): its parent must exist, as every output file's directory must
/// (an app does not create missing parents, so a mistyped path fails
/// before any work). IoError: "--out a/b/c: output directory 'a/b' does
/// not exist".
inline void require_parent_directory(const std::string& path, const std::string& option) {
  const std::filesystem::path parent = std::filesystem::absolute(path).parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(parent, ec)) {
    const std::filesystem::path shown = std::filesystem::path(path).has_parent_path()
                                            ? std::filesystem::path(path).parent_path()
                                            : std::filesystem::path(".");
    throw touchdown::IoError(option + " " + path + ": output directory '" + shown.string() + "' does not exist");
  }
}

/// Validator of an input file (CLI11's ExistingFile, with the message
/// every reader of the library gives: "PATH: cannot open: no such file",
/// "... is a directory"), so a missing file reads the same whether an
/// option's check or a parser finds it.
inline CLI::Validator existing_file() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        std::error_code ec;
        const auto status = std::filesystem::status(path, ec);
        if (ec || !std::filesystem::exists(status)) return path + ": cannot open: no such file";
        if (std::filesystem::is_directory(status)) return path + ": cannot open: is a directory";
        return "";
      },
      "FILE");
}

/// Validator of an input directory, in the same words.
inline CLI::Validator existing_directory() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        std::error_code ec;
        const auto status = std::filesystem::status(path, ec);
        if (ec || !std::filesystem::exists(status)) return path + ": cannot open: no such directory";
        if (!std::filesystem::is_directory(status)) return path + ": not a directory";
        return "";
      },
      "DIR");
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

/// Validator of a name from a registry's list (core/registry.hpp): a bad
/// one is refused listing them, in the style of the enum options
/// ("--perception: expected one of model, render; got 'sonar'").
inline CLI::Validator one_of_names(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return CLI::Validator(
      [names, list](std::string& text) -> std::string {
        if (std::find(names.begin(), names.end(), text) != names.end()) return "";
        return "expected one of " + list + "; got '" + text + "'";
      },
      "{" + list + "}");
}

/// Outputs larger than this get a warning with their size (issue 58: a
/// 638 MB STL from --cell 0.001 came without a word).
inline constexpr double kLargeOutputBytes = 100e6;

/// "--output out.stl: 638 MB written; HINT" when `written` (the staged
/// file) exceeds `limit` bytes; "" otherwise.
inline std::string large_output_warning(const std::string& label, const std::string& target,
                                        const std::filesystem::path& written, const std::string& hint,
                                        double limit = kLargeOutputBytes) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(written, ec);
  if (ec || static_cast<double>(bytes) <= limit) return "";
  return label + " " + target + ": " + detail::format_general(static_cast<double>(bytes) / 1e6, 3) + " MB written" +
         (hint.empty() ? "" : "; " + hint);
}

/// Warnings found while the command line was parsed (values that parse
/// but look wrong); run() prints them once the whole line has parsed, so a
/// command refused for another reason still prints one line.
inline std::vector<std::string>& parse_warnings() {
  static std::vector<std::string> warnings;
  return warnings;
}

/// Check of an angle option in degrees (not a sigma): a value that looks
/// like radians (touchdown::look_like_radians, the rule of the files'
/// rpy_deg) is taken as given, with a warning: "--yaw-max 3.14 looks like
/// radians (within +-2 pi, not a whole degree) but is read as degrees; if
/// radians were meant, write 179.91".
inline CLI::Validator degrees_not_radians(const std::string& option) {
  return CLI::Validator(
      [option](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !touchdown::look_like_radians({v})) return "";
        parse_warnings().push_back(option + " " + text +
                                   " looks like radians (within +-2 pi, not a whole degree) but is read as degrees; "
                                   "if radians were meant, write " +
                                   detail::format_general(std::round(touchdown::rad_to_deg(v) * 100) / 100));
        return "";
      },
      "");
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

// Figures in JSON output: 3 decimals, no negative zero (core/json_number.hpp).
using detail::round3;

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
/// (docs/architecture.md, "Conventions": apps). Draw it only when stderr is a terminal (`on_terminal()`);
/// close() the line before printing anything else.
/// A duration for people: "45 s", "12 min", "3.5 h".
inline std::string duration_text(double seconds) {
  // Two significant digits below 10, whole units from 10 (never "1e+02 s").
  const auto digits = [](double v) {
    return v < 9.5 ? touchdown::detail::format_general(v, 2) : touchdown::detail::format_fixed(v, 0);
  };
  if (seconds < 120) return digits(seconds) + " s";
  if (seconds < 7200) return digits(seconds / 60) + " min";
  return digits(seconds / 3600) + " h";
}

/// Progress of long work on stderr. On a terminal, a bar with the time
/// left, redrawn in place. Off one (a log file, CI, nohup) nothing for work
/// that ends within a minute; for longer work one line with the estimate
/// after the first 5 s, then a line every ~10 s, and one at
/// the end (issue 58 item 3): "landing_mission: about 9.5 min for 1000
/// missions (from the first 9 in 5.1 s)"; TOUCHDOWN_PROGRESS=off silences
/// both. The first draw() sets the
/// baseline, so work resumed at done = k estimates from what this run did.
/// Off a terminal: work that takes longer than `long_work_s` gets
/// progress lines, one every `every_s` (tests scale them down).
struct ProgressPacing {
  double long_work_s = 60, every_s = 10;
  double estimate_after_s = 5;  ///< the pace of the first seconds (a start-up) is no estimate
};

class ProgressBar {
 public:
  /// `app` prefixes the lines off a terminal; `unit` names what is counted
  /// ("missions", "scenarios"; empty: none).
  explicit ProgressBar(std::string app = "", std::string unit = "", bool terminal = on_terminal(),
                       std::ostream& out = std::cerr, ProgressPacing pacing = ProgressPacing())
      : app_(std::move(app)), unit_(std::move(unit)), terminal_(terminal), out_(&out), pacing_(pacing) {
    // TOUCHDOWN_PROGRESS=off: neither a bar nor lines (logs that keep only
    // results; the README's checked examples).
    const char* env = std::getenv("TOUCHDOWN_PROGRESS");
    off_ = env != nullptr && std::string(env) == "off";
  }

  void draw(std::size_t done, std::size_t total, const std::string& detail = "") {
    if (off_) return;
    if (!baseline_) baseline_ = done;
    if (terminal_) {
      draw_bar(done, total, detail);
    } else {
      report(done, total, detail);
    }
  }

  void close() {
    if (open_) *out_ << "\n";
    open_ = false;
  }

  [[nodiscard]] static bool on_terminal() { return isatty(STDERR_FILENO) != 0; }

 private:
  using Clock = std::chrono::steady_clock;

  [[nodiscard]] double elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  // Seconds left from the pace since the baseline; negative: not known yet.
  [[nodiscard]] double left(std::size_t done, std::size_t total) const {
    const std::size_t base = baseline_.value_or(0);
    if (done <= base || done >= total) return -1;
    return elapsed() * static_cast<double>(total - done) / static_cast<double>(done - base);
  }

  [[nodiscard]] std::string counted(std::size_t n) const {
    return std::to_string(n) + (unit_.empty() ? "" : " " + unit_);
  }

  void draw_bar(std::size_t done, std::size_t total, const std::string& detail) {
    // The first call draws (a 0/total line shows the work has started).
    if (drawn_ && done != total && done < last_drawn_ + std::max<std::size_t>(1, total / 200) && detail == detail_) {
      return;
    }
    drawn_ = true;
    last_drawn_ = done;
    detail_ = detail;
    const int width = 40, filled = static_cast<int>(width * done / std::max<std::size_t>(1, total));
    *out_ << "\r[" << std::string(static_cast<std::size_t>(filled), '#')
          << std::string(static_cast<std::size_t>(width - filled), '.') << "] " << done << "/" << total;
    if (!detail.empty()) *out_ << "  " << detail;
    if (const double l = left(done, total); l >= 0) {
      *out_ << "  " << duration_text(std::ceil(l)) << " left ";
    } else if (done == total) {
      *out_ << "  " << duration_text(elapsed()) << "      ";
    }
    *out_ << std::flush;
    open_ = done != total;
    if (done == total) *out_ << "\n";
  }

  void report(std::size_t done, std::size_t total, const std::string& detail) {
    const std::string prefix = app_.empty() ? "" : app_ + ": ";
    const std::string extra = detail.empty() ? "" : " · " + detail;
    if (done >= total) {
      if (lines_ > 0) *out_ << prefix << counted(done) << " in " << duration_text(elapsed()) << extra << "\n";
      lines_ = 0;
      return;
    }
    const double l = left(done, total);
    if (l < 0) return;
    // The estimate after a few seconds and two pieces: the first pieces
    // carry the start-up, and on two threads the first one done alone
    // would double it (one piece is enough after six times as long).
    if (!estimated_ &&
        (elapsed() < pacing_.estimate_after_s || (done - *baseline_ < 2 && elapsed() < 6 * pacing_.estimate_after_s))) {
      return;
    }
    if (!estimated_) {
      estimated_ = true;
      if (elapsed() + l < pacing_.long_work_s) return;  // short work: no lines
      *out_ << prefix << "about " << duration_text(elapsed() + l) << " for " << counted(total - *baseline_)
            << " (from the first " << done - *baseline_ << " in " << duration_text(elapsed()) << ")" << extra << "\n";
      ++lines_;
      last_line_ = Clock::now();
      return;
    }
    if (lines_ == 0 || std::chrono::duration<double>(Clock::now() - last_line_).count() < pacing_.every_s) return;
    *out_ << prefix << done << "/" << counted(total) << " ("
          << touchdown::detail::format_fixed(100.0 * static_cast<double>(done) / static_cast<double>(total), 1)
          << " %), " << duration_text(elapsed()) << ", about " << duration_text(l) << " left" << extra << "\n";
    ++lines_;
    last_line_ = Clock::now();
  }

  std::string app_, unit_, detail_;
  bool terminal_;
  std::ostream* out_;
  ProgressPacing pacing_;
  bool open_ = false, drawn_ = false, estimated_ = false, off_ = false;
  int lines_ = 0;
  std::optional<std::size_t> baseline_;
  const Clock::time_point start_ = Clock::now();
  Clock::time_point last_line_ = start_;
  std::size_t last_drawn_ = 0;
};

/// Prints each warning of a loaded file (a reader's `warnings`) on stderr
/// as "APP: warning: FILE:LINE: key: ..."; the run continues.
inline void print_warnings(const std::string& app, const std::vector<std::string>& warnings) {
  for (const auto& w : warnings) std::cerr << app << ": warning: " << w << "\n";
}

/// Levenshtein's edit distance (insertions, deletions, substitutions), by
/// the two-row dynamic programme of Wagner and Fischer (1974).
inline std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

/// For an "argument was not expected" error: " (did you mean --extrinsics?)"
/// when an unexpected `--word` is within a few edits of one option of the
/// command (or of the subcommand it ran) and nearer to it than to any
/// other; empty otherwise.
inline std::string option_suggestion(const CLI::App& app, const std::string& message) {
  std::vector<std::string> names;
  std::vector<const CLI::App*> apps{&app};
  for (std::size_t k = 0; k < apps.size(); ++k) {
    for (const CLI::Option* o : apps[k]->get_options()) {
      for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
    }
    for (const CLI::App* s : apps[k]->get_subcommands()) apps.push_back(s);  // the parsed ones
  }
  std::string out;
  std::size_t start = message.find(": ");
  while (start != std::string::npos && start < message.size()) {
    start = message.find_first_not_of(": ", start);
    if (start == std::string::npos) break;
    const std::size_t end = std::min(message.find(' ', start), message.size());
    std::string word = message.substr(start, end - start);
    start = end;
    if (word.rfind("--", 0) != 0) continue;
    word = word.substr(0, word.find('='));
    const std::size_t limit = std::max<std::size_t>(1, (word.size() - 2) / 4);
    std::string best;
    std::size_t best_d = limit + 1;
    bool tie = false;
    for (const std::string& n : names) {
      const std::size_t d = edit_distance(word, n);
      if (d < best_d) {
        best = n;
        best_d = d;
        tie = false;
      } else if (d == best_d && n != best) {
        tie = true;
      }
    }
    if (!best.empty() && !tie && best != word) out += (out.empty() ? " (did you mean " : ", ") + best;
  }
  return out.empty() ? out : out + "?)";
}

/// Ctrl-C, kill and a closed terminal: SIGINT, SIGTERM and SIGHUP are
/// blocked in this thread and every thread it starts after this call, and
/// one thread waits for them. On one it removes the outputs still being
/// written (their hidden temporaries: core/atomic_file.hpp), says so in
/// one line and ends the process by that signal (a shell sees 128 + N), so
/// an interrupted run leaves no partial file (issue 58). Child processes
/// unblock them before exec (scenario/process_system.cpp).
inline void remove_temporaries_on_signal(const std::string& app) {
  sigset_t set;
  sigemptyset(&set);
  int count = 0;
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    // A signal the parent set to be ignored (SIGINT for a script's `app &`)
    // stays ignored, as a program that handles it should leave it.
    struct sigaction current {};
    if (::sigaction(sig, nullptr, &current) == 0 && current.sa_handler == SIG_IGN) continue;
    sigaddset(&set, sig);
    ++count;
  }
  if (count == 0 || ::pthread_sigmask(SIG_BLOCK, &set, nullptr) != 0) return;
  std::thread([set, app] {
    int sig = 0;
    if (::sigwait(&set, &sig) != 0) return;
    const std::size_t removed = touchdown::remove_live_temporaries();
    (void)touchdown::kill_live_process_groups();  // exec: systems and what they started
    const char* name = sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "SIGHUP";
    std::string line = (::isatty(2) != 0 ? "\n" : "") + app + ": interrupted (" + name + ")";
    if (removed > 0) line += ": removed " + std::to_string(removed) + " unfinished output(s)";
    line += "\n";
    (void)!::write(2, line.data(), line.size());
    ::signal(sig, SIG_DFL);
    sigset_t one;
    sigemptyset(&one);
    sigaddset(&one, sig);
    ::pthread_sigmask(SIG_UNBLOCK, &one, nullptr);
    ::raise(sig);  // default action: the process ends by the signal
    ::_exit(128 + sig);
  }).detach();
}

/// A subcommand and what runs it once parsed: an app with many subcommands
/// declares them from several files (landing_scenario.hpp) and runs the one
/// given with run_parsed.
struct Subcommand {
  CLI::App* command = nullptr;
  std::function<int()> run;
};

/// A subcommand whose options `add(app, args)` declares on an Args of its
/// own (kept alive by the returned runner) and `run(args)` runs.
template <class Args, class Add, class Run>
Subcommand make_subcommand(CLI::App& app, Add add, Run run) {
  auto args = std::make_shared<Args>();
  CLI::App* command = add(app, *args);
  return {command, [args, run] { return run(*args); }};
}

/// Runs the parsed one of `commands` (the app requires one).
inline int run_parsed(const std::vector<Subcommand>& commands) {
  for (const Subcommand& c : commands) {
    if (c.command->parsed()) return c.run();
  }
  throw std::logic_error("no subcommand was parsed");
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
  } catch (const CLI::ExtrasError& e) {
    std::cerr << app.get_name() << ": " << e.what() << option_suggestion(app, e.what()) << " (see --help)\n";
    return kExitBadInput;
  } catch (const CLI::ParseError& e) {
    std::cerr << app.get_name() << ": " << e.what() << " (see --help)\n";
    return kExitBadInput;
  }
  remove_temporaries_on_signal(app.get_name());
  print_warnings(app.get_name(), parse_warnings());
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
