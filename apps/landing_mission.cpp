// landing_mission: fly the closed-loop landing on a moving vehicle in
// simulation, N seeded missions, and report how often and how well it lands
// (issue 34); `envelope` maps the success rate over vehicle speed × wind.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "app_common.hpp"
#include "core/format.hpp"
#include "touchdown/mission/mission.hpp"
#include "touchdown/mission/mission_io.hpp"
#include "touchdown/mission/mission_plot.hpp"
#include "touchdown/mission/perception_render.hpp"
#include "touchdown/mission/report.hpp"
#include "video.hpp"

namespace {

namespace td = touchdown;
namespace tdm = touchdown::mission;
using td::detail::format_fixed;

struct Args {
  std::string mission_path;
  int runs = 1;
  std::uint64_t seed = 1;
  int record_run = 0;  ///< --record-run: the run --plot/--log/--video show
  int threads = 0;
  std::string perception = "model";
  bool json = false;
  std::string plot_dir, log_path, video_path;
  std::vector<double> wind;  ///< --wind: the mission file's wind.mean replaced
  std::string turbulence;    ///< --turbulence: the file's wind.turbulence replaced
  // envelope
  std::vector<double> speeds{0, 3, 0.5}, winds{0, 8, 2};
  std::string envelope_plot;
  std::vector<std::string> envelope_paths, envelope_turbulence;  ///< empty: the file's
};

tdm::MissionFile load(const Args& a) {
  if (a.mission_path.empty()) return {};  // the built-in default: the paper's setup
  return tdm::load_mission(a.mission_path);
}

std::string source_name(const Args& a) { return a.mission_path.empty() ? "built-in circle mission" : a.mission_path; }

// --plot DIR and --log FILE: staged before any work (a run that fails
// leaves nothing), written from the --record-run run flown again with its trace recorded.
struct Recorded {
  td::StagedOutputs staged;
  std::filesystem::path log, video;
  std::vector<std::pair<std::string, std::filesystem::path>> plots;
};

// One video frame: the camera image with the tracker's blobs (yellow
// circles), the constellation at the estimated pose (green crosses) and a
// status line.
cv::Mat overlay(const tdm::PerceptionFrame& f) {
  const td::BgrImage& c = *f.colour;
  cv::Mat img = cv::Mat(c.height, c.width, CV_8UC3, const_cast<std::uint8_t*>(c.pixels.data())).clone();
  for (const auto& b : *f.blobs) {
    cv::circle(img, cv::Point2d(b.uv_px.x(), b.uv_px.y()), 9, cv::Scalar(0, 220, 255), 1, cv::LINE_AA);
  }
  for (const Eigen::Vector2d& p : f.reprojected) {
    const cv::Point2d q(p.x(), p.y());
    cv::line(img, q - cv::Point2d(6, 0), q + cv::Point2d(6, 0), cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
    cv::line(img, q - cv::Point2d(0, 6), q + cv::Point2d(0, 6), cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
  }
  const auto& e = *f.estimate;
  std::string line = "t " + format_fixed(f.t, 2) + " s   " + std::string(tdm::to_string(f.state)) +
                     "   pose: " + std::string(td::pose::to_string(e.status));
  if (e.ok()) {
    line += " (" + std::to_string(e.points) + " LEDs, sigma " + format_fixed(1e3 * e.sigma_position_m, 1) + " mm)";
  }
  cv::rectangle(img, cv::Rect(0, 0, img.cols, 30), cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(img, line, cv::Point(8, 21), cv::FONT_HERSHEY_SIMPLEX, 0.65, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return img;
}

void stage_recorded(const Args& a, Recorded& out) {
  if (!a.plot_dir.empty()) std::filesystem::create_directories(a.plot_dir);
  if (!a.log_path.empty()) out.log = out.staged.add(a.log_path, "--log");
  if (!a.video_path.empty()) out.video = out.staged.add(a.video_path, "--video");
  if (!a.plot_dir.empty()) {
    for (const char* name : {"positions.svg", "velocities.svg", "errors.svg", "top_view.svg"}) {
      out.plots.emplace_back(name, out.staged.add(std::filesystem::path(a.plot_dir) / name, "--plot"));
    }
  }
}

void write_recorded(const Args& a, const tdm::MissionOptions& o, Recorded& out) {
  if (out.log.empty() && out.plots.empty() && out.video.empty()) return;
  std::optional<td::app::VideoFile> video;
  tdm::PerceptionFactory factory;
  if (!out.video.empty()) {
    // The run again with a render perception that hands each frame to the video.
    factory = [&](const tdm::MissionOptions& mo, std::uint64_t seed) {
      const tdm::PerceptionModelOptions m = mo.perception_options();
      auto p = std::make_unique<tdm::RenderPerception>(mo.render, m.camera.T_pad_camera,
                                                       mo.drone.airframe.centre_of_mass(), m.rate_hz, m.latency, seed);
      p->on_frame(
          [&, fps = m.rate_hz, w = mo.render.camera.width, h = mo.render.camera.height](const tdm::PerceptionFrame& f) {
            if (!video) video.emplace(out.video, a.video_path, fps, w, h);
            video->write(overlay(f));
          });
      return p;
    };
  }
  const auto run = static_cast<std::uint64_t>(a.record_run);
  const tdm::MissionResult r = tdm::run_mission(o, a.seed, run, true, factory);
  if (video) video->finish();
  // The outcome and, when it did not land, why (issue 58 item 8).
  const std::string title = source_name(a) + ", run " + std::to_string(run) + ", seed " + std::to_string(a.seed) +
                            " (" + (r.landed() ? std::string("landed") : tdm::failure_reason(r)) + ")";
  for (const auto& [name, tmp] : out.plots) {
    const std::string svg = name == "positions.svg"    ? tdm::plot_positions(r, title)
                            : name == "velocities.svg" ? tdm::plot_velocities(r, title)
                            : name == "errors.svg"     ? tdm::plot_errors(r, title)
                                                       : tdm::plot_top_view(r, title);
    td::app::write_text(tmp, svg, "--plot");
  }
  if (!out.log.empty()) td::app::write_text(out.log, tdm::trace_csv(r), "--log");
  out.staged.commit();
}

// "lo:hi:step" → values.
std::vector<double> range_of(const std::vector<double>& r) {
  std::vector<double> v;
  for (double x = r[0]; x <= r[1] + 1e-9 * std::max(1.0, std::abs(r[1])); x += r[2]) v.push_back(x);
  return v;
}

// envelope.svg → envelope_road_moderate.svg when several blocks are flown.
std::string block_plot_path(const std::string& plot, const std::string& suffix) {
  const std::filesystem::path p(plot);
  return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
}

int run_envelope(const Args& a) {
  tdm::MissionFile file = load(a);
  td::app::print_warnings("landing_mission", file.warnings);
  // One block per path × turbulence level (each the file's when not given).
  std::vector<std::pair<tdm::VehiclePath, tdm::TurbulenceLevel>> blocks;
  const auto paths = a.envelope_paths.empty()
                         ? std::vector<std::string>{std::string(to_string(file.options.vehicle.path))}
                         : a.envelope_paths;
  const auto levels = a.envelope_turbulence.empty()
                          ? std::vector<std::string>{std::string(to_string(file.options.wind.turbulence))}
                          : a.envelope_turbulence;
  for (const auto& p : paths) {
    for (const auto& t : levels) {
      blocks.emplace_back(td::from_string<tdm::VehiclePath>(p), td::from_string<tdm::TurbulenceLevel>(t));
    }
  }
  const bool several = blocks.size() > 1;
  td::StagedOutputs staged;
  std::vector<std::filesystem::path> plots;
  for (const auto& [path, level] : blocks) {
    if (a.envelope_plot.empty()) break;
    const std::string suffix = "_" + std::string(to_string(path)) + "_" + std::string(to_string(level));
    plots.push_back(staged.add(several ? block_plot_path(a.envelope_plot, suffix) : a.envelope_plot, "--plot"));
  }
  td::app::ProgressBar bar("landing_mission", "missions");
  const std::size_t per_block = range_of(a.speeds).size() * range_of(a.winds).size() * static_cast<std::size_t>(a.runs);
  std::string text;
  nlohmann::json blocks_json = nlohmann::json::array();
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    tdm::MissionOptions o = file.options;
    o.vehicle.path = blocks[b].first;
    o.wind.turbulence = blocks[b].second;
    const std::string name =
        several ? source_name(a) + ", path " + std::string(to_string(o.vehicle.path)) : source_name(a);
    const tdm::Envelope e =
        tdm::run_envelope(o, range_of(a.speeds), range_of(a.winds), a.runs, a.seed, a.threads,
                          [&](const td::Progress& p) { bar.draw(b * per_block + p.done, blocks.size() * per_block); });
    if (!plots.empty()) {
      td::app::write_text(
          plots[b], tdm::plot_envelope(e.cells, name + ", " + std::to_string(a.runs) + " runs per cell"), "--plot");
    }
    text += (b > 0 ? "\n" : "") + tdm::envelope_text(e, name);
    nlohmann::json j = nlohmann::json::parse(tdm::envelope_json(e, name, a.seed));
    j["path"] = to_string(o.vehicle.path);
    j["turbulence"] = to_string(o.wind.turbulence);
    blocks_json.push_back(std::move(j));
  }
  bar.close();
  staged.commit();
  if (a.json) {
    std::cout << (several ? nlohmann::json{{"mission", source_name(a)}, {"seed", a.seed}, {"envelopes", blocks_json}}
                          : blocks_json[0])
                     .dump()
              << "\n";
  } else {
    std::cout << text;
  }
  return td::app::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Fly the closed-loop landing on a moving vehicle in simulation: N seeded missions, outcome and errors.",
               "landing_mission"};
  Args a;
  app.add_option("mission", a.mission_path, "MISSION.yaml (docs/formats.md); default: the built-in circle mission")
      ->check(td::app::existing_file());
  app.add_option("--runs", a.runs, "missions")->check(CLI::Range(1, 1000000))->capture_default_str();
  td::app::add_seed_option(app, "--seed", a.seed, "seed of the first mission (run i: (seed, i))");
  app.add_option("--threads", a.threads, "worker threads (0 = every core)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  CLI::Option* perception =
      app.add_option("--perception", a.perception, "perception in the loop (default: the mission file's)")
          ->check(td::app::one_of_names(tdm::perception_registry().names()))
          ->default_str("the file's");
  app.add_flag("--json", a.json, "one JSON object on stdout");
  app.add_option("--wind", a.wind, "mean wind VX,VY,VZ in the world [m/s] instead of the mission file's wind.mean")
      ->delimiter(',')
      ->expected(3)
      ->check(td::app::number_in(-50, 50))
      ->default_str("the file's");
  app.add_option("--turbulence", a.turbulence, "Dryden turbulence level instead of the file's wind.turbulence")
      ->check(td::app::one_of<tdm::TurbulenceLevel>())
      ->default_str("the file's");
  app.add_option("--plot", a.plot_dir, "write positions/velocities/errors/top_view SVGs of one run to this directory")
      ->default_str("off");
  app.add_option("--log", a.log_path, "write one run's trace (50 Hz) as CSV")
      ->check(td::app::output_extension(".csv"))
      ->default_str("off");
  app.add_option("--video", a.video_path, "render mode: the vehicle camera's view of one run (MP4)")
      ->check(td::app::output_extension(".mp4"))
      ->default_str("off");
  app.add_option("--record-run", a.record_run,
                 "the run --plot/--log/--video show (0 .. runs-1: replay a failure from a batch with its index)")
      ->check(CLI::Range(0, 999999))
      ->capture_default_str();
  CLI::App* envelope = app.add_subcommand("envelope", "success rate over vehicle speed x wind");
  envelope->add_option("mission", a.mission_path, "MISSION.yaml")->check(td::app::existing_file());
  envelope->add_option("--speeds", a.speeds, "vehicle speeds lo hi step [m/s]")
      ->delimiter(':')
      ->expected(3)
      ->check(td::app::number_in(0, 50))
      ->capture_default_str();
  envelope->add_option("--winds", a.winds, "mean winds lo hi step [m/s]")
      ->delimiter(':')
      ->expected(3)
      ->check(td::app::number_in(0, 50))
      ->capture_default_str();
  envelope
      ->add_option("--turbulence", a.envelope_turbulence,
                   "Dryden turbulence levels, comma-separated (one envelope each) instead of the file's")
      ->delimiter(',')
      ->check(td::app::one_of<tdm::TurbulenceLevel>())
      ->default_str("the file's");
  envelope
      ->add_option("--paths", a.envelope_paths,
                   "vehicle paths, comma-separated (one envelope each; not log) instead of the file's")
      ->delimiter(',')
      ->check(td::app::one_of<tdm::VehiclePath>())
      ->default_str("the file's");
  envelope->add_option("--runs", a.runs, "missions per cell")->check(CLI::Range(1, 100000))->capture_default_str();
  td::app::add_seed_option(*envelope, "--seed", a.seed, "seed");
  envelope->add_option("--threads", a.threads, "worker threads (0 = every core)")->check(CLI::Range(0, 1024));
  envelope->add_option("--plot", a.envelope_plot, "write the envelope as SVG")
      ->check(td::app::output_extension(".svg"))
      ->default_str("off");
  envelope->add_flag("--json", a.json, "one JSON object on stdout");

  return td::app::run(app, argc, argv, [&]() -> int {
    if (envelope->parsed()) {
      for (const auto* r : {&a.speeds, &a.winds}) {
        if (!((*r)[2] > 0) || (*r)[1] < (*r)[0]) {
          throw td::InvalidArgument(std::string(r == &a.speeds ? "--speeds" : "--winds") +
                                    ": expected lo:hi:step with lo <= hi and step > 0");
        }
      }
      // A grid a person reads (and a run that ends): at most 10 000 cells.
      if (const std::size_t cells = range_of(a.speeds).size() * range_of(a.winds).size() *
                                    std::max<std::size_t>(1, a.envelope_paths.size()) *
                                    std::max<std::size_t>(1, a.envelope_turbulence.size());
          cells > 10000) {
        throw td::InvalidArgument("--speeds/--winds: " + std::to_string(cells) +
                                  " cells (speeds x winds x paths x levels); at most 10000: use larger steps");
      }
      return run_envelope(a);
    }
    tdm::MissionFile file = load(a);
    td::app::print_warnings(app.get_name(), file.warnings);
    if (!a.wind.empty()) file.options.wind.mean = {a.wind[0], a.wind[1], a.wind[2]};
    if (!a.turbulence.empty()) file.options.wind.turbulence = td::from_string<tdm::TurbulenceLevel>(a.turbulence);
    if (a.record_run >= a.runs) {
      throw td::InvalidArgument("--record-run: " + std::to_string(a.record_run) + " is not one of the " +
                                std::to_string(a.runs) + " runs (0 .. --runs - 1)");
    }
    if (perception->count() == 0) a.perception = file.options.perception;
    file.options.perception = a.perception;
    if (!a.video_path.empty() && a.perception != "render") {
      throw td::InvalidArgument("--video: needs --perception render (the camera's frames are rendered only then)");
    }
    Recorded recorded;
    stage_recorded(a, recorded);
    const auto t0 = std::chrono::steady_clock::now();
    td::app::ProgressBar bar("landing_mission", "missions");
    const bool draw = a.runs > 1;
    const auto results = tdm::run_missions(file.options, a.runs, a.seed, a.threads, {}, [&](const td::Progress& p) {
      if (draw) bar.draw(p.done, p.total);
    });
    bar.close();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    write_recorded(a, file.options, recorded);
    const tdm::MissionRunInfo info{source_name(a), a.seed, a.perception};
    std::cout << (a.json ? tdm::missions_json(info, results, wall) + "\n"
                         : tdm::summary_text(info, file.options, tdm::summarise(results), wall));
    return td::app::kExitOk;
  });
}
