// A recorded drive as the pad's vehicle (vehicle_log.hpp): a log sampled
// from an analytic drive (a circle, a straight line) replays that drive
// between and after its rows; a log round-trips through its CSV; every
// kind of bad log is one error naming the file and the line; a mission
// flies on a log and its vehicle is where the log says.
#include "touchdown/mission/vehicle_log.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/mission/mission.hpp"
#include "touchdown/mission/mission_io.hpp"
#include "touchdown/mission/vehicle.hpp"

namespace tdm = touchdown::mission;
namespace td = touchdown;

namespace {

constexpr double kPi = std::numbers::pi;

// A counter-clockwise circle of radius R at speed v from the origin heading
// +x, sampled every h seconds for `duration` seconds (yaw in degrees when
// `degrees`; with or without the speed column).
std::string circle_log(double R, double v, double h, double duration, bool speed, bool degrees = false) {
  std::ostringstream out;
  out.precision(17);
  out << "# a circle\nt," << (degrees ? "yaw_deg" : "yaw") << ",x,y" << (speed ? ",speed" : "") << "\n";
  for (int i = 0; i * h <= duration + 1e-9; ++i) {
    const double t = i * h, a = v * t / R;
    const double yaw = degrees ? a * 180 / kPi : a;
    out << t << "," << yaw << "," << R * std::sin(a) << "," << R * (1 - std::cos(a));
    if (speed) out << "," << v;
    out << "\n";
  }
  return out.str();
}

std::string error_of(const std::string& text) {
  try {
    (void)tdm::VehicleLog::parse(text, "drive.csv", 1.0);
  } catch (const td::ParseError& e) {
    return e.what();
  }
  return "(accepted)";
}

}  // namespace

// Smoothing (vehicle.log_smoothing): a least-squares parabola over the
// window is exact for a motion of constant acceleration; on a circle it is
// biased by R ω⁴ w⁴ / 4480 in position (the fit of τ⁴ over ±h misses it by
// 3h⁴/35) and by ω² w² / 40 in the speed (the slope fitted to τ³ is 3h²/5);
// and it takes most of a logger's noise out of the replayed motion.
TEST(VehicleLog, SmoothingKeepsAConstantAccelerationAndACircle) {
  std::ostringstream ramp;
  ramp.precision(17);
  ramp << "t,x,y,yaw\n";
  for (int i = 0; i <= 100; ++i) {
    const double t = 0.1 * i;
    ramp << t << "," << 1 + 2 * t + 0.4 * t * t << ",0,0\n";
  }
  const tdm::VehicleLog exact = tdm::VehicleLog::parse(ramp.str(), "ramp.csv", 1.0, 2.0);
  for (const double t : {0.0, 0.33, 4.05, 9.99}) {
    const tdm::LogSample s = exact.sample(t);
    EXPECT_NEAR(s.position.x(), 1 + 2 * t + 0.4 * t * t, 1e-9) << t;
    EXPECT_NEAR(s.speed, 2 + 0.8 * t, 1e-6) << t;
  }
  const double R = 8, v = 2, w = 0.25, window = 2.0;
  const tdm::VehicleLog circle = tdm::VehicleLog::parse(circle_log(R, v, 0.1, 30, false), "c.csv", 1.0, window);
  const double bias = R * std::pow(w, 4) * std::pow(window, 4) / 4480;  // 0.11 mm
  const double rate_bias = w * w * window * window / 40;                // 0.63 %
  for (double t = 2; t < 28; t += 0.37) {
    const tdm::LogSample s = circle.sample(t);
    const double a = w * t;
    // Between rows the Hermite curve follows the rows' (slower) tangents:
    // up to a row interval's share of the speed's bias more.
    EXPECT_LT((s.position - Eigen::Vector2d(R * std::sin(a), R * (1 - std::cos(a)))).norm(),
              1.1 * bias + 0.1 * rate_bias * v)
        << t;
    EXPECT_NEAR(s.yaw_rate, w, 1e-9) << t;  // a heading turning at a constant rate: exact
    EXPECT_NEAR(s.speed, v * (1 - rate_bias), 0.1 * rate_bias * v) << t;
  }
}

