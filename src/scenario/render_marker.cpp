// The renderer's marker images (render_marker.hpp).
#include "scenario/render_marker.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>

#include "touchdown/core/random.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::scenario::render_detail {

cv::Mat marker_cells(const cv::Ptr<cv::aruco::Dictionary>& dict, int bits, DistractorKind kind, int id,
                     int flipped_bits, int target_id, std::uint64_t flip_seed) {
  const int side = bits + 4;
  cv::Mat cells(side, side, CV_8U, cv::Scalar(255));
  cv::Mat inner = cells(cv::Rect(1, 1, bits + 2, bits + 2));
  if (kind == DistractorKind::WrongId) {
    cv::Mat drawn;
    cv::aruco::drawMarker(dict, id, bits + 2, drawn, 1);
    drawn.copyTo(inner);
    return cells;
  }
  cv::Mat code(bits, bits, CV_8U);
  if (kind == DistractorKind::Lookalike) {
    code = cv::aruco::Dictionary::getBitsFromByteList(dict->bytesList.rowRange(target_id, target_id + 1), bits);
    // Invert `flipped_bits` distinct cells, drawn by a partial Fisher–Yates.
    std::vector<int> order(static_cast<std::size_t>(bits * bits));
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    Rng rng(flip_seed);
    const int flips = std::clamp(flipped_bits, 0, bits * bits);
    for (int i = 0; i < flips; ++i) {
      const auto j = static_cast<std::size_t>(i) +
                     static_cast<std::size_t>(rng.next() % (order.size() - static_cast<std::size_t>(i)));
      std::swap(order[static_cast<std::size_t>(i)], order[j]);
      std::uint8_t& c =
          code.at<std::uint8_t>(order[static_cast<std::size_t>(i)] / bits, order[static_cast<std::size_t>(i)] % bits);
      c = c ? 0 : 1;
    }
  } else {  // pattern: a random grid, seeded by its id
    Rng rng(static_cast<std::uint64_t>(id), 0x9A77E28ull);
    for (int r = 0; r < bits; ++r) {
      for (int c = 0; c < bits; ++c) code.at<std::uint8_t>(r, c) = rng.uniform() < 0.5 ? 1 : 0;
    }
  }
  inner.setTo(0);
  for (int r = 0; r < bits; ++r) {
    for (int c = 0; c < bits; ++c) cells.at<std::uint8_t>(r + 2, c + 2) = code.at<std::uint8_t>(r, c) ? 255 : 0;
  }
  return cells;
}

Quad make_quad(const cv::Mat& cells, Label label, const Eigen::Vector2d& centre, double yaw_deg, double border_size,
               int bits, const CoverSampler& cover, const Eigen::Vector2d& map_shift, const Weather& weather) {
  Quad q;
  q.label = label;
  q.centre = centre;
  q.cos_yaw = std::cos(deg_to_rad(yaw_deg));
  q.sin_yaw = std::sin(deg_to_rad(yaw_deg));
  q.side = border_size * (bits + 4) / (bits + 2);
  const Eigen::Vector2d ex(q.cos_yaw, q.sin_yaw), ey(-q.sin_yaw, q.cos_yaw);
  const double h = 0.5 * q.side;
  // Image top = local +y, image right = local +x (reads correctly from above).
  const std::array<Eigen::Vector2d, 4> c2{centre - h * ex + h * ey, centre + h * ex + h * ey, centre + h * ex - h * ey,
                                          centre - h * ex - h * ey};
  for (std::size_t i = 0; i < 4; ++i) q.corners[i] = Eigen::Vector3d(c2[i].x(), c2[i].y(), 0);
  const int m = cells.cols * kMarkerTexelsPerCell;
  cv::Mat big;
  cv::resize(cells, big, cv::Size(m, m), 0, 0, cv::INTER_NEAREST);
  cv::Mat img(m, m, CV_8UC4);
  const float dark = wet_darkening(weather);
  const double texel = q.side / m;
  for (int y = 0; y < m; ++y) {
    const std::uint8_t* b = big.ptr<std::uint8_t>(y);
    cv::Vec4b* o = img.ptr<cv::Vec4b>(y);
    for (int x = 0; x < m; ++x) {
      cv::Vec3f c = b[x] ? cv::Vec3f(228, 232, 232) : cv::Vec3f(28, 28, 30);
      if (!cover.empty()) {
        // World point of this texel → map → cover texel (periodic), bilinear.
        const double lx = (x + 0.5) * texel - h, ly = h - (y + 0.5) * texel;
        const Eigen::Vector2d p = centre + lx * ex + ly * ey + map_shift;
        const cv::Point2f t(static_cast<float>(p.x() / kGroundTexel - 0.5),
                            static_cast<float>(p.y() / kGroundTexel - 0.5));
        const int tx = floor_int(t.x), ty = floor_int(t.y);
        const float fx = t.x - static_cast<float>(tx), fy = t.y - static_cast<float>(ty);
        cv::Vec3f acc(0, 0, 0);
        float acc_a = 0;
        for (int k = 0; k < 4; ++k) {
          const float wgt = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
          cv::Vec3f colour;
          float alpha = 0;
          if (cover.at(tx + (k & 1), ty + (k >> 1), &colour, &alpha)) {
            acc += (wgt * alpha) * colour;
            acc_a += wgt * alpha;
          }
        }
        c = c * (1 - acc_a) + acc;
      }
      c *= dark;
      o[x] = cv::Vec4b(sat8(c[0]), sat8(c[1]), sat8(c[2]), 255);
    }
  }
  q.mips = mip_chain(img, 8);
  for (const cv::Mat& level : q.mips) {
    q.level_scale.push_back(static_cast<float>(level.cols) / static_cast<float>(q.mips.front().cols));
  }
  return q;
}

}  // namespace touchdown::scenario::render_detail
