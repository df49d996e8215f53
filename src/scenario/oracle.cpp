// The observability oracle (oracle.hpp): can a camera read the target marker
// in a rendered frame? Geometry from the scenario's truth, legibility
// measured in the frame's pixels cell by cell.
#include "touchdown/scenario/oracle.hpp"

#include <cmath>
#include <opencv2/aruco.hpp>

#include "scenario/render_marker.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"

namespace touchdown::scenario {

bool OracleOptions::validate(std::string* why) const {
  auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (!in(sighting_time, 0, 600)) return invalid(why, "sighting_time: must be in [0, 600] s");
  if (!in(max_gap, 0, 60)) return invalid(why, "max_gap: must be in [0, 60] s");
  if (!in(min_cell_px, 0, 100)) return invalid(why, "min_cell_px: must be in [0, 100] px");
  if (!in(min_visible_fraction, 0, 1)) return invalid(why, "min_visible_fraction: must be in [0, 1]");
  if (!in(min_contrast, 0, 255)) return invalid(why, "min_contrast: must be in [0, 255] grey levels");
  if (!in(min_snr, 0, 1000)) return invalid(why, "min_snr: must be in [0, 1000]");
  if (!in(noise_floor, 0, 255)) return invalid(why, "noise_floor: must be in [0, 255] grey levels");
  if (!in(max_view_angle_deg, 0, 90)) return invalid(why, "max_view_angle_deg: must be in [0, 90]");
  if (!in(probe_altitude, 1, 200)) return invalid(why, "probe_altitude: must be in [1, 200] m");
  if (!in(probe_rate_hz, 0.1, 100)) return invalid(why, "probe_rate_hz: must be in [0.1, 100]");
  if (probe_size_px < 16 || probe_size_px > 1024) return invalid(why, "probe_size_px: must be in [16, 1024]");
  return true;
}

TargetOracle::TargetOracle(const Scenario& scenario, const OracleOptions& options) : options_(options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("oracle." + why);
  const auto* info = pose::find_aruco_dictionary(scenario.marker.dictionary);
  if (!info) throw InvalidArgument("marker.dictionary: unknown " + scenario.marker.dictionary);
  if (scenario.marker.id < 0 || scenario.marker.id >= info->codes)
    throw InvalidArgument("marker.id: " + std::to_string(scenario.marker.id) + " is not in " + std::string(info->name));
  const cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(info->opencv_id);
  // The renderer's own cells (with the white margin): the code as printed.
  const cv::Mat cells =
      render_detail::marker_cells(dict, info->bits, DistractorKind::WrongId, scenario.marker.id, 0, 0, 0);
  n_ = info->bits + 2;
  correctable_ = dict->maxCorrectionBits;
  const int m = n_ + 2;  // with the white margin
  white_.resize(static_cast<std::size_t>(m * m));
  for (int r = 0; r < m; ++r) {
    for (int c = 0; c < m; ++c) white_[static_cast<std::size_t>(r * m + c)] = cells.at<std::uint8_t>(r, c) != 0;
  }
  centre_ = scenario.marker.position;
  cos_yaw_ = std::cos(deg_to_rad(scenario.marker.yaw_deg));
  sin_yaw_ = std::sin(deg_to_rad(scenario.marker.yaw_deg));
  size_ = scenario.marker.size;
}

namespace {

/// Per-cell sums of the grey levels sampled in a cell's middle.
struct CellStats {
  double sum = 0, sum2 = 0;
  int n = 0;
};

}  // namespace

TargetView TargetOracle::observe(const CameraFrame& frame, const Eigen::Isometry3d& T_world_camera,
                                 const CameraOptions& camera) const {
  TargetView v;
  const double f = camera.fx(), cx = 0.5 * (camera.width - 1), cy = 0.5 * (camera.height - 1);
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  const Eigen::Vector2d ex(cos_yaw_, sin_yaw_), ey(-sin_yaw_, cos_yaw_);
  const double h = 0.5 * size_, cell = size_ / n_, hm = h + cell;
  // Corners, top-left, top-right, bottom-right, bottom-left of the marker
  // image (image top = local +y): of the bordered code (px) and of the
  // printed marker with its white margin, which must be in the image.
  const auto corner = [&](double half, std::size_t i) -> Eigen::Vector2d {
    const double sx = (i == 1 || i == 2) ? 1 : -1, sy = i < 2 ? 1 : -1;
    return centre_ + sx * half * ex + sy * half * ey;
  };
  const auto pixel = [&](const Eigen::Vector2d& g, Eigen::Vector2d* out) {
    const Eigen::Vector3d pc = T_camera_world * Eigen::Vector3d(g.x(), g.y(), 0);
    if (pc.z() <= 1e-6) return false;
    *out = Eigen::Vector2d(f * pc.x() / pc.z() + cx, f * pc.y() / pc.z() + cy);
    return out->x() >= 1 && out->y() >= 1 && out->x() <= camera.width - 2 && out->y() <= camera.height - 2;
  };
  std::array<Eigen::Vector2d, 4> px, pm;
  bool inside = frame.width == camera.width && frame.height == camera.height;
  for (std::size_t i = 0; i < 4 && inside; ++i) inside = pixel(corner(hm, i), &pm[i]) && pixel(corner(h, i), &px[i]);
  if (!inside) return v;  // out of view
  v.side_px = (px[0] - px[3]).norm();
  for (std::size_t i = 0; i < 3; ++i) v.side_px = std::min(v.side_px, (px[i + 1] - px[i]).norm());
  const Eigen::Vector3d c = T_world_camera.translation();
  const Eigen::Vector3d sight = Eigen::Vector3d(centre_.x(), centre_.y(), 0) - c;
  v.view_angle_deg = rad_to_deg(std::acos(std::clamp(-sight.z() / sight.norm(), -1.0, 1.0)));
  if (v.side_px < options_.min_cell_px * n_) {
    v.sight = Sight::TooSmall;
    return v;
  }
  if (v.view_angle_deg > options_.max_view_angle_deg) {
    v.sight = Sight::Oblique;
    return v;
  }

  // Sample the code's cells: ≤ ~4096 pixels of its bounding box, each
  // pixel's ray meeting the ground in a cell's middle 60 %.
  // The bounding box of the marker with its margin.
  double u0 = pm[0].x(), u1 = u0, v0 = pm[0].y(), v1 = v0;
  for (const Eigen::Vector2d& p : pm) {
    u0 = std::min(u0, p.x()), u1 = std::max(u1, p.x()), v0 = std::min(v0, p.y()), v1 = std::max(v1, p.y());
  }
  const int x0 = static_cast<int>(std::floor(u0)), x1 = static_cast<int>(std::ceil(u1));
  const int y0 = static_cast<int>(std::floor(v0)), y1 = static_cast<int>(std::ceil(v1));
  const int stride = std::max(1, static_cast<int>(std::sqrt((x1 - x0 + 1.0) * (y1 - y0 + 1.0) / 4096.0)));
  const Eigen::Matrix3d R_wc = T_world_camera.linear();
  // The grid includes the one-cell white margin (ArUco finds the border as
  // a dark contour inside a light one: leaves or snow on the margin break it).
  const int m = n_ + 2;
  std::vector<CellStats> stats(static_cast<std::size_t>(m * m));
  int inside_px = 0, visible_px = 0;
  const std::uint8_t marker_label = mask_value(Label::Marker);
  for (int y = y0; y <= y1; y += stride) {
    for (int x = x0; x <= x1; x += stride) {
      const std::size_t k =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(frame.width) + static_cast<std::size_t>(x);
      // The pixel's ray meets the ground inside the code, or not; what the
      // mask shows there is the code itself (visible) or something in front.
      const Eigen::Vector3d ray = R_wc * Eigen::Vector3d((x - cx) / f, (y - cy) / f, 1.0);
      if (ray.z() >= -1e-9) continue;
      const Eigen::Vector3d g = c + (-c.z() / ray.z()) * ray;
      const Eigen::Vector2d d = g.head<2>() - centre_;
      const double lx = d.dot(ex) + hm, ly = hm - d.dot(ey);  // from the margin's top-left
      const double fc = lx / cell, fr = ly / cell;
      const int col = static_cast<int>(std::floor(fc)), row = static_cast<int>(std::floor(fr));
      if (col < 0 || row < 0 || col >= m || row >= m) continue;
      ++inside_px;
      if (frame.mask[k] != marker_label) continue;
      ++visible_px;
      const double ax = fc - col, ay = fr - row;
      if (ax < 0.2 || ax > 0.8 || ay < 0.2 || ay > 0.8) continue;
      const std::uint8_t* p = frame.image.pixels.data() + 3 * k;
      const double grey = (p[0] + p[1] + p[2]) / 3.0;
      CellStats& s = stats[static_cast<std::size_t>(row * m + col)];
      s.sum += grey, s.sum2 += grey * grey, ++s.n;
    }
  }
  v.visible_fraction = inside_px > 0 ? static_cast<double>(visible_px) / inside_px : 0.0;
  if (v.visible_fraction < options_.min_visible_fraction) {
    v.sight = Sight::Hidden;
    return v;
  }
  // Contrast: the mean of the white cells' means minus that of the black.
  double white_sum = 0, black_sum = 0, within = 0;
  int whites = 0, blacks = 0, dof = 0;
  const auto ring = [m](int r, int k) { return std::min(std::min(r, k), std::min(m - 1 - r, m - 1 - k)); };
  for (std::size_t i = 0; i < stats.size(); ++i) {
    const CellStats& s = stats[i];
    // The contrast is the bordered code's; the margin is only read.
    if (s.n == 0 || ring(static_cast<int>(i) / m, static_cast<int>(i) % m) == 0) continue;
    const double mean = s.sum / s.n;
    (white_[i] ? white_sum : black_sum) += mean;
    (white_[i] ? whites : blacks) += 1;
    within += std::max(0.0, s.sum2 - s.n * mean * mean);
    dof += s.n - 1;
  }
  if (whites == 0 || blacks == 0) {
    v.sight = Sight::Covered;  // nothing readable of one colour
    v.misread_border = 4 * (m - 1) + 4 * (n_ - 1);
    return v;
  }
  v.contrast = white_sum / whites - black_sum / blacks;
  v.noise = dof > 0 ? std::sqrt(within / dof) : 0.0;
  const double mid = 0.5 * (white_sum / whites + black_sum / blacks);
  int unseen = 0;
  for (int r = 0; r < m; ++r) {
    for (int col = 0; col < m; ++col) {
      const auto i = static_cast<std::size_t>(r * m + col);
      const CellStats& s = stats[i];
      unseen += s.n == 0;
      const bool misread = s.n == 0 || ((s.sum / s.n >= mid) != (white_[i] != 0));
      if (!misread) continue;
      ++(ring(r, col) <= 1 ? v.misread_border : v.misread_code);
    }
  }
  if (v.contrast < options_.min_contrast) {
    v.sight = Sight::LowContrast;
  } else if (v.contrast < options_.min_snr * std::hypot(v.noise, options_.noise_floor)) {
    v.sight = Sight::Noisy;
  } else if (unseen > 0) {
    // A cell without a pixel in its middle: hidden by a sliver of an object,
    // or cells too few pixels wide to be read.
    v.sight = v.visible_fraction < 0.999 ? Sight::Hidden : Sight::TooSmall;
  } else if (v.misread_border > 0 || v.misread_code > correctable_) {
    v.sight = Sight::Covered;
  } else {
    v.sight = Sight::Observable;
  }
  return v;
}

double longest_stretch(const std::vector<double>& t, const std::vector<char>& ok, double period, double max_gap) {
  double best = 0;
  bool open = false;
  double first = 0, last = 0;
  for (std::size_t i = 0; i < t.size() && i < ok.size(); ++i) {
    if (!ok[i]) continue;
    if (open && t[i] - last <= max_gap + period + 1e-9) {
      last = t[i];
    } else {
      open = true;
      first = last = t[i];
    }
    best = std::max(best, last - first + period);
  }
  return best;
}

}  // namespace touchdown::scenario