TEST(VehicleLog, SmoothingTakesALoggersNoiseOutOfTheMotion) {
  // A straight drive at 3 m/s logged at 10 Hz with 2 cm of position and
  // 0.01 rad of heading noise, no speed column.
  td::Rng rng(7);
  std::ostringstream noisy;
  noisy.precision(17);
  noisy << "t,x,y,yaw\n";
  for (int i = 0; i <= 600; ++i) {
    const double t = 0.1 * i;
    noisy << t << "," << 3 * t + 0.02 * rng.normal() << "," << 0.02 * rng.normal() << "," << 0.01 * rng.normal()
          << "\n";
  }
  const auto rms = [](const tdm::VehicleLog& log) {
    double e_speed = 0, e_rate = 0, e_pos = 0;
    int n = 0;
    for (double t = 3; t < 57; t += 0.013, ++n) {
      const tdm::LogSample s = log.sample(t);
      e_speed += std::pow(s.speed - 3, 2);
      e_rate += std::pow(s.yaw_rate, 2);
      e_pos += (s.position - Eigen::Vector2d(3 * t, 0)).squaredNorm();
    }
    return Eigen::Vector3d(std::sqrt(e_speed / n), std::sqrt(e_rate / n), std::sqrt(e_pos / n));
  };
  const Eigen::Vector3d raw = rms(tdm::VehicleLog::parse(noisy.str(), "n.csv", 1.0, 0.0));
  const Eigen::Vector3d smooth = rms(tdm::VehicleLog::parse(noisy.str(), "n.csv", 1.0, 2.0));
  // 21 rows a window: the value's noise √(9/84) ≈ 0.33 of σ; a rate's
  // σ/√(Σ τ²) (the heading's: 0.011 rad/s) against σ√2/0.2 s from three
  // rows (0.07 rad/s).
  EXPECT_GT(raw.x(), 0.1);
  EXPECT_LT(smooth.x(), 0.03);
  EXPECT_GT(raw.y(), 0.05);
  EXPECT_LT(smooth.y(), 0.015);
  EXPECT_LT(smooth.z(), 0.5 * raw.z());
  // The logged rows themselves are kept (to_csv round-trips them).
  EXPECT_EQ(tdm::VehicleLog::parse(noisy.str(), "n.csv", 1.0, 2.0).to_csv(),
            tdm::VehicleLog::parse(noisy.str(), "n.csv", 1.0, 0.0).to_csv());
  EXPECT_THROW((void)tdm::VehicleLog::parse(noisy.str(), "n.csv", 1.0, -1.0), td::InvalidArgument);
}

TEST(VehicleLog, ReplaysACircleBetweenAndAfterItsRows) {
  const double R = 20, v = 10;  // 0.5 rad/s
  for (const bool speed : {true, false}) {
    const tdm::VehicleLog log = tdm::VehicleLog::parse(circle_log(R, v, 0.1, 30, speed, !speed), "c.csv");
    EXPECT_EQ(log.has_speed(), speed);
    EXPECT_DOUBLE_EQ(log.duration(), 30);
    for (double t = 0.013; t < 40; t += 0.37) {  // between rows, and 10 s past the last
      const tdm::LogSample m = log.sample(t);
      const double a = v * t / R;
      // With the speed column the tangents are exact and so is the heading
      // (linear in t): Hermite's O(h^4) position error, about 1e-5 m here.
      // Without it the tangents are three-point differences, O(h^2): the
      // speed off by up to h^2/3 v^3/R^2 = 8 mm/s at the log's ends, and
      // 10 s of extrapolation drift by that times 10 s.
      const double p_tol = speed ? 1e-4 : t <= 30 ? 2e-3 : 0.1;
      EXPECT_NEAR(m.position.x(), R * std::sin(a), p_tol) << speed << " t " << t;
      EXPECT_NEAR(m.position.y(), R * (1 - std::cos(a)), p_tol) << speed << " t " << t;
      EXPECT_NEAR(std::remainder(m.yaw - a, 2 * kPi), 0, 1e-6) << speed << " t " << t;
      EXPECT_NEAR(m.speed, v, speed ? 1e-12 : 1e-2) << speed << " t " << t;
      EXPECT_NEAR(m.yaw_rate, v / R, 1e-6) << speed << " t " << t;
      EXPECT_NEAR(m.acceleration, 0, speed ? 1e-12 : 0.15) << speed << " t " << t;
    }
  }
}

