#pragma once
// Helpers shared by the tests.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/mesh.hpp"
#include "touchdown/core/point_cloud.hpp"

/// Skips a long closed-loop test when the suite runs at reduced size
/// (touchdown::test::reduced_size()).
#define TD_FULL_SIZE_ONLY()                                                                      \
  if (::touchdown::test::reduced_size())                                                         \
  GTEST_SKIP() << "TOUCHDOWN_TEST_SIZE=reduced: a long closed loop, run in full by the Release " \
                  "tests"

namespace touchdown::test {

/// True when the suite runs at reduced size: scripts/test.sh sets
/// TOUCHDOWN_TEST_SIZE=reduced for the sanitizer tree's run, where a long
/// closed loop (a golden sweep of 200 landings, a search campaign and its
/// replays) costs 5-15x its Release time. Such a test is then skipped with
/// TD_FULL_SIZE_ONLY(), saying so, and runs in full in the Release tests;
/// every other case runs under the sanitizers as it is
/// (docs/architecture.md, "What runs where").
inline bool reduced_size() {
  const char* size = std::getenv("TOUCHDOWN_TEST_SIZE");
  return size != nullptr && std::string_view(size) == "reduced";
}

/// A fresh empty directory under the build tree, removed at destruction.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "tmp";
    for (auto& c : name) {
      if (c == '/') c = '_';
    }
    path_ = std::filesystem::path(TOUCHDOWN_BINARY_DIR) / "test-tmp" /
            (name + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
  /// Names of the files in the directory.
  [[nodiscard]] std::vector<std::string> files() const {
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::directory_iterator(path_)) out.push_back(e.path().filename().string());
    return out;
  }

 private:
  std::filesystem::path path_;
};

/// The message of the touchdown::Error that `f` throws, or "<no error>".
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const touchdown::Error& e) {
    return e.what();
  }
  return "<no error>";
}

/// The ParseError message of `parse(text, source)`; a test failure when it
/// parses or throws anything else.
template <typename Parse>
std::string parse_error_of(Parse parse, const std::string& text, const std::string& source) {
  try {
    (void)parse(text, source);
  } catch (const touchdown::ParseError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a ParseError: " << e.what() << "\n" << text;
    return {};
  }
  ADD_FAILURE() << "parsed without error:\n" << text;
  return {};
}

/// One way to spoil an Options struct, and the field its validate() must
/// then name first ("field:").
template <typename Options>
struct SpoiledField {
  const char* field;
  std::function<void(Options&)> spoil;
};

/// Table-driven validate() check: `base` (the defaults unless given)
/// validates, and every spoiled copy is refused with a reason that starts
/// with its field's name.
template <typename Options>
void expect_validate_names_fields(std::initializer_list<SpoiledField<Options>> cases, const Options& base = {}) {
  std::string why;
  EXPECT_TRUE(base.validate(&why)) << why;
  for (const auto& c : cases) {
    Options o = base;
    c.spoil(o);
    why.clear();
    EXPECT_FALSE(o.validate(&why)) << c.field << " was accepted";
    EXPECT_EQ(why.rfind(c.field, 0), 0u) << "expected a reason starting with '" << c.field << "', got '" << why << "'";
  }
}

/// Every enumerator of `E` round-trips through its module's to_string
/// (from_string<E>(to_string(e)) == e), and to_string is its names-table
/// entry; the names are distinct.
template <NamedEnum E>
void expect_names_round_trip() {
  const auto& names = EnumNames<E>::names;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto e = static_cast<E>(i);
    EXPECT_EQ(to_string(e), names[i]);
    EXPECT_EQ(from_string<E>(to_string(e)), e) << "'" << names[i] << "'";
    for (std::size_t j = 0; j < i; ++j) EXPECT_NE(names[j], names[i]) << "two enumerators named '" << names[i] << "'";
  }
}

/// from_string<E>(bad) throws InvalidArgument with exactly `message`.
template <NamedEnum E>
void expect_bad_name(std::string_view bad, const std::string& message) {
  try {
    (void)from_string<E>(bad);
    ADD_FAILURE() << "'" << bad << "' was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(std::string(e.what()), message);
  }
}

