// A recorded drive as the pad's vehicle (vehicle_log.hpp): the CSV reader,
// cubic Hermite interpolation (e.g. de Boor, "A Practical Guide to Splines",
// ch. IV) and constant-turn-rate extrapolation after the last row.
#include "touchdown/mission/vehicle_log.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "core/format.hpp"
#include "core/io_util.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::mission {
namespace {

using touchdown::detail::parse_fail;
using touchdown::detail::parse_fail_line;

constexpr double kPi = std::numbers::pi;
constexpr double kMaxJumpSpeed = 100;  // [m/s]: faster between rows is a broken log
constexpr double kMinDuration = 1.0;   // [s]

// The columns, as indices into a row's values.
constexpr std::size_t kT = 0, kX = 1, kY = 2, kYaw = 3, kSpeed = 4, kColumns = 5;

// The slope at t0, t1 or t2 (at = 0, 1, 2) of the parabola through (t0, f0),
// (t1, f1), (t2, f2): second-order derivatives on non-uniform rows, the
// middle one inside the log and the outer ones at its ends.
double three_point(double t0, double f0, double t1, double f1, double t2, double f2, int at) {
  const double h0 = t1 - t0, h1 = t2 - t1, H = h0 + h1;
  if (at == 0) return -(2 * h0 + h1) / (h0 * H) * f0 + H / (h0 * h1) * f1 - h0 / (h1 * H) * f2;
  if (at == 2) return h1 / (h0 * H) * f0 - H / (h0 * h1) * f1 + (2 * h1 + h0) / (h1 * H) * f2;
  return (h1 * h1 * (f1 - f0) + h0 * h0 * (f2 - f1)) / (h0 * h1 * H);
}

struct Hermite {
  std::array<double, 4> value, slope;  // basis weights of p0, h·m0, p1, h·m1 and their derivatives in s
  explicit Hermite(double s) {
    const double s2 = s * s, s3 = s2 * s;
    value = {2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, -2 * s3 + 3 * s2, s3 - s2};
    slope = {6 * s2 - 6 * s, 3 * s2 - 4 * s + 1, -6 * s2 + 6 * s, 3 * s2 - 2 * s};
  }
};

}  // namespace