TEST(VehicleLog, AStraightDriveIsExactAndSpeedChangesAreTheLogs) {
  // Constant velocity along 30 degrees, no speed column: exact everywhere.
  std::string text = "t,x,y,yaw_deg\n";
  for (int i = 0; i <= 20; ++i) {
    const double t = 0.25 * i;
    text += std::to_string(t) + "," + std::to_string(3 * t * std::cos(kPi / 6)) + "," +
            std::to_string(3 * t * std::sin(kPi / 6)) + ",30\n";
  }
  const tdm::VehicleLog line = tdm::VehicleLog::parse(text, "line.csv");
  for (double t : {0.0, 0.1, 2.6, 5.0, 7.5}) {
    const tdm::LogSample m = line.sample(t);
    EXPECT_NEAR(m.position.x(), 3 * t * std::cos(kPi / 6), 1e-5) << t;
    EXPECT_NEAR(m.position.y(), 3 * t * std::sin(kPi / 6), 1e-5) << t;
    EXPECT_NEAR(m.speed, 3, 1e-5) << t;
    EXPECT_NEAR(m.yaw_rate, 0, 1e-9) << t;
  }
  // A speed column that ramps: the speed and acceleration are the log's.
  const tdm::VehicleLog ramp = tdm::VehicleLog::parse("time,x,y,yaw,speed\n0,0,0,0,2\n1,3,0,0,4\n2,7,0,0,4\n", "r.csv");
  EXPECT_DOUBLE_EQ(ramp.sample(0.5).speed, 3);
  EXPECT_DOUBLE_EQ(ramp.sample(0.5).acceleration, 2);
  EXPECT_DOUBLE_EQ(ramp.sample(1.5).acceleration, 0);
  EXPECT_DOUBLE_EQ(ramp.top_speed(1.0), 4);
}

TEST(VehicleLog, RoundTripsThroughItsCsv) {
  for (const bool speed : {true, false}) {
    const tdm::VehicleLog a = tdm::VehicleLog::parse(circle_log(8, 2.5, 0.05, 40, speed, true), "a.csv");
    const tdm::VehicleLog b = tdm::VehicleLog::parse(a.to_csv(), "b.csv");
    ASSERT_EQ(a.rows().size(), b.rows().size());
    for (std::size_t i = 0; i < a.rows().size(); ++i) {
      EXPECT_EQ(a.rows()[i].t, b.rows()[i].t);
      EXPECT_EQ(a.rows()[i].x, b.rows()[i].x);
      EXPECT_EQ(a.rows()[i].y, b.rows()[i].y);
      EXPECT_EQ(a.rows()[i].yaw, b.rows()[i].yaw);  // unwrapped once, the same again
      if (speed) {
        EXPECT_EQ(a.rows()[i].speed, b.rows()[i].speed);
      }
    }
    EXPECT_EQ(a.sample(17.3).position, b.sample(17.3).position);
    // 40 s at 2.5 m/s on 8 m is about two turns: the heading is unwrapped.
    EXPECT_GT(a.rows().back().yaw, 2 * kPi);
  }
  // Without a header: t, x, y, yaw [rad], speed.
  const tdm::VehicleLog bare = tdm::VehicleLog::parse("0, 0, 0, 0, 1\n1, 1, 0, 0, 1\n", "bare.csv");
  EXPECT_TRUE(bare.has_speed());
  EXPECT_DOUBLE_EQ(bare.sample(0.75).position.x(), 0.75);
  EXPECT_DOUBLE_EQ(bare.sample(3).position.x(), 3);  // extrapolated at its last speed
  // A spreadsheet's UTF-8 byte-order mark before the header is not a column's.
  const tdm::VehicleLog bom = tdm::VehicleLog::parse("\xEF\xBB\xBFt,x,y,yaw\n0,0,0,0\n1,1,0,0\n", "bom.csv");
  EXPECT_DOUBLE_EQ(bom.sample(0.5).position.x(), 0.5);
}

TEST(VehicleLog, BadLogsNameTheLine) {
  const std::string head = "t,x,y,yaw\n0,0,0,0\n0.5,1,0,0\n";
  EXPECT_EQ(error_of(head + "0.5,2,0,0\n"), "drive.csv:4: t: 0.5 s is not after the row before's 0.5 s (line 3)");
  EXPECT_EQ(error_of(head + "0.4,2,0,0\n"), "drive.csv:4: t: 0.4 s is not after the row before's 0.5 s (line 3)");
  EXPECT_EQ(error_of(head + "3,2,0,0\n"),
            "drive.csv:4: a gap of 2.5 s after the row before (line 3), more than vehicle.log_max_gap 1 s");
  EXPECT_EQ(error_of(head + "1,nan,0,0\n"), "drive.csv:4: x: 'nan' is not a finite number");
  EXPECT_EQ(error_of(head + "1,,0,0\n"), "drive.csv:4: x: '' is not a finite number");
  EXPECT_EQ(error_of(head + "1,2,0\n"), "drive.csv:4: 3 fields, the log has 4 columns");
  EXPECT_EQ(error_of(head + "1,80,0,0\n"),
            "drive.csv:4: a jump of 79 m in 0.5 s since the row before (line 3) (faster than 100 m/s: not a drive)");
  EXPECT_EQ(error_of("t,x,y,yaw\n0,0,0,0\n"), "drive.csv: too short: 1 row (a log needs at least 2, over 1 s or more)");
  EXPECT_EQ(error_of("t,x,y,yaw\n0,0,0,0\n0.5,1,0,0\n"), "drive.csv: too short: 0.5 s (at least 1 s)");
  EXPECT_EQ(error_of(""), "drive.csv: too short: 0 rows (a log needs at least 2, over 1 s or more)");
  EXPECT_EQ(error_of("t,x,y,heading\n"),
            "drive.csv:1: unknown column 'heading' (the columns: t or time, x, y, yaw [rad] or yaw_deg, speed [m/s] "
            "optional)");
  EXPECT_EQ(error_of("# log\nt,x,y\n"), "drive.csv:2: no column yaw (or yaw_deg)");
  EXPECT_EQ(error_of("t,x,x,yaw\n"), "drive.csv:1: column 'x' given twice");
  EXPECT_EQ(error_of("t,x,y,yaw,speed\n0,0,0,0,-1\n"),
            "drive.csv:2: speed: -1 m/s is below 0 (driving backwards is not supported)");
  EXPECT_EQ(error_of("0,0,0\n"),
            "drive.csv:1: a log without a header has the columns t, x, y, yaw [rad] and maybe speed: 3 fields here");
}

