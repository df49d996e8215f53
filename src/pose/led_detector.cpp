#include "touchdown/pose/led_detector.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "touchdown/core/error.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::pose {

bool DetectorOptions::validate(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (threshold < 1 || threshold > 255) return fail("threshold: must be in 1..255");
  if (background < 0 || background >= threshold) return fail("background: must be in 0..threshold-1");
  if (min_area < 1 || max_area < min_area) return fail("min_area/max_area: need 1 <= min_area <= max_area");
  if (refine_margin < 0 || refine_margin > 16) return fail("refine_margin: must be in 0..16");
  if (split_prominence < 0 || split_prominence > 765) return fail("split_prominence: must be in 0..765");
  if (!(white_saturation >= 0 && white_saturation <= 1)) return fail("white_saturation: must be in [0, 1]");
  if (saturation_level < 1 || saturation_level > 255) return fail("saturation_level: must be in 1..255");
  if (!(min_colour_evidence >= 0) || !std::isfinite(min_colour_evidence))
    return fail("min_colour_evidence: must be >= 0");
  if (!(min_hue_coherence >= 0 && min_hue_coherence <= 1)) return fail("min_hue_coherence: must be in [0, 1]");
  if (!(min_depth >= 0 && max_depth > min_depth)) return fail("min_depth/max_depth: need 0 <= min_depth < max_depth");
  if (depth_window < 0 || depth_window > 3) return fail("depth_window: must be in 0..3");
  if (max_blobs < 1) return fail("max_blobs: must be positive");
  return true;
}

Eigen::Vector3d bgr_to_hsv(const Eigen::Vector3d& bgr) {
  const double b = bgr(0), g = bgr(1), r = bgr(2);
  const double mx = std::max({b, g, r}), mn = std::min({b, g, r});
  const double d = mx - mn;
  double h = 0;
  if (d > 0) {
    if (mx == r) {
      h = 60.0 * (g - b) / d;
    } else if (mx == g) {
      h = 120.0 + 60.0 * (b - r) / d;
    } else {
      h = 240.0 + 60.0 * (r - g) / d;
    }
    if (h < 0) h += 360.0;
  }
  return {h, mx > 0 ? d / mx : 0.0, mx / 255.0};
}

LedColor classify_color(const Eigen::Vector3d& hsv, double white_saturation) {
  if (hsv(1) < white_saturation) return LedColor::White;
  const double h = hsv(0);
  if (h < 30 || h >= 330) return LedColor::Red;
  if (h >= 75 && h < 165) return LedColor::Green;
  if (h >= 195 && h < 265) return LedColor::Blue;
  return LedColor::Unknown;
}

namespace {

// Hue evidence of a set of pixels: the chroma-plane vectors
// α = R − (G + B)/2, β = √3/2 (G − B) (whose angle is the hue and whose
// length is the chroma of the hexagonal HSV model, to within 13 %; a
// neutral background adds nothing to them), summed; the summed brightest
// channel (the saturation's denominator) and the summed brightness above
// the background (the amount of evidence).
struct HueEvidence {
  double a = 0, b = 0;   // Σ α, Σ β
  double chroma = 0;     // Σ |(α, β)|
  double brightest = 0;  // Σ max channel
  double value = 0;      // Σ (max channel − background)
  int pixels = 0;

  void add(int blue, int green, int red, int max_channel, double above_background) {
    const double al = red - 0.5 * (green + blue), be = 0.8660254037844386 * (green - blue);
    a += al;
    b += be;
    chroma += std::sqrt(al * al + be * be);
    brightest += max_channel;
    value += above_background;
    ++pixels;
  }
};

// The class the evidence supports, with its (H, S, V) in `hsv`.
LedColor classify_evidence(const HueEvidence& e, const DetectorOptions& o, Eigen::Vector3d& hsv) {
  double hue = rad_to_deg(std::atan2(e.b, e.a));
  if (hue < 0) hue += 360.0;
  const double saturation = e.brightest > 0 ? std::min(1.0, e.chroma / e.brightest) : 0.0;
  hsv = {hue, saturation, e.pixels ? std::min(1.0, e.value / e.pixels / 255.0) : 0.0};
  if (saturation < o.white_saturation) return LedColor::White;
  const double coherence = e.chroma > 0 ? std::hypot(e.a, e.b) / e.chroma : 0.0;
  if (coherence < o.min_hue_coherence) return LedColor::Unknown;
  return classify_color({hue, 1.0, 1.0}, o.white_saturation);
}

}  // namespace