VehicleLog VehicleLog::parse(std::string_view text, std::string_view source, double max_gap, double smoothing) {
  if (!(max_gap > 0) || !std::isfinite(max_gap)) throw InvalidArgument("vehicle log: max_gap must be positive [s]");
  if (!(smoothing >= 0) || !std::isfinite(smoothing)) throw InvalidArgument("vehicle log: smoothing must be >= 0 [s]");
  VehicleLog log;
  log.source_ = std::string(source);
  std::array<int, kColumns> where{-1, -1, -1, -1, -1};  // the field index of each column
  bool degrees = false;
  std::size_t fields = 0;  // per row, from the header or the first row
  std::size_t previous_line = 0;
  std::vector<std::string_view> parts;
  std::size_t line_no = 0;
  // A UTF-8 byte-order mark (spreadsheets write one) is not part of the header.
  std::size_t start = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view line = touchdown::detail::trim(text.substr(start, end - start));
    start = end + 1;
    ++line_no;
    if (line.empty() || line.front() == '#') continue;
    // Fields: comma-separated, each trimmed.
    parts.clear();
    for (std::size_t b = 0;;) {
      const std::size_t e = std::min(line.find(',', b), line.size());
      parts.push_back(touchdown::detail::trim(line.substr(b, e - b)));
      if (e == line.size()) break;
      b = e + 1;
    }
    double first = 0;
    if (fields == 0) {
      fields = parts.size();
      if (touchdown::detail::parse_double(parts[0], first)) {
        // No header: t, x, y, yaw [rad] and maybe speed.
        if (fields != 4 && fields != 5) {
          parse_fail_line(source, line_no,
                          "a log without a header has the columns t, x, y, yaw [rad] and maybe speed: " +
                              std::to_string(fields) + " fields here");
        }
        for (int c = 0; c < static_cast<int>(fields); ++c) where[static_cast<std::size_t>(c)] = c;
      } else {
        for (std::size_t i = 0; i < parts.size(); ++i) {
          const std::string_view name = parts[i];
          std::size_t c = kColumns;  // none
          if (name == "t" || name == "time") c = kT;
          if (name == "x") c = kX;
          if (name == "y") c = kY;
          if (name == "yaw" || name == "yaw_deg") c = kYaw;
          if (name == "speed") c = kSpeed;
          if (c == kColumns) {
            parse_fail_line(source, line_no,
                            "unknown column '" + std::string(name) +
                                "' (the columns: t or time, x, y, yaw [rad] or "
                                "yaw_deg, speed [m/s] optional)");
          }
          if (where[c] >= 0) {
            parse_fail_line(source, line_no, "column '" + std::string(name) + "' given twice");
          }
          where[c] = static_cast<int>(i);
          degrees = degrees || name == "yaw_deg";
        }
        static constexpr std::array<std::pair<std::size_t, const char*>, 4> kNeeded{
            {{kT, "t (or time)"}, {kX, "x"}, {kY, "y"}, {kYaw, "yaw (or yaw_deg)"}}};
        for (const auto& [c, name] : kNeeded) {
          if (where[c] < 0) parse_fail_line(source, line_no, std::string("no column ") + name);
        }
        log.has_speed_ = where[kSpeed] >= 0;
        continue;
      }
      log.has_speed_ = where[kSpeed] >= 0;
    }
    if (parts.size() != fields) {
      parse_fail_line(source, line_no,
                      std::to_string(parts.size()) + " fields, the log has " + std::to_string(fields) + " columns");
    }
    std::array<double, kColumns> v{0, 0, 0, 0, std::nan("")};
    static constexpr std::array<const char*, kColumns> kNames{"t", "x", "y", "yaw", "speed"};
    for (std::size_t c = 0; c < kColumns; ++c) {
      if (where[c] < 0) continue;
      const std::string_view field = parts[static_cast<std::size_t>(where[c])];
      if (!touchdown::detail::parse_double(field, v[c]) || !std::isfinite(v[c])) {
        parse_fail_line(source, line_no,
                        std::string(kNames[c]) + ": '" + std::string(field) + "' is not a finite number");
      }
    }
    if (degrees) v[kYaw] *= kPi / 180;
    if (log.has_speed_ && v[kSpeed] < 0) {
      parse_fail_line(source, line_no,
                      "speed: " + touchdown::detail::format_general(v[kSpeed]) +
                          " m/s is below 0 (driving backwards is not supported)");
    }
    if (!log.rows_.empty()) {
      const Row& p = log.rows_.back();
      const std::string before = " (line " + std::to_string(previous_line) + ")";
      if (!(v[kT] > p.t)) {
        parse_fail_line(source, line_no,
                        "t: " + touchdown::detail::format_general(v[kT]) + " s is not after the row before's " +
                            touchdown::detail::format_general(p.t) + " s" + before);
      }
      const double dt = v[kT] - p.t;
      if (dt > max_gap) {
        parse_fail_line(source, line_no,
                        "a gap of " + touchdown::detail::format_general(dt) + " s after the row before" + before +
                            ", more than vehicle.log_max_gap " + touchdown::detail::format_general(max_gap) + " s");
      }
      const double jump = std::hypot(v[kX] - p.x, v[kY] - p.y);
      if (jump > kMaxJumpSpeed * dt) {
        parse_fail_line(source, line_no,
                        "a jump of " + touchdown::detail::format_general(jump) + " m in " +
                            touchdown::detail::format_general(dt) + " s since the row before" + before +
                            " (faster than 100 m/s: not a drive)");
      }
      // The heading unwrapped: within π of the row before.
      v[kYaw] = p.yaw + std::remainder(v[kYaw] - p.yaw, 2 * kPi);
    }
    log.rows_.push_back({v[kT], v[kX], v[kY], v[kYaw], v[kSpeed]});
    previous_line = line_no;
  }
  if (log.rows_.size() < 2) {
    parse_fail(source, "too short: " + touchdown::detail::count_noun(static_cast<long long>(log.rows_.size()), "row") +
                           " (a log needs at least 2, over " + touchdown::detail::format_general(kMinDuration) +
                           " s or more)");
  }
  if (log.duration() < kMinDuration) {
    parse_fail(source, "too short: " + touchdown::detail::format_general(log.duration()) + " s (at least " +
                           touchdown::detail::format_general(kMinDuration) + " s)");
  }
  log.prepare(smoothing);
  return log;
}

VehicleLog VehicleLog::load(const std::filesystem::path& path, double max_gap, double smoothing) {
  return parse(touchdown::detail::read_text_file(path), path.string(), max_gap, smoothing);
}