/// A malformed input for a table-driven bad-input test: its name (letters,
/// digits, '_'; the test's name), the text, and the parts its one-line
/// error must contain.
struct BadInput {
  const char* name;
  std::string text;
  std::vector<std::string> expected;
};
inline void PrintTo(const BadInput& b, std::ostream* os) { *os << b.name; }
/// The error `message` a BadInput case got is one line holding every
/// expected part (file, line, key, problem).
inline void expect_one_line_naming(const std::string& message, const BadInput& input) {
  EXPECT_EQ(message.find('\n'), std::string::npos) << "one line, got: " << message;
  for (const auto& part : input.expected) EXPECT_NE(message.find(part), std::string::npos) << message;
}
/// Test-name generator for INSTANTIATE_TEST_SUITE_P over BadInput tables.
inline std::string bad_input_name(const ::testing::TestParamInfo<BadInput>& info) { return info.param.name; }

/// Angle of the rotation between two poses [rad].
inline double rotation_error(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

inline std::filesystem::path data_path(const std::string& rel) {
  return std::filesystem::path(TOUCHDOWN_TEST_DATA) / rel;
}

inline void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

/// `s` with the first `from` replaced by `to`; a test failure when `s` has
/// no `from` (the edit the test means to make would silently not happen).
inline std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A copy of a bundled YAML file with a top-level key repeated at its end,
/// and the one-line error its loader must give.
struct RepeatedKeyFile {
  std::filesystem::path path;  // the copy
  std::string expected;        // "COPY:N: KEY: duplicate key (first at line M)"
};

/// Writes `original` to `copy` with the line "KEY: VALUE" appended; M is the
/// line of `original` that starts with "KEY:" (a test failure when none does).
inline RepeatedKeyFile with_repeated_key(const std::filesystem::path& original, const std::filesystem::path& copy,
                                         const std::string& key, const std::string& value) {
  std::string text = read_text(original);
  if (!text.empty() && text.back() != '\n') text += '\n';
  int first = 0;
  int lines = 0;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    ++lines;
    if (first == 0 && line.rfind(key + ":", 0) == 0) first = lines;
  }
  EXPECT_NE(first, 0) << original << " has no line starting with " << key << ":";
  write_text(copy, text + key + ": " + value + "\n");
  return {copy, copy.string() + ":" + std::to_string(lines + 1) + ": " + key + ": duplicate key (first at line " +
                    std::to_string(first) + ")"};
}

/// Exit code and output of an app run as `exe args` (stdout and stderr
/// captured through files in `dir`, removed afterwards).
struct AppRun {
  int code = -1;
  std::string out, err;
};

/// `yaml` with the line starting with "key:" replaced by `line` (removed
/// when `line` is empty). Plain string search: std::regex trips GCC 12's
/// -Wmaybe-uninitialized under the sanitizer build.
inline std::string replace_key_line(const std::string& yaml, const std::string& key, const std::string& line) {
  std::string out;
  std::size_t at = 0;
  while (at < yaml.size()) {
    std::size_t end = yaml.find('\n', at);
    if (end == std::string::npos) end = yaml.size();
    const std::string l = yaml.substr(at, end - at);
    if (l.rfind(key + ":", 0) == 0) {
      if (!line.empty()) out += line + "\n";
    } else {
      out += l + "\n";
    }
    at = end + 1;
  }
  return out;
}

/// docs/architecture.md, "Conventions" (apps): every option of a CLI11 --help text that takes
/// a value (TEXT, INT, UINT, FLOAT) and is not required shows its default
/// ("--cell FLOAT=0.02", "--crop-box FLOAT=off x 6").
inline void expect_help_shows_defaults(const std::string& help) {
  std::istringstream in(help);
  std::string line;
  int options = 0;
  while (std::getline(in, line)) {
    const auto start = line.find_first_not_of(' ');
    if (start == std::string::npos || line[start] != '-') continue;
    const std::string head = line.substr(start, line.find("  ", start) - start);
    const bool takes_value = head.find(" TEXT") != std::string::npos || head.find(" INT") != std::string::npos ||
                             head.find(" UINT") != std::string::npos || head.find(" FLOAT") != std::string::npos;
    if (!takes_value || head.find("REQUIRED") != std::string::npos) continue;
    ++options;
    EXPECT_NE(head.find('='), std::string::npos) << "no default shown: " << line;
  }
  EXPECT_GT(options, 3) << help;
}

