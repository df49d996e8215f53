#include "touchdown/pose/led_detector.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "touchdown/core/error.hpp"
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
  std::vector<Run> runs;
  std::vector<int> row_start;
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

  bool measure(const BgrImageView& img, const Component& c, Blob& b) const {
    const int m = options.refine_margin;
    const int x0 = std::max(0, c.x0 - m), x1 = std::min(img.width - 1, c.x1 + m);
    const int y0 = std::max(0, c.y0 - m), y1 = std::min(img.height - 1, c.y1 + m);
    // Local background: the mean brightness on the window's border (a lit
    // card or body behind the LED would otherwise pull the centre).
    double ring = 0;
    int ring_n = 0;
    for (int y = y0; y <= y1; ++y) {
      const std::uint8_t* p = img.row(y);
      const bool edge_row = y == y0 || y == y1;
      for (int x = x0; x <= x1; x += (edge_row || x == x1) ? 1 : std::max(1, x1 - x0)) {
        ring += std::max({p[3 * x], p[3 * x + 1], p[3 * x + 2]});
        ++ring_n;
      }
    }
    const int bg = std::max(options.background, ring_n ? static_cast<int>(ring / ring_n) + 4 : 0);
    double sw = 0, sx = 0, sy = 0;
    HueEvidence halo, core;  // unclipped pixels; pixels clipped in one or two channels
    const int sat = options.saturation_level;
    for (int y = y0; y <= y1; ++y) {
      const std::uint8_t* p = img.row(y);
      for (int x = x0; x <= x1; ++x) {
        const int blue = p[3 * x], green = p[3 * x + 1], red = p[3 * x + 2];
        const int mx = std::max({blue, green, red});
        if (mx <= bg) continue;
        const double w = mx - bg;
        sw += w;
        sx += w * x;
        sy += w * y;
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
    b.area = c.area;
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
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2),
                     v.begin() + static_cast<std::ptrdiff_t>(n));
    const double z = v[n / 2] * camera.depth_scale;
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
    Blob b;
    if (!d.measure(colour, c, b)) continue;
    if (depth && depth->data && !d.depth_gate(*depth, b)) continue;
    out.push_back(b);
  }
  std::sort(out.begin(), out.end(), [](const Blob& a, const Blob& b) { return a.intensity > b.intensity; });
  if (out.size() > d.options.max_blobs) out.resize(d.options.max_blobs);
}

}  // namespace touchdown::pose