void VehicleLog::prepare(double smoothing) {
  const std::size_t n = rows_.size();
  smooth_ = rows_;
  velocity_.resize(n);
  yaw_rate_.resize(n);
  // Smoothing: each row's value and rate from the least-squares parabola
  // over the rows within ±smoothing/2 (times relative to the row's own).
  std::vector<Eigen::Vector4d> rate(n, Eigen::Vector4d::Constant(std::numeric_limits<double>::quiet_NaN()));
  if (smoothing > 0) {
    std::size_t lo = 0, hi = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double t = rows_[i].t;
      while (rows_[lo].t < t - 0.5 * smoothing) ++lo;
      while (hi + 1 < n && rows_[hi + 1].t <= t + 0.5 * smoothing) ++hi;
      if (hi - lo + 1 < 4) continue;
      Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
      Eigen::Matrix<double, 3, 4> b = Eigen::Matrix<double, 3, 4>::Zero();
      for (std::size_t j = lo; j <= hi; ++j) {
        const Row& r = rows_[j];
        const double tau = r.t - t;
        const Eigen::Vector3d phi(1, tau, tau * tau);
        A += phi * phi.transpose();
        b += phi * Eigen::RowVector4d(r.x, r.y, r.yaw, has_speed_ ? r.speed : 0.0);
      }
      const Eigen::Matrix<double, 3, 4> c = A.ldlt().solve(b);
      if (!c.allFinite()) continue;
      Row& s = smooth_[i];
      s.x = c(0, 0);
      s.y = c(0, 1);
      s.yaw = c(0, 2);
      if (has_speed_) s.speed = std::max(0.0, c(0, 3));
      rate[i] = c.row(1).transpose();
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Row& r = smooth_[i];
    // The three rows around row i (two rows: the chord), or the fit's rate.
    const auto derivative = [&](double Row::*f, int k) {
      if (std::isfinite(rate[i][k])) return rate[i][k];
      if (n == 2) return (smooth_[1].*f - smooth_[0].*f) / (smooth_[1].t - smooth_[0].t);
      const std::size_t a = std::clamp<std::size_t>(i, 1, n - 2) - 1;
      const Row &r0 = smooth_[a], &r1 = smooth_[a + 1], &r2 = smooth_[a + 2];
      return three_point(r0.t, r0.*f, r1.t, r1.*f, r2.t, r2.*f, static_cast<int>(i - a));
    };
    yaw_rate_[i] = derivative(&Row::yaw, 2);
    velocity_[i] = has_speed_ ? Eigen::Vector2d(r.speed * std::cos(r.yaw), r.speed * std::sin(r.yaw))
                              : Eigen::Vector2d(derivative(&Row::x, 0), derivative(&Row::y, 1));
  }
  // Without a speed column: the speed at each row is the velocity along the
  // heading there, interpolated between rows as a logged one would be.
  if (!has_speed_) {
    for (std::size_t i = 0; i < n; ++i) {
      speed_.push_back(velocity_[i].dot(Eigen::Vector2d(std::cos(smooth_[i].yaw), std::sin(smooth_[i].yaw))));
    }
  }
}

double VehicleLog::row_speed(std::size_t i) const { return has_speed_ ? smooth_[i].speed : speed_[i]; }

LogSample VehicleLog::sample(double t) const {
  const double tt = smooth_.front().t + std::max(t, 0.0);
  LogSample out;
  if (tt >= smooth_.back().t) {
    // Constant turn rate and velocity from the last row.
    const Row& r = smooth_.back();
    const Eigen::Vector2d heading(std::cos(r.yaw), std::sin(r.yaw));
    const double v = row_speed(smooth_.size() - 1), w = yaw_rate_.back(), dt = tt - r.t;
    const double yaw = r.yaw + w * dt;
    const Eigen::Vector2d travelled =
        std::abs(w * dt) > 1e-9
            ? Eigen::Vector2d(v / w * (std::sin(yaw) - std::sin(r.yaw)), -v / w * (std::cos(yaw) - std::cos(r.yaw)))
            : Eigen::Vector2d(v * dt * heading);
    out.position = Eigen::Vector2d(r.x, r.y) + travelled;
    out.yaw = std::remainder(yaw, 2 * kPi);
    out.speed = v;
    out.yaw_rate = w;
    return out;
  }
  const auto it = std::upper_bound(smooth_.begin(), smooth_.end(), tt, [](double x, const Row& r) { return x < r.t; });
  const std::size_t i = static_cast<std::size_t>(it - smooth_.begin()) - 1;
  const Row &r0 = smooth_[i], &r1 = smooth_[i + 1];
  const double h = r1.t - r0.t;
  const Hermite b((tt - r0.t) / h);
  const Eigen::Vector2d p0(r0.x, r0.y), p1(r1.x, r1.y), m0 = h * velocity_[i], m1 = h * velocity_[i + 1];
  out.position = b.value[0] * p0 + b.value[1] * m0 + b.value[2] * p1 + b.value[3] * m1;
  const double yaw =
      b.value[0] * r0.yaw + b.value[1] * h * yaw_rate_[i] + b.value[2] * r1.yaw + b.value[3] * h * yaw_rate_[i + 1];
  out.yaw_rate =
      (b.slope[0] * r0.yaw + b.slope[1] * h * yaw_rate_[i] + b.slope[2] * r1.yaw + b.slope[3] * h * yaw_rate_[i + 1]) /
      h;
  out.yaw = std::remainder(yaw, 2 * kPi);
  const double v0 = row_speed(i), v1 = row_speed(i + 1);
  out.speed = v0 + (tt - r0.t) / h * (v1 - v0);
  out.acceleration = (v1 - v0) / h;
  return out;
}

double VehicleLog::top_speed(double offset) const {
  double top = 0;
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    top = std::max(top, std::abs(row_speed(i)) + std::abs(yaw_rate_[i]) * offset);
  }
  return top;
}

std::string VehicleLog::to_csv() const {
  std::string out = has_speed_ ? "t,x,y,yaw,speed\n" : "t,x,y,yaw\n";
  for (const Row& r : rows_) {
    out += touchdown::detail::format_exact(r.t) + "," + touchdown::detail::format_exact(r.x) + "," +
           touchdown::detail::format_exact(r.y) + "," + touchdown::detail::format_exact(r.yaw);
    if (has_speed_) out += "," + touchdown::detail::format_exact(r.speed);
    out += "\n";
  }
  return out;
}

}  // namespace touchdown::mission