struct LedDetector::Impl {
  CameraModel camera;
  DetectorOptions options;
  struct Run {
    int y, x0, x1;  // x1 exclusive
    int parent;
  };
  struct Component {
    int area;
    int x0, y0, x1, y1;  // inclusive bounding box
  };
  struct Window {
    int x0, y0, x1, y1;  // inclusive
  };
  // A basin of the split's flood (split()).
  struct Basin {
    std::int32_t parent;
    int peak;             // highest channel sum
    int lit = 0;          // pixels of the component (brightest channel >= threshold)
    bool border = false;  // its peak lies on the window's border: another source's glow
    int saddle = -1;      // channel sum where it first met a basin kept apart from it
  };
  static constexpr int kMaxSplitWindow = 4096;  // larger windows (lamps) are not split [px]
  std::vector<Run> runs;
  std::vector<int> row_start;
  std::vector<std::int32_t> split_labels, split_order;
  std::vector<Basin> basins;
  std::array<int, 3 * 255 + 2> split_hist{};
  bool labels_valid = false;
  std::vector<Component> components;
  std::vector<int> component_of;  // per run (indexed by root)

  int find(int i) {
    while (runs[static_cast<std::size_t>(i)].parent != i) {
      auto& r = runs[static_cast<std::size_t>(i)];
      r.parent = runs[static_cast<std::size_t>(r.parent)].parent;  // path halving
      i = r.parent;
    }
    return i;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (a < b) {
      runs[static_cast<std::size_t>(b)].parent = a;
    } else {
      runs[static_cast<std::size_t>(a)].parent = b;
    }
  }

  void label(const BgrImageView& img) {
    runs.clear();
    row_start.resize(static_cast<std::size_t>(img.height) + 1);
    const auto thr = static_cast<std::uint8_t>(options.threshold);
    const bool word_skip = options.threshold >= 128;
    for (int y = 0; y < img.height; ++y) {
      row_start[static_cast<std::size_t>(y)] = static_cast<int>(runs.size());
      const std::uint8_t* p = img.row(y);
      int x = 0;
      const int w = img.width;
      auto dark = [&](int i) { return p[3 * i] < thr && p[3 * i + 1] < thr && p[3 * i + 2] < thr; };
      const std::size_t end = 3 * static_cast<std::size_t>(w);
      while (x < w) {
        if (word_skip) {
          // A low-exposure frame is almost all dark: skip 8 bytes at a time
          // while no byte has its high bit set (all < 128 <= threshold).
          std::size_t i = 3 * static_cast<std::size_t>(x);
          while (i + 8 <= end) {
            std::uint64_t v;
            std::memcpy(&v, p + i, 8);
            if (v & 0x8080808080808080ull) break;
            i += 8;
          }
          x = static_cast<int>(i / 3);
          const int stop = std::min(w, static_cast<int>((i + 8) / 3) + 1);
          while (x < stop && dark(x)) ++x;
          if (x >= w) break;
          if (x == stop) continue;  // only bright-ish bytes below the threshold: skip on
        } else {
          while (x < w && dark(x)) ++x;
          if (x >= w) break;
        }
        const int x0 = x;
        while (x < w && !dark(x)) ++x;
        const int id = static_cast<int>(runs.size());
        runs.push_back({y, x0, x, id});
      }
      if (y > 0) {
        // Join with overlapping runs of the previous row (8-connectivity).
        int a = row_start[static_cast<std::size_t>(y - 1)];
        const int a_end = row_start[static_cast<std::size_t>(y)];
        for (int b = a_end; b < static_cast<int>(runs.size()); ++b) {
          const Run& rb = runs[static_cast<std::size_t>(b)];
          while (a < a_end && runs[static_cast<std::size_t>(a)].x1 < rb.x0)
            ++a;  // ends left of rb (x1 exclusive: touches diagonally if x1 == x0)
          for (int k = a; k < a_end && runs[static_cast<std::size_t>(k)].x0 <= rb.x1; ++k) unite(b, k);
        }
      }
    }
    row_start[static_cast<std::size_t>(img.height)] = static_cast<int>(runs.size());
    // Components: one per root (a root is the lowest-numbered run of its
    // set, so it is met before the other runs of the set).
    components.clear();
    component_of.assign(runs.size(), -1);
    for (int i = 0; i < static_cast<int>(runs.size()); ++i) {
      const auto r = static_cast<std::size_t>(find(i));
      const Run& run = runs[static_cast<std::size_t>(i)];
      if (component_of[r] < 0) {
        component_of[r] = static_cast<int>(components.size());
        components.push_back({0, run.x0, run.y, run.x1 - 1, run.y});
      }
      Component& comp = components[static_cast<std::size_t>(component_of[r])];
      comp.area += run.x1 - run.x0;
      comp.x0 = std::min(comp.x0, run.x0);
      comp.x1 = std::max(comp.x1, run.x1 - 1);
      comp.y1 = std::max(comp.y1, run.y);
    }
  }