TEST(VehicleLog, AMissionFliesOnALogAndItsVehicleIsWhereTheLogSays) {
  td::test::TempDir dir;
  {
    std::ofstream(dir / "drive.csv") << circle_log(8, 2, 0.05, 120, true);
    std::ofstream(dir / "m.yaml") << "vehicle:\n  path: log\n  log: drive.csv\n";
  }
  const tdm::MissionFile f = tdm::load_mission(dir / "m.yaml");
  ASSERT_TRUE(f.options.vehicle.log);
  EXPECT_EQ(f.vehicle_log.filename(), "drive.csv");
  EXPECT_TRUE(f.warnings.empty());  // 120 s covers the 90 s timeout
  tdm::GroundVehicle vehicle(f.options.vehicle, 1);
  for (int i = 0; i < 1000; ++i) vehicle.step(0.01);
  const tdm::LogSample m = f.options.vehicle.log->sample(10.0);
  EXPECT_NEAR((vehicle.state().position - m.position).norm(), 0, 1e-9);
  EXPECT_NEAR(vehicle.state().yaw, m.yaw, 1e-9);
  // The same drive as the bundled circle mission's path (radius 8 m, 2 m/s):
  // the mission lands as it does there.
  tdm::MissionOptions o = f.options;
  const tdm::MissionResult r = tdm::run_mission(o, 3);
  EXPECT_TRUE(r.landed()) << r.message;
  EXPECT_LT(r.touchdown_error, 0.1);

  // A log shorter than the timeout is flown, with a warning.
  std::ofstream(dir / "short.csv") << circle_log(8, 2, 0.05, 30, true);
  std::ofstream(dir / "s.yaml") << "vehicle:\n  path: log\n  log: short.csv\n";
  const tdm::MissionFile s = tdm::load_mission(dir / "s.yaml");
  ASSERT_EQ(s.warnings.size(), 1U);
  EXPECT_NE(s.warnings[0].find("covers 30 s, the mission's timeout 90 s"), std::string::npos) << s.warnings[0];

  // The log's own errors name the log and its line; the mission's keys theirs.
  std::ofstream(dir / "bad.csv") << "t,x,y,yaw\n0,0,0,0\n1,nan,0,0\n";
  std::ofstream(dir / "b.yaml") << "vehicle:\n  path: log\n  log: bad.csv\n";
  const std::string bad = td::test::error_of([&] { (void)tdm::load_mission(dir / "b.yaml"); });
  EXPECT_NE(bad.find("bad.csv:3: x: 'nan' is not a finite number"), std::string::npos) << bad;
  std::ofstream(dir / "n.yaml") << "vehicle:\n  path: log\n";
  const std::string none = td::test::error_of([&] { (void)tdm::load_mission(dir / "n.yaml"); });
  EXPECT_NE(none.find("n.yaml:2: vehicle.log: path log needs a log file"), std::string::npos) << none;
  std::ofstream(dir / "c.yaml") << "vehicle:\n  path: circle\n  log: drive.csv\n";
  const std::string circle = td::test::error_of([&] { (void)tdm::load_mission(dir / "c.yaml"); });
  EXPECT_NE(circle.find("c.yaml:3: vehicle.log: a log is only read with path: log"), std::string::npos) << circle;
  // A drive the drone cannot follow is refused by its top speed.
  std::ofstream(dir / "fast.csv") << circle_log(30, 12, 0.1, 100, true);
  std::ofstream(dir / "f.yaml") << "vehicle:\n  path: log\n  log: fast.csv\n";
  const std::string fast = td::test::error_of([&] { (void)tdm::load_mission(dir / "f.yaml"); });
  EXPECT_NE(fast.find("vehicle.log: the drone would need"), std::string::npos) << fast;
}
