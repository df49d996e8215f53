#include "touchdown/plan/problem_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/rotation.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::plan {
namespace {

// Every value equal, bit for bit, except the camera rotation, which passes
// through roll-pitch-yaw degrees (to `rotation_tolerance`).
void problem_io_expect_same(const PlanProblem& a, const PlanProblem& b, double rotation_tolerance = 1e-12) {
  auto same_state = [](const KinematicState& x, const KinematicState& y) {
    EXPECT_EQ(x.p, y.p);
    EXPECT_EQ(x.v, y.v);
    EXPECT_EQ(x.a, y.a);
  };
  same_state(a.start, b.start);
  ASSERT_EQ(a.goal.has_value(), b.goal.has_value());
  if (a.goal) same_state(*a.goal, *b.goal);
  EXPECT_EQ(a.pad.velocity, b.pad.velocity);
  EXPECT_EQ(a.pad.yaw_rate, b.pad.yaw_rate);
  EXPECT_EQ(a.pad.yaw, b.pad.yaw);
  const PlannerOptions &o = a.options, &p = b.options;
  EXPECT_EQ(o.order, p.order);
  EXPECT_EQ(o.segments, p.segments);
  EXPECT_EQ(o.v_max, p.v_max);
  EXPECT_EQ(o.a_max, p.a_max);
  EXPECT_EQ(o.durations, p.durations);
  EXPECT_EQ(o.time.min, p.time.min);
  EXPECT_EQ(o.time.max, p.time.max);
  EXPECT_EQ(o.time.rho, p.time.rho);
  EXPECT_EQ(o.time.max_evaluations, p.time.max_evaluations);
  ASSERT_EQ(o.corridor.has_value(), p.corridor.has_value());
  if (o.corridor) {
    const CorridorOptions &c = *o.corridor, &d = *p.corridor;
    EXPECT_EQ(c.h_touchdown, d.h_touchdown);
    EXPECT_EQ(c.deflate, d.deflate);
    EXPECT_EQ(c.dilate, d.dilate);
    EXPECT_EQ(c.max_dilations, d.max_dilations);
    EXPECT_EQ(c.radius, d.radius);
    EXPECT_EQ(c.margin, d.margin);
    ASSERT_EQ(c.camera.has_value(), d.camera.has_value());
    if (c.camera) {
      EXPECT_EQ(c.camera->T_pad_camera.translation(), d.camera->T_pad_camera.translation());
      EXPECT_LE((c.camera->T_pad_camera.linear() - d.camera->T_pad_camera.linear()).cwiseAbs().maxCoeff(),
                rotation_tolerance);
      EXPECT_EQ(c.camera->horizontal_fov_rad, d.camera->horizontal_fov_rad);
      EXPECT_EQ(c.camera->vertical_fov_rad, d.camera->vertical_fov_rad);
      EXPECT_EQ(c.camera->near_m, d.camera->near_m);
      EXPECT_EQ(c.camera->far_m, d.camera->far_m);
    }
  }
  ASSERT_EQ(o.obstacles.size(), p.obstacles.size());
  for (std::size_t i = 0; i < o.obstacles.size(); ++i) {
    EXPECT_EQ(o.obstacles[i].min, p.obstacles[i].min);
    EXPECT_EQ(o.obstacles[i].max, p.obstacles[i].max);
  }
}

// A valid problem with every key; each line is one key (lines named in the
// bad-input table below).
const char* const kProblemIoFull =
    "start: {p: [-3, 0, 2], v: [0.3, 0, 0], a: [0, 0, 0.1]}\n"  // 1
    "goal: {p: [0, 0, 0.6], v: [0, 0, -0.2]}\n"                 // 2
    "pad: {v: [2, 0, 0], yaw_rate_deg: 6, yaw_deg: 30}\n"       // 3
    "limits: {v_max: 4, a_max: 5}\n"                            // 4
    "order: 8\n"                                                // 5
    "segments: 3\n"                                             // 6
    "durations: [1.5, 1, 2]\n"                                  // 7
    "time: {min: 0.2, max: 6, rho: 2, max_evaluations: 50}\n"   // 8
    "corridor:\n"                                               // 9
    "  h_touchdown: 0.6\n"                                      // 10
    "  deflate: 0.2\n"                                          // 11
    "  dilate: 0.1\n"                                           // 12
    "  max_dilations: 7\n"                                      // 13
    "  radius: 0.3\n"                                           // 14
    "  margin: 1.5\n"                                           // 15
    "  camera:\n"                                               // 16
    "    p: [0.3, 0, 0.05]\n"                                   // 17
    "    rpy_deg: [-45, 0, 90]\n"                               // 18
    "    fov_deg: [90, 100]\n"                                  // 19
    "    range: [0.1, 8]\n"                                     // 20
    "obstacles:\n"                                              // 21
    "  - {min: [-1.6, -0.15, 0], max: [-1.45, 0.15, 0.7]}\n"    // 22
    "  - {min: [-5, -5, 0], max: [-4.5, -4.5, 0.2]}\n";         // 23

std::string problem_io_replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(ProblemIo, ReadsEveryKey) {
  const PlanProblem p = parse_plan_problem(kProblemIoFull, "p.yaml");
  EXPECT_EQ(p.start.p, Eigen::Vector3d(-3, 0, 2));
  EXPECT_EQ(p.start.v, Eigen::Vector3d(0.3, 0, 0));
  EXPECT_EQ(p.start.a, Eigen::Vector3d(0, 0, 0.1));
  ASSERT_TRUE(p.goal.has_value());
  EXPECT_EQ(p.goal->p, Eigen::Vector3d(0, 0, 0.6));
  EXPECT_EQ(p.goal->v, Eigen::Vector3d(0, 0, -0.2));
  EXPECT_EQ(p.goal->a, Eigen::Vector3d::Zero());
  EXPECT_EQ(p.pad.velocity, Eigen::Vector3d(2, 0, 0));
  EXPECT_EQ(p.pad.yaw_rate, deg_to_rad(6.0));  // deg/s in the file, rad/s in the struct
  EXPECT_TRUE(p.warnings.empty());
  EXPECT_DOUBLE_EQ(p.pad.yaw, std::numbers::pi / 6);
  const PlannerOptions& o = p.options;
  EXPECT_EQ(o.v_max, 4);
  EXPECT_EQ(o.a_max, 5);
  EXPECT_EQ(o.order, 8);
  EXPECT_EQ(o.segments, 3);
  EXPECT_EQ(o.durations, (std::vector<double>{1.5, 1, 2}));
  EXPECT_EQ(o.time.min, 0.2);
  EXPECT_EQ(o.time.max, 6);
  EXPECT_EQ(o.time.rho, 2);
  EXPECT_EQ(o.time.max_evaluations, 50);
  ASSERT_TRUE(o.corridor.has_value());
  EXPECT_EQ(o.corridor->h_touchdown, 0.6);
  EXPECT_EQ(o.corridor->deflate, 0.2);
  EXPECT_EQ(o.corridor->dilate, 0.1);
  EXPECT_EQ(o.corridor->max_dilations, 7);
  EXPECT_EQ(o.corridor->radius, 0.3);
  EXPECT_EQ(o.corridor->margin, 1.5);
  ASSERT_TRUE(o.corridor->camera.has_value());
  const CameraFov& c = *o.corridor->camera;
  EXPECT_EQ(c.T_pad_camera.translation(), Eigen::Vector3d(0.3, 0, 0.05));
  // rpy [-45, 0, 90] deg: the optical axis (camera z) looks backward and up
  // at 45 deg, image right (camera x) is the pad's left.
  const Eigen::Vector3d axis = c.T_pad_camera.linear().col(2), right = c.T_pad_camera.linear().col(0);
  EXPECT_NEAR((axis - Eigen::Vector3d(-std::sqrt(0.5), 0, std::sqrt(0.5))).norm(), 0, 1e-12);
  EXPECT_NEAR((right - Eigen::Vector3d(0, 1, 0)).norm(), 0, 1e-12);
  EXPECT_DOUBLE_EQ(c.horizontal_fov_rad, std::numbers::pi / 2);
  EXPECT_DOUBLE_EQ(c.vertical_fov_rad, deg_to_rad(100));
  EXPECT_EQ(c.near_m, 0.1);
  EXPECT_EQ(c.far_m, 8);
  ASSERT_EQ(o.obstacles.size(), 2u);
  EXPECT_EQ(o.obstacles[0].min, Eigen::Vector3d(-1.6, -0.15, 0));
  EXPECT_EQ(o.obstacles[1].max, Eigen::Vector3d(-4.5, -4.5, 0.2));
}

TEST(ProblemIo, DefaultsOfAMinimalFile) {
  const PlanProblem p = parse_plan_problem("start: {p: [-2, 1, 3]}\nlimits: {v_max: 3, a_max: 2}\n", "min.yaml");
  const PlanProblem defaults;
  EXPECT_EQ(p.start.v, Eigen::Vector3d::Zero());
  EXPECT_EQ(p.start.a, Eigen::Vector3d::Zero());
  EXPECT_FALSE(p.goal.has_value());
  EXPECT_EQ(p.pad.velocity, Eigen::Vector3d::Zero());
  EXPECT_EQ(p.pad.yaw_rate, 0);
  EXPECT_EQ(p.pad.yaw, 0);
  EXPECT_EQ(p.options.order, defaults.options.order);
  EXPECT_EQ(p.options.segments, defaults.options.segments);
  EXPECT_TRUE(p.options.durations.empty());
  EXPECT_EQ(p.options.time.min, defaults.options.time.min);
  EXPECT_EQ(p.options.time.max, defaults.options.time.max);
  EXPECT_EQ(p.options.time.rho, defaults.options.time.rho);
  EXPECT_FALSE(p.options.corridor.has_value());
  EXPECT_TRUE(p.options.obstacles.empty());
  // Inside a corridor every key has CorridorOptions' default; no camera, no FoV.
  const PlanProblem c =
      parse_plan_problem("start: {p: [-2, 1, 3]}\nlimits: {v_max: 3, a_max: 2}\ncorridor: {}\n", "c.yaml");
  ASSERT_TRUE(c.options.corridor.has_value());
  const CorridorOptions d;
  EXPECT_EQ(c.options.corridor->h_touchdown, d.h_touchdown);
  EXPECT_EQ(c.options.corridor->radius, d.radius);
  EXPECT_EQ(c.options.corridor->margin, d.margin);
  EXPECT_FALSE(c.options.corridor->camera.has_value());
  // An empty camera map: CameraFov's defaults (looking straight up from the pad centre).
  const PlanProblem e =
      parse_plan_problem("start: {p: [-2, 1, 3]}\nlimits: {v_max: 3, a_max: 2}\ncorridor: {camera: {}}\n", "e.yaml");
  ASSERT_TRUE(e.options.corridor->camera.has_value());
  EXPECT_EQ(e.options.corridor->camera->horizontal_fov_rad, CameraFov{}.horizontal_fov_rad);
  EXPECT_TRUE(e.options.corridor->camera->T_pad_camera.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(ProblemIo, RoundTripOfTheFullFile) {
  const PlanProblem p = parse_plan_problem(kProblemIoFull, "p.yaml");
  const std::string yaml = plan_problem_to_yaml(p);
  const PlanProblem q = parse_plan_problem(yaml, "again.yaml");
  problem_io_expect_same(p, q);
  // Written again, the text is the same (a fixed point).
  EXPECT_EQ(plan_problem_to_yaml(q), yaml);
  // The camera reads as written by hand: rpy_deg [-45, 0, 90].
  EXPECT_NE(yaml.find("rpy_deg: [-45, 0, 90]"), std::string::npos) << yaml;
}

// Random problems with awkward numbers: written and read back, every value is
// the same double (angles through degrees: the writer picks the decimal that
// maps back to the same radians).
TEST(ProblemIo, RoundTripOfRandomProblems) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> exponent(-12, 12);
  auto awkward = [&]() { return u(rng) * std::pow(10.0, exponent(rng)); };
  auto positive = [&]() { return std::abs(awkward()) + 1e-300; };
  // A segment duration in [0.001, 100] s with awkward digits.
  auto duration = [&]() { return 1e-3 + std::abs(u(rng)) * std::pow(10.0, exponent(rng) % 3); };
  auto vec = [&]() { return Eigen::Vector3d(awkward(), awkward(), awkward()); };
  for (int trial = 0; trial < 200; ++trial) {
    PlanProblem p;
    p.start = {vec(), vec(), vec()};
    if (trial % 2) p.goal = KinematicState{vec(), vec(), vec()};
    p.pad.velocity = vec();
    p.pad.yaw_rate = deg_to_rad(awkward());  // deg/s in the file, as the yaw: exact through degrees
    p.pad.yaw = deg_to_rad(360 * u(rng));
    PlannerOptions& o = p.options;
    o.order = 5 + trial % 16;
    o.segments = 2 + trial % 5;
    o.v_max = positive();
    o.a_max = positive();
    if (trial % 3 == 0) {
      for (int k = 0; k < o.segments; ++k) o.durations.push_back(duration());
    }
    o.time.min = duration();
    o.time.max = o.time.min * (1.5 + std::abs(u(rng)));
    o.time.rho = std::abs(awkward());
    o.time.max_evaluations = 1 + trial;
    if (trial % 4 != 1) {
      CorridorOptions c;
      c.h_touchdown = positive();
      c.deflate = std::abs(awkward());
      c.dilate = positive();
      c.max_dilations = 1 + trial % 9;
      c.radius = std::abs(awkward());
      c.margin = c.radius + std::abs(awkward());
      if (trial % 2 == 0) {
        CameraFov cam;
        cam.T_pad_camera.translation() = vec();
        const double yaw = deg_to_rad(180 * u(rng)), pitch = deg_to_rad(89 * u(rng));  // yaw first, as recorded
        cam.T_pad_camera.linear() = rotation_from_rpy(deg_to_rad(180 * u(rng)), pitch, yaw);
        cam.horizontal_fov_rad = deg_to_rad(1 + 178 * std::abs(u(rng)));
        cam.vertical_fov_rad = deg_to_rad(1 + 178 * std::abs(u(rng)));
        cam.near_m = std::abs(awkward());
        cam.far_m = 2 * cam.near_m + positive();
        c.camera = cam;
      }
      o.corridor = c;
    }
    for (int i = 0; i < trial % 3; ++i) {
      Box b;
      b.min = vec();
      b.max = b.min + Eigen::Vector3d(std::abs(awkward()), std::abs(awkward()), std::abs(awkward()));
      o.obstacles.push_back(b);
    }
    const std::string yaml = plan_problem_to_yaml(p);
    PlanProblem q;
    ASSERT_NO_THROW(q = parse_plan_problem(yaml, "random.yaml")) << yaml;
    problem_io_expect_same(p, q, 1e-12);
  }
}

TEST(ProblemIo, MissingFileIsAnIoError) {
  EXPECT_THROW(load_plan_problem("/nonexistent/problem.yaml"), IoError);
  EXPECT_NE(test::error_of([] { load_plan_problem("/nonexistent/problem.yaml"); }).find("/nonexistent/problem.yaml"),
            std::string::npos);
}

TEST(ProblemIo, LoadsAFile) {
  test::TempDir dir;
  test::write_text(dir / "p.yaml", kProblemIoFull);
  problem_io_expect_same(load_plan_problem((dir / "p.yaml").string()), parse_plan_problem(kProblemIoFull, "p.yaml"));
  test::write_text(dir / "bad.yaml", problem_io_replace(kProblemIoFull, "v_max: 4", "v_max: -4"));
  EXPECT_EQ(test::error_of([&] { load_plan_problem((dir / "bad.yaml").string()); }),
            (dir / "bad.yaml").string() + ":4: limits.v_max: must be > 0, got -4");
}

// The case: a second `limits` appended to the bundled problem was
// ignored (the first value won) and gave the unchanged plan.
TEST(ProblemIo, RepeatedKeyIsAnError) {
  test::TempDir dir;
  const auto f = test::with_repeated_key(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/plans/landing.yaml",
                                         dir / "landing.yaml", "limits", "{v_max: 0.1, a_max: 0.1}");
  EXPECT_EQ(test::error_of([&] { load_plan_problem(f.path.string()); }), f.expected);
  EXPECT_THROW(load_plan_problem(f.path.string()), ParseError);
}

// Issue 31 item 9: radians written where degrees are read get a warning
// naming the file, line and key (as camera pose files do); the problem
// still reads, as degrees.
TEST(ProblemIo, RadiansInDegreeKeysAreWarnedAbout) {
  std::string text = problem_io_replace(kProblemIoFull, "rpy_deg: [-45, 0, 90]", "rpy_deg: [-0.785, 0, 1.571]");
  PlanProblem p = parse_plan_problem(text, "p.yaml");
  ASSERT_EQ(p.warnings.size(), 1u);
  EXPECT_EQ(p.warnings[0],
            "p.yaml:18: corridor.camera.rpy_deg: [-0.785, 0, 1.571] look like radians (all within +-2 pi, not whole "
            "degrees) but are read as degrees; if radians were meant, write [-44.98, 0, 90.01]");
  EXPECT_NEAR(rpy_from_rotation(p.options.corridor->camera->T_pad_camera.linear()).z(), deg_to_rad(1.571), 1e-12);
  text = problem_io_replace(kProblemIoFull, "yaw_deg: 30", "yaw_deg: 1.5708");
  p = parse_plan_problem(text, "p.yaml");
  ASSERT_EQ(p.warnings.size(), 1u);
  EXPECT_NE(p.warnings[0].find("p.yaml:3: pad.yaw_deg: 1.5708 looks like radians"), std::string::npos) << p.warnings[0];
  EXPECT_NE(p.warnings[0].find("write 90"), std::string::npos) << p.warnings[0];
  // Whole degrees, or angles beyond 2 pi, are degrees: no warning.
  text = problem_io_replace(kProblemIoFull, "rpy_deg: [-45, 0, 90]", "rpy_deg: [-2, 0, 3]");
  EXPECT_TRUE(parse_plan_problem(text, "p.yaml").warnings.empty());
  text = problem_io_replace(kProblemIoFull, "rpy_deg: [-45, 0, 90]", "rpy_deg: [-45.5, 0, 90]");
  EXPECT_TRUE(parse_plan_problem(text, "p.yaml").warnings.empty());
}

// The planner part of another file (the mission's guidance.planner): the
// same keys and messages as a problem file's, the key path and the
// document's own lines in each message.
TEST(ProblemIo, APlannerSectionOfAnotherFileReadsTheSameKeys) {
  const std::string text =
      "name: x\n"
      "guidance:\n"
      "  speed: 2\n"
      "  planner:\n"
      "    limits: {v_max: 1.5, a_max: 2.5}\n"
      "    order: 9\n";
  PlannerOptions o;
  const int segments = o.segments;
  std::vector<std::string> warnings;
  parse_planner_section(text, "m.yaml", "guidance.planner", o, warnings);
  EXPECT_EQ(o.v_max, 1.5);
  EXPECT_EQ(o.a_max, 2.5);
  EXPECT_EQ(o.order, 9);
  EXPECT_EQ(o.segments, segments);  // absent: kept
  EXPECT_TRUE(warnings.empty());
  // The same keys as the problem file's planner part read to the same options.
  const PlanProblem p = parse_plan_problem(kProblemIoFull, "p.yaml");
  std::string nested = "outer:\n  planner:\n";
  std::istringstream lines(kProblemIoFull);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("start", 0) == 0 || line.rfind("goal", 0) == 0 || line.rfind("pad", 0) == 0) {
      for (std::string skip; lines.peek() == ' ' && std::getline(lines, skip);) {
      }
      continue;
    }
    nested += "    " + line + "\n";
  }
  PlannerOptions from_section;
  parse_planner_section(nested, "n.yaml", "outer.planner", from_section, warnings);
  EXPECT_EQ(from_section.order, p.options.order);
  EXPECT_EQ(from_section.segments, p.options.segments);
  EXPECT_EQ(from_section.durations, p.options.durations);
  EXPECT_EQ(from_section.v_max, p.options.v_max);
  EXPECT_EQ(from_section.obstacles.size(), p.options.obstacles.size());
  EXPECT_EQ(from_section.corridor.has_value(), p.options.corridor.has_value());
  // Errors name the document's line and the whole key path.
  EXPECT_EQ(test::error_of(
                [&] { parse_planner_section(text + "    ordre: 3\n", "m.yaml", "guidance.planner", o, warnings); }),
            "m.yaml:7: guidance.planner.ordre: unknown key (expected limits, order, segments, durations, time, "
            "corridor, obstacles)");
  EXPECT_NE(test::error_of([&] {
              parse_planner_section("g:\n  p:\n    limits: {v_max: -1, a_max: 1}\n", "m.yaml", "g.p", o, warnings);
            }).find("m.yaml:3: g.p.limits.v_max"),
            std::string::npos);
  EXPECT_EQ(test::error_of([&] { parse_planner_section("g: 3\n", "m.yaml", "g.p", o, warnings); }),
            "m.yaml:1: g: expected a mapping");
  // No such section: nothing read, nothing refused.
  PlannerOptions untouched;
  parse_planner_section("other: 1\n", "m.yaml", "guidance.planner", untouched, warnings);
  EXPECT_EQ(untouched.order, PlannerOptions{}.order);
  EXPECT_THROW(parse_planner_section(text, "m.yaml", "guidance..planner", o, warnings), InvalidArgument);
}

