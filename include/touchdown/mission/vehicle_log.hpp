#pragma once
/// \file
/// A recorded drive replayed as the pad's vehicle (`vehicle.path: log`,
/// docs/formats.md "Vehicle log"): a CSV of time, x, y, heading and, where
/// the log has it, speed.
///
/// Format: '#' starts a comment, blank lines are skipped, fields are
/// separated by commas (spaces around them allowed). The first line that
/// is not a comment either names the columns — `t` (or `time`), `x`, `y`,
/// `yaw` [rad] or `yaw_deg`, and optionally `speed` [m/s], in any order;
/// other columns are refused by name — or is the first row of a log
/// without a header, whose columns are then t, x, y, yaw [rad] and
/// optionally speed. SI units, world frame of the mission (x, y in metres;
/// heading from +x towards +y). Time starts where the log starts: the
/// mission's t = 0 is the first row.
///
/// Refused, with "source:line: what": a row with another number of fields
/// than the header, a field that is not a finite number, a time not after
/// the row before, a gap between rows longer than `max_gap`, a jump of
/// position faster than 100 m/s, a speed below 0; and a log of fewer than
/// 2 rows or shorter than 1 s.
///
/// Smoothing (`smoothing` > 0, the mission's `vehicle.log_smoothing`): a
/// logged position and heading carry the logger's noise (a GNSS or
/// odometry fix of a few centimetres at 10 Hz), which, replayed as the
/// vehicle's motion, is metres per second squared of jitter the real
/// vehicle never had. Each row's position, unwrapped heading and logged
/// speed, and their rates, are then those of a least-squares parabola over
/// the rows within ±smoothing/2 of it (a Savitzky–Golay filter on the
/// log's own, possibly uneven, times): exact for a motion of constant
/// acceleration; on a circle the position is biased by R ω⁴ w⁴ / 4480
/// and the speed by ω² w² / 40 of itself (0.1 mm and 0.6 % at 2 m/s on 8 m
/// with w = 2 s; a heading turning at a constant rate is exact); the noise of n rows is about √(9/(4n)) of its σ in
/// position and much less in the rates. A row with fewer than 4 rows in its window keeps its
/// own values. 0 replays the rows exactly.
///
/// Between rows: cubic Hermite interpolation of the position (tangents:
/// the logged speed along the logged heading when the log has speed, else
/// the derivative of the positions: three-point, or the smoothing fit's)
/// and of the unwrapped heading, so that velocity and turn rate are
/// continuous; the speed (the logged one, or the velocity along the
/// heading at each row) is interpolated linearly and the forward
/// acceleration is its slope.
/// After the last row the vehicle keeps its last speed and turn rate
/// (constant turn rate and velocity); `duration()` says where the log ends.
/// Thread-safety: a loaded log is immutable; sample() is const.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace touchdown::mission {

/// The vehicle's motion at one time, from the log.
struct LogSample {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< [m]
  double yaw = 0;                                      ///< heading [rad], wrapped to (-π, π]
  double speed = 0;                                    ///< forward [m/s]
  double yaw_rate = 0;                                 ///< [rad/s]
  double acceleration = 0;                             ///< forward [m/s²]
};

class VehicleLog {
 public:
  struct Row {
    double t, x, y, yaw, speed;  ///< yaw [rad], unwrapped; speed NaN when the log has none
  };

  /// Parses a log (see the file comment); throws ParseError
  /// "source:line: what". `max_gap` [s] > 0; `smoothing` [s] ≥ 0 (the
  /// window; 0: the rows exactly), InvalidArgument otherwise.
  static VehicleLog parse(std::string_view text, std::string_view source, double max_gap = 1.0, double smoothing = 0.0);
  /// Reads and parses a file (IoError when it cannot be read).
  static VehicleLog load(const std::filesystem::path& path, double max_gap = 1.0, double smoothing = 0.0);

  /// The log as CSV with a header (`t,x,y,yaw[,speed]`, shortest exact
  /// numbers): parse() of it gives the same rows.
  [[nodiscard]] std::string to_csv() const;

  /// The motion at mission time t ≥ 0 (t = 0 is the first row).
  [[nodiscard]] LogSample sample(double t) const;

  /// The rows as logged (to_csv writes them).
  [[nodiscard]] const std::vector<Row>& rows() const { return rows_; }
  /// The rows as replayed: smoothed when the log was read with smoothing,
  /// else the logged ones.
  [[nodiscard]] const std::vector<Row>& replayed_rows() const { return smooth_; }
  [[nodiscard]] bool has_speed() const { return has_speed_; }
  /// From the first row to the last [s].
  [[nodiscard]] double duration() const { return rows_.back().t - rows_.front().t; }
  /// The largest speed + |turn rate|·offset over the rows: what a drone
  /// holding `offset` metres from the vehicle's centre must fly [m/s].
  [[nodiscard]] double top_speed(double offset) const;
  /// Where the log was read from (for messages).
  [[nodiscard]] const std::string& source() const { return source_; }

 private:
  VehicleLog() = default;
  // The derivatives at each row (position and heading), after parsing.
  void prepare(double smoothing);
  [[nodiscard]] double row_speed(std::size_t i) const;

  std::string source_;
  std::vector<Row> rows_;
  std::vector<Row> smooth_;                ///< the rows replayed (prepare)
  std::vector<Eigen::Vector2d> velocity_;  ///< per row [m/s]
  std::vector<double> yaw_rate_;           ///< per row [rad/s]
  std::vector<double> speed_;              ///< per row, without a speed column [m/s]
  bool has_speed_ = false;
};

}  // namespace touchdown::mission
