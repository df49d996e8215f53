// led_pose benchmark's outputs: the figures as JSON and the table.
#include <algorithm>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/format.hpp"
#include "touchdown/pose/sim/pose_benchmark.hpp"

namespace touchdown::pose {

using detail::format_fixed;

std::string benchmark_json(const PoseBenchmarkResult& r, int frames_per_sequence, std::uint64_t seed) {
  nlohmann::json j;
  j["status"] = std::string(to_string(r.status));
  j["frames_per_sequence"] = frames_per_sequence;
  j["seed"] = seed;
  for (const auto& row : r.rows) {
    j["rows"].push_back({{"scenario", row.scenario},
                         {"profile", row.profile},
                         {"method", row.method},
                         {"sequence", row.sequence},
                         {"frames", row.frames},
                         {"success_rate", row.success_rate},
                         {"wrong_ok", row.wrong_ok},
                         {"wrong_ok_rate", row.wrong_ok_rate},
                         {"position_mean_m", row.position_mean_m},
                         {"position_std_m", row.position_std_m},
                         {"position_max_m", row.position_max_m},
                         {"orientation_mean_rad", row.orientation_mean_rad},
                         {"orientation_std_rad", row.orientation_std_rad},
                         {"ms_median", row.ms_median},
                         {"ms_p90", row.ms_p90}});
  }
  j["solvers_us_median"] = {{"epnp_gauss_newton", r.epnp_gn_us_median},
                            {"opencv_iterative", r.opencv_iterative_us_median},
                            {"opencv_sqpnp", r.opencv_sqpnp_us_median},
                            {"opencv_epnp", r.opencv_epnp_us_median},
                            {"samples", r.solver_samples}};
  return j.dump();
}

std::string benchmark_table(const PoseBenchmarkResult& r) {
  std::ostringstream out;
  std::size_t scenario_width = 16;  // a custom scenario's name may be longer
  for (const auto& row : r.rows) scenario_width = std::max(scenario_width, row.scenario.size() + 2);
  out << std::left << std::setw(static_cast<int>(scenario_width)) << "scenario"
      << "profile  sequence  method  frames  success  wrong-ok  pos mean [m]  pos std [m]  "
         "rot mean [rad]  rot std [rad]  ms/frame (median)\n";
  for (const auto& row : r.rows) {
    out << std::left << std::setw(static_cast<int>(scenario_width)) << row.scenario << std::setw(9) << row.profile
        << std::setw(10) << row.sequence << std::setw(8) << row.method << std::right << std::setw(6) << row.frames
        << std::setw(9) << format_fixed(row.success_rate, 3) << std::setw(10) << row.wrong_ok << std::setw(14)
        << format_fixed(row.position_mean_m, 4) << std::setw(13) << format_fixed(row.position_std_m, 4) << std::setw(16)
        << format_fixed(row.orientation_mean_rad, 4) << std::setw(15) << format_fixed(row.orientation_std_rad, 4)
        << std::setw(19) << format_fixed(row.ms_median, 3) << "\n";
  }
  out << "solvers on the tracked LEDs (median, " << r.solver_samples << " frames): EPnP+GN "
      << format_fixed(r.epnp_gn_us_median, 1) << " us, OpenCV ITERATIVE "
      << format_fixed(r.opencv_iterative_us_median, 1) << " us, SQPNP " << format_fixed(r.opencv_sqpnp_us_median, 1)
      << " us, EPNP " << format_fixed(r.opencv_epnp_us_median, 1) << " us\n";
  return out.str();
}

}  // namespace touchdown::pose
