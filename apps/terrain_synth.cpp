// terrain_synth: scan a synthetic terrain with a simulated depth camera and
// write the cloud (and the camera extrinsics) — how data/terrains/ is made.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "app_common.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/cloud_io.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/terrain/extrinsics.hpp"
#include "touchdown/terrain/filters.hpp"
#include "touchdown/terrain/synthetic.hpp"

namespace {

// Ranges of the size options (docs/cli.md).
constexpr int kMaxSide = 8192;            // --width, --height [px]
constexpr double kMaxPixels = 4194304.0;  // width x height (2048 x 2048; 1920 x 1080 fits)
constexpr double kBytesPerPixel = 52.0;   // 2 depth images (16) + cloud (12) + writer (24)
constexpr int kMaxRocks = 1000;           // --rubble-count

namespace td = touchdown;
namespace syn = td::terrain::synthetic;

// The command line: what the user asked for.
struct Args {
  std::string output, extrinsics_out, frame = "camera";
  td::PcdEncoding encoding = td::PcdEncoding::Binary;
  syn::Shape shape;
  syn::DepthCamera cam;
  double cam_height = 1.2, cam_x = 0, cam_y = 0, cam_yaw_deg = 0, noise_scale = 1.0;
  std::vector<double> plateau_size{shape.plateau_size.x(), shape.plateau_size.y()};
  std::vector<double> post{shape.post_xy.x(), shape.post_xy.y(), shape.post_radius, shape.post_height};
  std::uint64_t seed = 1;
  bool json = false;
};

// The shape's own options (--azimuth .. --post).
void add_shape_options(CLI::App& app, Args& a) {
  using td::app::number_in;
  syn::Shape& shape = a.shape;
  app.add_option("--azimuth", shape.azimuth_deg, "direction the incline rises / the step goes up [deg]")
      ->check(number_in(-360, 360))
      ->check(td::app::degrees_not_radians("--azimuth"))
      ->capture_default_str();
  app.add_option("--slope", shape.slope_deg, "incline angle [deg]")
      ->check(number_in(0, 80, false, true))
      ->check(td::app::degrees_not_radians("--slope"))
      ->capture_default_str();
  app.add_option("--step-height", shape.step_height, "step height [m] (< 0: a step down)")
      ->check(number_in(-5, 5))
      ->capture_default_str();
  app.add_option("--edge-offset", shape.edge_offset, "step edge distance from the origin [m]")
      ->check(number_in(-1000, 1000))
      ->capture_default_str();
  app.add_option("--plateau-height", shape.plateau_height, "plateau height [m] (< 0: a pit)")
      ->check(number_in(-5, 5))
      ->capture_default_str();
  app.add_option("--plateau-size", a.plateau_size, "plateau length,width [m]")
      ->delimiter(',')
      ->expected(2)
      ->check(number_in(0, 1000, true))
      ->capture_default_str();
  app.add_option("--rubble-count", shape.rubble_count, "number of rocks")
      ->check(number_in(0, kMaxRocks))
      ->capture_default_str();
  app.add_option("--rubble-height", shape.rubble_max_height, "tallest rock [m]")
      ->check(number_in(0, 5))
      ->capture_default_str();
  app.add_option("--post", a.post,
                 "post: x,y,radius,height [m] (x, y in [-1000, 1000], radius in (0, 100], height in "
                 "[-5, 5])")
      ->delimiter(',')
      ->expected(4)
      ->check(number_in(-1000, 1000))
      ->capture_default_str();
}

void add_options(CLI::App& app, Args& a) {
  using td::app::number_in;
  syn::Shape& shape = a.shape;
  td::app::add_enum_option(app, "KIND", shape.kind, "terrain: " + td::enum_names_list<syn::ShapeKind>())
      ->required()
      ->default_str("");
  app.add_option("-o,--output", a.output, "cloud to write: .pcd, .ply, .xyz")->required();
  app.add_option("--extrinsics-out", a.extrinsics_out,
                 "write the camera pose YAML here (for terrain_mesh --extrinsics)")
      ->default_str("none");
  app.add_option("--frame", a.frame, "camera (organized, optical frame) or world (unorganized, finite points, z up)")
      ->check(CLI::IsMember({"camera", "world"}))
      ->capture_default_str();
  td::app::add_enum_option(app, "--encoding", a.encoding, "PCD encoding: " + td::enum_names_list<td::PcdEncoding>());
  app.add_option("--camera-height", a.cam_height, "camera height above the origin [m] (depth range 0.2-10 m)")
      ->check(number_in(0, 10, true))
      ->capture_default_str();
  app.add_option("--camera-x", a.cam_x, "camera x [m]")->check(number_in(-1000, 1000))->capture_default_str();
  app.add_option("--camera-y", a.cam_y, "camera y [m]")->check(number_in(-1000, 1000))->capture_default_str();
  app.add_option("--camera-yaw", a.cam_yaw_deg, "camera yaw [deg]")
      ->check(number_in(-360, 360))
      ->check(td::app::degrees_not_radians("--camera-yaw"))
      ->capture_default_str();
  app.add_option("--width", a.cam.width, "image width [px]; width x height at most 4194304 pixels")
      ->check(number_in(1, kMaxSide))
      ->capture_default_str();
  app.add_option("--height", a.cam.height, "image height [px]")->check(number_in(1, kMaxSide))->capture_default_str();
  app.add_option("--fx", a.cam.fx, "focal length [px] (fy = fx; principal point at the centre)")
      ->check(number_in(0, 100000, true))
      ->capture_default_str();
  app.add_option("--noise-scale", a.noise_scale, "multiplies depth noise, dropouts and outliers (0 = ideal)")
      ->check(number_in(0, 100))
      ->capture_default_str();
  add_shape_options(app, a);
  td::app::add_seed_option(app, "--seed", a.seed, "random seed");
  app.add_flag("--json", a.json, "print one JSON object on stdout");
}

// The plateau and the post from the vector options, checked.
void prepare_shape(Args& a) {
  syn::Shape& shape = a.shape;
  shape.plateau_size = {a.plateau_size[0], a.plateau_size[1]};
  if (!(a.post[2] > 0 && a.post[2] <= 100)) throw td::InvalidArgument("--post: radius must be in (0, 100] m");
  if (!(std::abs(a.post[3]) <= 5)) throw td::InvalidArgument("--post: height must be in [-5, 5] m");
  shape.post_xy = {a.post[0], a.post[1]};
  shape.post_radius = a.post[2];
  shape.post_height = a.post[3];
}

// Memory before allocating: the renderer holds two depth images
// (doubles) and the cloud (3 floats), the writer up to twice the cloud.
void check_image_size(const syn::DepthCamera& cam) {
  const double pixels = static_cast<double>(cam.width) * cam.height;
  if (pixels > kMaxPixels) {
    throw td::InvalidArgument("--width x --height = " + std::to_string(cam.width) + " x " + std::to_string(cam.height) +
                              " = " + std::to_string(static_cast<long long>(pixels)) + " pixels needs ~" +
                              td::app::gigabytes(pixels * kBytesPerPixel) + "; the limit is " +
                              std::to_string(static_cast<long long>(kMaxPixels)) + " pixels (~" +
                              td::app::gigabytes(kMaxPixels * kBytesPerPixel) + ")");
  }
}

// The depth camera sees from 0.2 m: it must be that far above the terrain under it.
void check_camera_height(const Args& a) {
  const double ground = a.shape.height(a.cam_x, a.cam_y);
  if (!(a.cam_height - ground >= a.cam.min_range)) {
    std::ostringstream os;
    os << "--camera-height: the camera at (" << a.cam_x << ", " << a.cam_y << ", " << a.cam_height << ") is "
       << a.cam_height - ground << " m above the terrain under it (z = " << ground << "); it sees from "
       << a.cam.min_range << " m";
    throw td::InvalidArgument(os.str());
  }
}

// The camera's scan of the shape, in the --frame asked for.
td::PointCloud scan(Args& a, const Eigen::Isometry3d& T) {
  syn::DepthCamera& cam = a.cam;
  cam = syn::DepthCamera::centred(cam.width, cam.height, cam.fx);
  cam.subpixel *= a.noise_scale;
  cam.dropout_fraction *= a.noise_scale;
  cam.outlier_fraction *= a.noise_scale;
  cam.flying_pixels = a.noise_scale > 0;
  td::PointCloud cloud = syn::render_depth_scan(a.shape, cam, T, a.seed);
  if (std::none_of(cloud.points.begin(), cloud.points.end(), [](const Eigen::Vector3f& p) { return p.allFinite(); }))
    throw td::InvalidArgument("no terrain point lies within the depth camera's " + std::to_string(cam.min_range) + "-" +
                              std::to_string(cam.max_range) + " m range: lower --camera-height");
  if (a.frame == "world") {
    // Not organized (even when no pixel was lost): a world-frame cloud has
    // no pixel grid, and terrain_mesh/landing_sweep take an organized
    // cloud for a camera frame.
    td::terrain::remove_non_finite(cloud);
    td::terrain::transform_cloud(cloud, T);
    cloud.mark_unorganized();
  }
  return cloud;
}

// The cloud, and with --extrinsics-out the camera pose, through `outputs`
// (staged before the work).
struct OutputFiles {
  td::StagedOutputs staged;
  std::filesystem::path cloud, extrinsics;
};

void write_outputs(const Args& a, OutputFiles& out, const td::PointCloud& cloud, const Eigen::Isometry3d& T) {
  if (td::cloud_format_from_path(a.output) == td::CloudFormat::Pcd) {
    td::write_pcd(cloud, out.cloud, a.encoding);
  } else {
    td::write_cloud(cloud, out.cloud);
  }
  if (!a.extrinsics_out.empty()) {
    td::terrain::Extrinsics e;
    if (a.frame == "camera") e.T_world_camera = T;
    const std::string text = td::terrain::format_extrinsics(e, false);
    td::app::write_text(out.extrinsics, text, a.extrinsics_out);
  }
  out.staged.commit();
}

void print_result(const Args& a, const td::PointCloud& cloud) {
  const std::string kind(syn::to_string(a.shape.kind));
  if (a.json) {
    nlohmann::json j{{"kind", kind},           {"output", a.output}, {"points", cloud.size()}, {"width", cloud.width},
                     {"height", cloud.height}, {"frame", a.frame},   {"seed", a.seed}};
    std::cout << j.dump() << "\n";
  } else {
    std::cout << "terrain_synth: " << kind << " -> " << a.output << " (" << cloud.size() << " points, " << a.frame
              << " frame)\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Scan a synthetic terrain (flat, incline, step, plateau, rubble, post) with a simulated depth camera.",
               "terrain_synth"};
  Args a;
  add_options(app, a);

  return td::app::run(app, argc, argv, [&]() -> int {
    prepare_shape(a);
    OutputFiles out;
    out.cloud = out.staged.add(a.output, "--output");
    out.extrinsics = td::app::stage(out.staged, a.extrinsics_out, "--extrinsics-out");
    check_image_size(a.cam);
    a.shape.rubble_seed = a.seed;
    a.shape.prepare();
    check_camera_height(a);
    const Eigen::Isometry3d T =
        syn::nadir_camera_pose(a.cam_x, a.cam_y, a.cam_height, touchdown::deg_to_rad(a.cam_yaw_deg));
    const td::PointCloud cloud = scan(a, T);
    write_outputs(a, out, cloud, T);
    print_result(a, cloud);
    return td::app::kExitOk;
  });
}