  // True when another lit component lies within reach of c's window: its
  // glow may then tilt c's background (the plane fit below is needed), else
  // a constant level is exact for a symmetric spot and the plane's tilt
  // would only follow the spot's own glow on a window that is not centred
  // on it (integer bounding box).
  bool crowded(const Component& c) const {
    const int reach = options.refine_margin + std::max({8, c.x1 - c.x0 + 1, c.y1 - c.y0 + 1});
    for (const Component& o : components) {
      if (&o == &c) continue;
      const int gap_x = std::max({0, o.x0 - c.x1, c.x0 - o.x1});
      const int gap_y = std::max({0, o.y0 - c.y1, c.y0 - o.y1});
      if (std::max(gap_x, gap_y) <= reach) return true;
    }
    return false;
  }

  std::int32_t basin_root(std::int32_t i) {
    while (basins[static_cast<std::size_t>(i)].parent != i) {
      auto& bs = basins[static_cast<std::size_t>(i)];
      bs.parent = basins[static_cast<std::size_t>(bs.parent)].parent;
      i = bs.parent;
    }
    return i;
  }

  // Splits a component that holds more than one spot: an LED merged with
  // its reflection off the airframe, a lamp or a neighbouring LED (seen at
  // range, where the spots' glows touch). A threshold cannot part them and
  // their brightest channel is often clipped in both, but the channel sum
  // (a white-clipped LED core 765, a colour-clipped reflection less) dips
  // between them. Watershed by flooding (Vincent & Soille 1991): the
  // window's pixels in decreasing channel sum grow basins from the local
  // maxima; where two basins meet, the one with the lower peak is merged
  // into the other unless its prominence (peak − the meeting level) is at
  // least split_prominence and 10 % of its peak, and it holds pixels of the
  // component or peaks on the window's border (the glow of a source outside
  // the window rising toward it: its pixels belong to no spot of c). An
  // unlit glow maximum inside the window is never a spot. Returns the number
  // of basins left with at least min_area lit pixels (1 if the window is not
  // flooded: labels_valid false); split_labels then holds each window
  // pixel's basin root.
  int split(const BgrImageView& img, const Component& c) {
    const Window win = window_of(img, c);
    const int x0 = win.x0, y0 = win.y0, x1 = win.x1, y1 = win.y1;
    const int ww = x1 - x0 + 1, wh = y1 - y0 + 1, n = ww * wh;
    labels_valid = false;
    if (options.split_prominence <= 0 || n > kMaxSplitWindow) return 1;
    labels_valid = true;
    split_labels.assign(static_cast<std::size_t>(n), -1);
    split_order.resize(static_cast<std::size_t>(n));
    basins.clear();
    // Counting sort by channel sum, brightest first.
    split_hist.fill(0);
    auto sum_at = [&](int i) {
      const std::uint8_t* p = img.row(y0 + i / ww) + 3 * (x0 + i % ww);
      return p[0] + p[1] + p[2];
    };
    for (int i = 0; i < n; ++i) ++split_hist[static_cast<std::size_t>(765 - sum_at(i) + 1)];
    for (std::size_t v = 1; v < split_hist.size(); ++v) split_hist[v] += split_hist[v - 1];
    for (int i = 0; i < n; ++i)
      split_order[static_cast<std::size_t>(split_hist[static_cast<std::size_t>(765 - sum_at(i))]++)] = i;
    for (const std::int32_t i : split_order) {
      const int px = x0 + i % ww, py = y0 + i / ww;
      const std::uint8_t* p = img.row(py) + 3 * px;
      const int v = p[0] + p[1] + p[2];
      const bool lit =
          std::max({p[0], p[1], p[2]}) >= options.threshold && px >= c.x0 && px <= c.x1 && py >= c.y0 && py <= c.y1;
      std::array<std::int32_t, 8> roots{};
      int k = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = px + dx - x0, qy = py + dy - y0;
          if ((dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= ww || qy >= wh) continue;
          const std::int32_t l = split_labels[static_cast<std::size_t>(qy * ww + qx)];
          if (l < 0) continue;
          const std::int32_t r = basin_root(l);
          if (std::find(roots.begin(), roots.begin() + k, r) == roots.begin() + k)
            roots[static_cast<std::size_t>(k++)] = r;
        }
      }
      std::int32_t own;
      if (k == 0) {
        own = static_cast<std::int32_t>(basins.size());
        basins.push_back({own, v, 0, px == x0 || px == x1 || py == y0 || py == y1, -1});
      } else {
        own = roots[0];  // the highest peak
        for (int j = 1; j < k; ++j) {
          if (basins[static_cast<std::size_t>(roots[static_cast<std::size_t>(j)])].peak >
              basins[static_cast<std::size_t>(own)].peak) {
            own = roots[static_cast<std::size_t>(j)];
          }
        }
        for (int j = 0; j < k; ++j) {
          const std::int32_t r = roots[static_cast<std::size_t>(j)];
          if (r == own) continue;
          Basin& low = basins[static_cast<std::size_t>(r)];
          const int prominence = low.peak - v;
          if ((low.lit > 0 || low.border) && prominence >= options.split_prominence && 10 * prominence >= low.peak) {
            low.saddle = std::max(low.saddle, v);
            Basin& high = basins[static_cast<std::size_t>(own)];
            high.saddle = std::max(high.saddle, v);
            continue;
          }
          low.parent = own;
          basins[static_cast<std::size_t>(own)].lit += low.lit;
        }
      }
      split_labels[static_cast<std::size_t>(i)] = own;
      if (lit) ++basins[static_cast<std::size_t>(own)].lit;
    }
    int spots = 0;
    for (std::int32_t& l : split_labels) {
      l = basin_root(l);
    }
    for (std::size_t b = 0; b < basins.size(); ++b) {
      if (basins[b].parent == static_cast<std::int32_t>(b) && basins[b].lit >= options.min_area) ++spots;
    }
    return spots;
  }

  // The window the centre and colour of c are measured over: its bounding
  // box grown by refine_margin, clipped to the image.
  Window window_of(const BgrImageView& img, const Component& c) const {
    const int m = options.refine_margin;
    return {std::max(0, c.x0 - m), std::max(0, c.y0 - m), std::min(img.width - 1, c.x1 + m),
            std::min(img.height - 1, c.y1 + m)};
  }

  // Which pixels of a component's window make one blob.
  struct Spot {
    const std::int32_t* labels = nullptr;  // a split component: per window pixel (row by row) its basin
    std::int32_t label = 0;                // ... and only pixels labelled so count
    int area = 0;                          // the blob's lit pixels
    int min_sum = -1;                      // the centre uses only pixels whose channel sum exceeds this
    bool tilted_background = false;        // fit a plane background (a neighbour's glow) instead of a level
  };

  // The centre and colour of component c, from the pixels of its window
  // that belong to `spot`.
  bool measure(const BgrImageView& img, const Component& c, const Spot& spot, Blob& b) const {
    const std::int32_t* labels = spot.labels;
    const Window win = window_of(img, c);
    const int x0 = win.x0, y0 = win.y0, x1 = win.x1, y1 = win.y1;
    // Local background: a plane fitted (least squares) to the unlit pixels
    // of the window's border, so that a lit card or body behind the LED, or
    // the glow of a reflection or lamp beside it, does not pull the centre
    // (a constant level would leave the glow's gradient in the weights).
    const double xc = 0.5 * (x0 + x1), yc = 0.5 * (y0 + y1);
    double s1 = 0, sum_x = 0, sum_y = 0, sxx = 0, sxy = 0, syy = 0, sv = 0, sxv = 0, syv = 0;
    for (int y = y0; y <= y1; ++y) {
      const std::uint8_t* p = img.row(y);
      const bool edge_row = y == y0 || y == y1;
      for (int x = x0; x <= x1; x += (edge_row || x == x1) ? 1 : std::max(1, x1 - x0)) {
        const int v = std::max({p[3 * x], p[3 * x + 1], p[3 * x + 2]});
        if (v >= options.threshold) continue;  // another blob reaching into the window
        const double dx = x - xc, dy = y - yc;
        s1 += 1;
        sum_x += dx;
        sum_y += dy;
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
        sv += v;
        sxv += dx * v;
        syv += dy * v;
      }
    }
    double plane_a = 0, plane_b = 0, plane_c = 0;  // background(x, y) = a + b (x - xc) + c (y - yc)
    if (s1 > 0) {
      plane_a = sv / s1;
      Eigen::Matrix3d n;
      n << s1, sum_x, sum_y, sum_x, sxx, sxy, sum_y, sxy, syy;
      const Eigen::Vector3d rhs(sv, sxv, syv);
      // A border that is a line or a few pixels cannot hold a tilt: keep the mean.
      if (spot.tilted_background && s1 >= 8 && sxx > 0 && syy > 0 &&
          std::abs(n.determinant()) > 1e-6 * s1 * sxx * syy) {
        const Eigen::Vector3d abc = n.ldlt().solve(rhs);
        plane_a = abc(0);
        plane_b = abc(1);
        plane_c = abc(2);
      }
    }
    const double floor_bg = options.background;
    double sw = 0, sx = 0, sy = 0;
    HueEvidence halo, core;  // unclipped pixels; pixels clipped in one or two channels
    const int sat = options.saturation_level;
    const int ww = x1 - x0 + 1;
    for (int y = y0; y <= y1; ++y) {
      const std::uint8_t* p = img.row(y);
      for (int x = x0; x <= x1; ++x) {
        if (labels && labels[(y - y0) * ww + (x - x0)] != spot.label) continue;
        const int blue = p[3 * x], green = p[3 * x + 1], red = p[3 * x + 2];
        const int mx = std::max({blue, green, red});
        const double bg = std::max(floor_bg, plane_a + plane_b * (x - xc) + plane_c * (y - yc) + 4);
        if (mx <= bg) continue;
        const double w = mx - bg;
        if (blue + green + red > spot.min_sum) {  // the centre: a split spot's cap only
          sw += w;
          sx += w * x;
          sy += w * y;
        }
        const int clipped = (blue >= sat) + (green >= sat) + (red >= sat);
        if (clipped == 0) {
          halo.add(blue, green, red, mx, w);
        } else if (clipped < 3) {
          core.add(blue, green, red, mx, w);
        }
      }
    }
    if (!(sw > 0)) return false;
    b.uv_px = {sx / sw, sy / sw};
    b.uv_undistorted = camera.undistort(b.uv_px);
    b.area = spot.area;
    b.intensity = sw;
    if (halo.value >= options.min_colour_evidence) {
      b.color = classify_evidence(halo, options, b.hsv);
    } else if (core.value >= options.min_colour_evidence) {
      b.color = classify_evidence(core, options, b.hsv);
    } else {
      b.color = LedColor::Unknown;  // too little unclipped light to tell
      b.hsv = {0, 0, 1};
    }
    b.has_point = false;
    b.p_camera.setZero();
    b.split = spot.area < c.area;
    return true;
  }

  // Median valid depth around the centre; false if the blob falls outside the gate.
  bool depth_gate(const DepthImageView& depth, Blob& b) const {
    std::array<std::uint16_t, 49> v{};
    std::size_t n = 0;
    const int cx = static_cast<int>(std::lround(b.uv_px.x())), cy = static_cast<int>(std::lround(b.uv_px.y()));
    const int w = options.depth_window;
    for (int y = std::max(0, cy - w); y <= std::min(depth.height - 1, cy + w); ++y) {
      for (int x = std::max(0, cx - w); x <= std::min(depth.width - 1, cx + w); ++x) {
        const std::uint16_t d = depth.row(y)[x];
        if (d != 0) v[n++] = d;
      }
    }
    if (n == 0) return true;  // no measurement (common on bright LEDs): keep, without a 3-D point
    const double z = upper_median_in_place(std::span(v).first(static_cast<std::size_t>(n))) * camera.depth_scale;
    if (z < options.min_depth || z > options.max_depth) return false;
    b.has_point = true;
    b.p_camera = camera.pinhole().back_project(b.uv_undistorted, z);
    return true;
  }
};