// ---- bad input: one error naming the file, the line and the key ----

class ProblemIoBadInput : public ::testing::TestWithParam<test::BadInput> {};

TEST_P(ProblemIoBadInput, NamesFileLineAndKey) {
  const auto& c = GetParam();
  std::string message;
  try {
    parse_plan_problem(c.text, "p.yaml");
    message = "<no error>";
  } catch (const ParseError& e) {
    message = e.what();
  }
  for (const auto& part : c.expected) EXPECT_NE(message.find(part), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

std::vector<test::BadInput> problem_io_bad_inputs() {
  const std::string f = kProblemIoFull;
  auto r = [&](const std::string& from, const std::string& to) { return problem_io_replace(f, from, to); };
  return {
      {"MissingLimits", r("limits: {v_max: 4, a_max: 5}\n", ""), {"p.yaml:1: limits: missing"}},
      {"MissingAMax", r("limits: {v_max: 4, a_max: 5}", "limits: {v_max: 4}"), {"p.yaml:4: limits.a_max: missing"}},
      {"NanVMax", r("v_max: 4", "v_max: .nan"), {"p.yaml:4: limits.v_max: expected a number, got '.nan'"}},
      {"InfAMax", r("a_max: 5", "a_max: .inf"), {"p.yaml:4: limits.a_max: expected a number"}},
      {"NegativeVMax", r("v_max: 4", "v_max: -1"), {"p.yaml:4: limits.v_max: must be > 0, got -1"}},
      {"ZeroDuration",
       r("durations: [1.5, 1, 2]", "durations: [1.5, 0, 2]"),
       {"p.yaml:7: durations[1]: must be in [0.001, 1000] s, got 0"}},
      // Issue 11: 1e5 s was reported "infeasible" (the QP not convex), 1e-300 s
      // as "qp: every entry of P, q, A and b must be finite".
      {"HugeDuration",
       r("durations: [1.5, 1, 2]", "durations: [1.5, 1e5, 2]"),
       {"p.yaml:7: durations[1]: must be in [0.001, 1000] s, got 100000"}},
      {"TinyDuration",
       r("durations: [1.5, 1, 2]", "durations: [1.5, 1e-300, 2]"),
       {"p.yaml:7: durations[1]: must be in [0.001, 1000] s, got 1e-300"}},
      {"HugeTimeMax", r("max: 6,", "max: 1e9,"), {"p.yaml:8: time.max: must be in [0.001, 1000] s, got 1e+09"}},
      {"TinyTimeMin", r("min: 0.2,", "min: 1e-4,"), {"p.yaml:8: time.min: must be in [0.001, 1000] s, got 0.0001"}},
      {"DurationCount",
       r("durations: [1.5, 1, 2]", "durations: [1.5, 1]"),
       {"p.yaml:7: durations: expected one per segment (3), got 2"}},
      {"DurationNotANumber",
       r("durations: [1.5, 1, 2]", "durations: [1.5, fast, 2]"),
       {"p.yaml:7: durations: expected a number, got 'fast'"}},
      {"OrderTooLow", r("order: 8", "order: 4"), {"p.yaml:5: order: must be in 5..20, got 4"}},
      {"OrderTooHigh", r("order: 8", "order: 21"), {"p.yaml:5: order: must be in 5..20, got 21"}},
      {"OrderNotAnInteger", r("order: 8", "order: 7.5"), {"p.yaml:5: order: expected an integer"}},
      {"OneSegmentWithACorridor",
       r("segments: 3\ndurations: [1.5, 1, 2]", "segments: 1"),
       {"p.yaml:6: segments: must be >= 2 with a corridor"}},
      {"TooManySegments",
       r("segments: 3\ndurations: [1.5, 1, 2]", "segments: 17"),
       {"p.yaml:6: segments: must be in 1..16, got 17"}},
      {"TimeMinAboveMax",
       r("time: {min: 0.2, max: 6", "time: {min: 7, max: 6"),
       {"p.yaml:8: time.max: need time.min < time.max, got min 7 s, max 6 s"}},
      {"TimeMinAboveDefaultMax",
       r("time: {min: 0.2, max: 6, rho: 2, max_evaluations: 50}", "time: {min: 9}"),
       {"p.yaml:8: time.min: need time.min < time.max"}},
      {"NegativeRho", r("rho: 2", "rho: -2"), {"p.yaml:8: time.rho: must be >= 0, got -2"}},
      {"ZeroEvaluations", r("max_evaluations: 50", "max_evaluations: 0"), {"p.yaml:8: time.max_evaluations"}},
      {"NegativeRadius", r("radius: 0.3", "radius: -0.3"), {"p.yaml:14: corridor.radius: must be >= 0, got -0.3"}},
      {"ZeroTouchdownHeight",
       r("h_touchdown: 0.6", "h_touchdown: 0"),
       {"p.yaml:10: corridor.h_touchdown: must be > 0"}},
      {"ZeroDilate", r("dilate: 0.1", "dilate: 0"), {"p.yaml:12: corridor.dilate: must be > 0"}},
      {"FovOf180",
       r("fov_deg: [90, 100]", "fov_deg: [180, 100]"),
       {"p.yaml:19: corridor.camera.fov_deg: each angle must be in (0, 180) deg"}},
      {"FovOneNumber",
       r("fov_deg: [90, 100]", "fov_deg: [90]"),
       {"p.yaml:19: corridor.camera.fov_deg: expected [horizontal, vertical], got 1 numbers"}},
      {"RangeFarBeforeNear",
       r("range: [0.1, 8]", "range: [8, 0.1]"),
       {"p.yaml:20: corridor.camera.range: need 0 <= near < far"}},
      {"RpyOutOfRange",
       r("rpy_deg: [-45, 0, 90]", "rpy_deg: [-45, 0, 400]"),
       {"p.yaml:18: corridor.camera.rpy_deg: must be within [-360, 360] deg, got 400"}},
      {"PadYawOutOfRange", r("yaw_deg: 30", "yaw_deg: -361"), {"p.yaml:3: pad.yaw_deg: must be within [-360, 360]"}},
      {"NanPadVelocity", r("pad: {v: [2, 0, 0]", "pad: {v: [2, .nan, 0]"), {"p.yaml:3: pad.v: expected a number"}},
      {"ObstacleMaxBelowMin",
       r("max: [-4.5, -4.5, 0.2]", "max: [-4.5, -4.5, -0.2]"),
       {"p.yaml:23: obstacles[1].max: must be >= min on every axis, got z max -0.2 < min 0"}},
      {"ObstacleWithoutMax",
       r("  - {min: [-5, -5, 0], max: [-4.5, -4.5, 0.2]}", "  - {min: [-5, -5, 0]}"),
       {"p.yaml:23: obstacles[1].max: missing"}},
      {"ObstaclesNotAList",
       r("  - {min: [-1.6, -0.15, 0], max: [-1.45, 0.15, 0.7]}\n  - {min: [-5, -5, 0], max: "
         "[-4.5, -4.5, 0.2]}\n",
         "  min: [0, 0, 0]\n"),
       {"p.yaml:22: obstacles: expected a list"}},
      {"StartWithoutP", r("start: {p: [-3, 0, 2], v:", "start: {v:"), {"p.yaml:1: start.p: missing"}},
      {"StartTwoNumbers", r("p: [-3, 0, 2]", "p: [-3, 0]"), {"p.yaml:1: start.p: expected 3 numbers, got 2"}},
      {"GoalNotAMap",
       r("goal: {p: [0, 0, 0.6], v: [0, 0, -0.2]}", "goal: [0, 0, 0.6]"),
       {"p.yaml:2: goal: expected a mapping"}},
      {"UnknownRootKey", r("order: 8", "order: 8\ncolour: red"), {"p.yaml:6: colour: unknown key (expected start,"}},
      {"UnknownStateKey", r("a: [0, 0, 0.1]", "j: [0, 0, 0.1]"), {"p.yaml:1: start.j: unknown key (expected p, v, a)"}},
      {"UnknownCameraKey",
       r("    range: [0.1, 8]\n", "    range: [0.1, 8]\n    zoom: 2\n"),
       {"p.yaml:21: corridor.camera.zoom: unknown key"}},
      {"UnknownObstacleKey",
       r("max: [-1.45, 0.15, 0.7]}", "max: [-1.45, 0.15, 0.7], colour: red}"),
       {"p.yaml:22: obstacles[0].colour: unknown key (expected min, max)"}},
      {"KeyNotAName", r("order: 8", "order: 8\n? [1, 2]\n: 3"), {"p.yaml:6: <document>: a key must be a plain name"}},
      {"InvalidYaml", r("segments: 3", "segments: [3"), {"p.yaml:", "invalid YAML"}},
      {"NotAMapping", "- 1\n- 2\n", {"p.yaml:1: <document>: expected a mapping"}},
      {"Empty", "", {"p.yaml: <document>: expected a mapping"}},
      // Issue 31 item 9: the turn rate was the file's only angle in radians.
      {"OldYawRateName",
       r("yaw_rate_deg: 6", "yaw_rate: 0.4"),
       {"p.yaml:3: pad.yaw_rate: renamed to pad.yaw_rate_deg (deg/s)", "0.4 rad/s is yaw_rate_deg: 22.9183"}},
      {"OldYawRateNameNotANumber",
       r("yaw_rate_deg: 6", "yaw_rate: fast"),
       {"p.yaml:3: pad.yaw_rate: renamed to pad.yaw_rate_deg (deg/s)"}},
  };
}

INSTANTIATE_TEST_SUITE_P(Cases, ProblemIoBadInput, ::testing::ValuesIn(problem_io_bad_inputs()), test::bad_input_name);

}  // namespace
}  // namespace touchdown::plan