/// docs/cli.md's convention: `--json` prints its object on one line.
inline void expect_one_json_line(const std::string& out) {
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out.substr(0, 400);
  EXPECT_TRUE(!out.empty() && out.front() == '{' && out.back() == '\n') << out.substr(0, 400);
}

/// Runs an app with TOUCHDOWN_PROGRESS=off: a test that reads stderr must
/// not depend on how fast the machine is (progress lines come after 5 s).
// Runs `command` through the shell; the app's output went to `out` and
// `err`, which are read and removed.
inline AppRun run_shell(const std::string& command, const std::filesystem::path& out,
                        const std::filesystem::path& err) {
  const int status = std::system(command.c_str());
  AppRun r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(out);
  r.err = read_text(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

inline AppRun run_app(const std::string& exe, const std::string& args, const TempDir& dir) {
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  return run_shell("TOUCHDOWN_PROGRESS=off " + exe + " " + args + " >" + out.string() + " 2>" + err.string(), out, err);
}

/// Runs an app in the background, waits (up to 120 s) until `dir` holds an
/// entry whose name starts with `appears` (a hidden temporary: the run is
/// writing its outputs), sends it `signal` ("INT", "TERM") and waits for
/// it. code: the shell's status (128 + N when the signal ended it).
inline AppRun interrupt_app(const std::string& exe, const std::string& args, const TempDir& dir,
                            const std::string& appears, const std::string& signal) {
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt", script = dir / "interrupt.sh";
  // Job control (set -m): the app gets its own process group and SIGINT
  // is not ignored, as for a command typed at a terminal.
  write_text(script, "set -m\n" + exe + " " + args + " >" + out.string() + " 2>" + err.string() +
                         " &\npid=$!\nfor i in $(seq 1200); do\n  ls -A " + dir.path().string() + " | grep -q '^" +
                         appears + "' && break\n  kill -0 $pid 2>/dev/null || break\n  sleep 0.1\ndone\nkill -" +
                         signal + " $pid\nwait $pid\n");
  AppRun r = run_shell("bash " + script.string(), out, err);
  std::filesystem::remove(script);
  return r;
}

/// Bitwise equality of two clouds (NaN == NaN when the bits match).
inline ::testing::AssertionResult same_points(const PointCloud& a, const PointCloud& b) {
  if (a.size() != b.size()) {
    return ::testing::AssertionFailure() << "sizes differ: " << a.size() << " vs " << b.size();
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::memcmp(a.points[i].data(), b.points[i].data(), 12) != 0) {
      return ::testing::AssertionFailure()
             << "point " << i << " differs: " << a.points[i].transpose() << " vs " << b.points[i].transpose();
    }
  }
  return ::testing::AssertionSuccess();
}

/// A random cloud with some NaNs and awkward values.
inline PointCloud random_cloud(std::size_t n, unsigned seed, bool with_nan = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-100.f, 100.f);
  PointCloud c;
  for (std::size_t i = 0; i < n; ++i) {
    const float z = u(rng), y = u(rng);  // one draw per statement: z first, as recorded
    Eigen::Vector3f p(u(rng), y, z);
    if (with_nan && i % 17 == 3) p.x() = std::numeric_limits<float>::quiet_NaN();
    if (i % 23 == 5) p.z() = std::numeric_limits<float>::denorm_min();
    if (i % 29 == 7) p.y() = 1e-30f;
    c.points.push_back(p);
  }
  c.mark_unorganized();
  return c;
}

/// Highest z where a vertical line at (x, y) meets an upward-facing triangle
/// of `mesh`; NaN when it meets none. Independent of how the mesh was built.
inline double mesh_top_z(const TriangleMesh& mesh, double x, double y) {
  double best = std::numeric_limits<double>::quiet_NaN();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    if (det <= 1e-14) continue;  // vertical or downward-facing
    const double l1 = ((x - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (y - a.y())) / det;
    const double l2 = ((b.x() - a.x()) * (y - a.y()) - (x - a.x()) * (b.y() - a.y())) / det;
    const double l0 = 1 - l1 - l2;
    if (l0 < -1e-9 || l1 < -1e-9 || l2 < -1e-9) continue;
    const double z = l0 * a.z() + l1 * b.z() + l2 * c.z();
    if (std::isnan(best) || z > best) best = z;
  }
  return best;
}

}  // namespace touchdown::test
