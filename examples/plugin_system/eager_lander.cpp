// eager-lander: a landing system written as a user of touchdown would
// write one, built as a plug-in (touchdown/scenario/plugin.hpp). It uses
// touchdown's ArUco detector through the public MarkerDetector interface
// and its own guidance: fly to the GPS target at 8 m, centre over the
// marker, and start the descent after 1 s of sighting (the reference
// systems wait 5 s: the eagerness is this system's own trade-off). It
// never searches: a marker not in view over the GPS target is never found.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string_view>
#include <touchdown/scenario/landing_system.hpp>
#include <touchdown/scenario/marker_detector.hpp>
#include <touchdown/scenario/plugin.hpp>
#include <vector>

namespace {

namespace ts = touchdown::scenario;

class EagerLander final : public ts::LandingSystem {
 public:
  [[nodiscard]] std::string_view name() const override { return "eager-lander"; }

  void reset(const ts::SystemSetup& setup) override {
    setup_ = setup;
    detector_ = ts::make_marker_detector({});  // ArUco with its tracking region
    detector_->reset(setup.dictionary, setup.marker_id);
    estimate_.reset();
    seen_since_ = -1;
    last_seen_ = -1e9;
    descending_ = false;
  }

  ts::SystemOutput update(const ts::SystemInput& in) override {
    ts::SystemOutput out;
    const touchdown::DroneState& s = in.state;
    if (in.frame != nullptr) look(*in.frame, s, out);
    if (s.t - last_seen_ > 1.0) seen_since_ = -1;  // lost: the sighting restarts
    if (!descending_ && seen_since_ >= 0 && s.t - seen_since_ >= 1.0) {
      descending_ = true;
      out.descent_started = true;
      out.target = *estimate_;
    }
    const Eigen::Vector2d goal = estimate_ ? *estimate_ : setup_.gps_target;
    Eigen::Vector2d v = goal - s.position.head<2>();
    if (v.norm() > 2.5) v *= 2.5 / v.norm();
    double vz = std::clamp(8.0 - s.position.z(), -1.0, 1.0);
    if (descending_) vz = -0.7;
    out.command.velocity_world = {v.x(), v.y(), vz};
    out.command.land = descending_ && s.position.z() < 1.2;
    out.phase = descending_ ? "descend" : (estimate_ ? "centre" : "approach");
    return out;
  }

 private:
  // Detects the target in the frame (grey by the BT.601 luma weights) and
  // moves the estimate to its centre's ground point.
  void look(const ts::CameraFrame& f, const touchdown::DroneState& s, ts::SystemOutput& out) {
    gray_.resize(static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height));
    const std::uint8_t* bgr = f.image.pixels.data();
    for (std::size_t i = 0; i < gray_.size(); ++i) {
      gray_[i] = static_cast<std::uint8_t>((29 * bgr[3 * i] + 150 * bgr[3 * i + 1] + 77 * bgr[3 * i + 2]) >> 8);
    }
    const ts::DetectorFrame frame{f.image.view(), {gray_.data(), f.width, f.height, f.width}};
    detector_->detect(frame, detections_);
    const ts::MarkerDetection* target = nullptr;
    for (const auto& d : detections_) {
      if (d.id == setup_.marker_id && (target == nullptr || d.confidence > target->confidence)) target = &d;
    }
    detector_->track(target);
    for (const auto& d : detections_) {
      ts::Detection r;
      r.id = d.id;
      r.corners = d.corners;
      r.confidence = d.confidence;
      r.quality = (d.box_max - d.box_min).norm();
      r.accepted = &d == target;
      if (r.accepted) {
        const Eigen::Isometry3d T_world_camera = s.T_world_body() * setup_.camera.T_body_camera();
        const Eigen::Vector2d c = d.centre();
        const Eigen::Vector3d ray =
            T_world_camera.linear() * (setup_.camera.K().inverse() * Eigen::Vector3d(c.x(), c.y(), 1));
        if (ray.z() < -1e-9) {
          const Eigen::Vector3d o = T_world_camera.translation();
          r.ground = (o - o.z() / ray.z() * ray).head<2>();
          estimate_ = estimate_ ? Eigen::Vector2d(0.5 * (*estimate_ + r.ground)) : r.ground;
          if (seen_since_ < 0) seen_since_ = s.t;
          last_seen_ = s.t;
        }
      }
      out.detections.push_back(r);
    }
  }

  ts::SystemSetup setup_;
  std::unique_ptr<ts::MarkerDetector> detector_;
  std::vector<ts::MarkerDetection> detections_;
  std::vector<std::uint8_t> gray_;
  std::optional<Eigen::Vector2d> estimate_;
  double seen_since_ = -1, last_seen_ = -1e9;
  bool descending_ = false;
};

void register_systems(ts::PluginRegistrar& registrar) {
  registrar.add("eager-lander", "ArUco, no search, descends after 1 s of sighting (examples/plugin_system)",
                "none (its gains are constants of eager_lander.cpp)",
                [](const ts::MlsOptions&) { return std::make_unique<EagerLander>(); });
}

}  // namespace

TOUCHDOWN_PLUGIN("touchdown's plug-in example", register_systems)
