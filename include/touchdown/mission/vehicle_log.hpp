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
/// Between rows: cubic Hermite interpolation of the position (tangents:
/// the logged speed along the logged heading when the log has speed, else
/// the three-point derivative of the positions) and of the unwrapped
/// heading, so that velocity and turn rate are continuous; the speed (the
/// logged one, or the velocity along the heading at each row) is
/// interpolated linearly and the forward acceleration is its slope.
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
  /// "source:line: what". `max_gap` [s] > 0.
  static VehicleLog parse(std::string_view text, std::string_view source, double max_gap = 1.0);
  /// Reads and parses a file (IoError when it cannot be read).
  static VehicleLog load(const std::filesystem::path& path, double max_gap = 1.0);

  /// The log as CSV with a header (`t,x,y,yaw[,speed]`, shortest exact
  /// numbers): parse() of it gives the same rows.
  [[nodiscard]] std::string to_csv() const;

  /// The motion at mission time t ≥ 0 (t = 0 is the first row).
  [[nodiscard]] LogSample sample(double t) const;

  [[nodiscard]] const std::vector<Row>& rows() const { return rows_; }
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
  void prepare();
  [[nodiscard]] double row_speed(std::size_t i) const;

  std::string source_;
  std::vector<Row> rows_;
  std::vector<Eigen::Vector2d> velocity_;  ///< per row [m/s]
  std::vector<double> yaw_rate_;           ///< per row [rad/s]
  std::vector<double> speed_;              ///< per row, without a speed column [m/s]
  bool has_speed_ = false;
};

}  // namespace touchdown::mission