LedDetector::LedDetector(const CameraModel& camera, const DetectorOptions& options) : impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!camera.validate(&why)) throw InvalidArgument("camera: " + why);
  if (!options.validate(&why)) throw InvalidArgument("detector options: " + why);
  impl_->camera = camera;
  impl_->options = options;
  impl_->runs.reserve(4096);
  impl_->components.reserve(1024);
  impl_->component_of.reserve(4096);
  impl_->split_labels.reserve(Impl::kMaxSplitWindow);
  impl_->split_order.reserve(Impl::kMaxSplitWindow);
  impl_->basins.reserve(Impl::kMaxSplitWindow);
}

LedDetector::~LedDetector() = default;
LedDetector::LedDetector(LedDetector&&) noexcept = default;
LedDetector& LedDetector::operator=(LedDetector&&) noexcept = default;

const DetectorOptions& LedDetector::options() const { return impl_->options; }

void LedDetector::detect(const BgrImageView& colour, const DepthImageView* depth, std::vector<Blob>& out) {
  out.clear();
  if (!colour.data || colour.width <= 0 || colour.height <= 0) throw InvalidArgument("colour image: empty");
  if (depth && (depth->width != colour.width || depth->height != colour.height)) {
    throw InvalidArgument("depth image is " + std::to_string(depth->width) + "x" + std::to_string(depth->height) +
                          " but the colour image is " + std::to_string(colour.width) + "x" +
                          std::to_string(colour.height));
  }
  Impl& d = *impl_;
  d.label(colour);
  for (const auto& c : d.components) {
    if (c.area < d.options.min_area || c.area > d.options.max_area) continue;
    if (d.options.drop_border_blobs &&
        (c.x0 == 0 || c.y0 == 0 || c.x1 == colour.width - 1 || c.y1 == colour.height - 1)) {
      continue;  // cut by the border: its centre is not the spot's (DetectorOptions::drop_border_blobs)
    }
    const int spots = d.split(colour, c);
    const bool crowded = spots > 1 || d.crowded(c);
    auto keep = [&](const std::int32_t* labels, std::int32_t label, int area, int min_sum) {
      Blob b;
      if (!d.measure(colour, c, {labels, label, area, min_sum, crowded}, b)) return;
      if (depth && depth->data && !d.depth_gate(*depth, b)) return;
      out.push_back(b);
    };
    if (!d.labels_valid || spots == 0) {
      keep(nullptr, 0, c.area, -1);
      continue;
    }
    for (std::size_t r = 0; r < d.basins.size(); ++r) {
      const Impl::Basin& basin = d.basins[r];
      if (basin.parent != static_cast<std::int32_t>(r) || basin.lit < d.options.min_area) continue;
      // One spot: all of c (lit pixels of basins too small to be spots too).
      // Split spots: only their cap above the level where they met another
      // (below it, the other's glow is a large share of the light).
      if (spots == 1) {
        keep(d.split_labels.data(), static_cast<std::int32_t>(r), c.area, -1);
      } else {
        keep(d.split_labels.data(), static_cast<std::int32_t>(r), basin.lit, basin.saddle);
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const Blob& a, const Blob& b) { return a.intensity > b.intensity; });
  if (out.size() > d.options.max_blobs) out.resize(d.options.max_blobs);
}

}  // namespace touchdown::pose
