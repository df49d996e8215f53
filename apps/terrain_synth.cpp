// terrain_synth: scan a synthetic terrain with a simulated depth camera and
// write the cloud (and the camera extrinsics) — how data/terrains/ is made.
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "app_common.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/cloud_io.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/terrain/extrinsics.hpp"
#include "touchdown/terrain/filters.hpp"
#include "touchdown/terrain/synthetic.hpp"

int main(int argc, char** argv) {
  namespace td = touchdown;
  namespace syn = td::terrain::synthetic;
  CLI::App app{"Scan a synthetic terrain (flat, incline, step, plateau, rubble, post) with a simulated depth camera.",
               "terrain_synth"};
  std::string kind, output, extrinsics_out, frame = "camera", encoding = "binary";
  syn::Shape shape;
  syn::DepthCamera cam;
  double cam_height = 1.2, cam_x = 0, cam_y = 0, cam_yaw_deg = 0, noise_scale = 1.0;
  std::vector<double> plateau_size;
  std::uint64_t seed = 1;
  bool json = false;
  app.add_option("KIND", kind, "flat, incline, step, plateau, rubble or post")->required();
  app.add_option("-o,--output", output, "cloud to write: .pcd, .ply, .xyz")->required();
  app.add_option("--extrinsics-out", extrinsics_out, "write the camera pose YAML here (for terrain_mesh --extrinsics)");
  app.add_option("--frame", frame, "camera (organized, optical frame) or world")
      ->check(CLI::IsMember({"camera", "world"}))
      ->capture_default_str();
  app.add_option("--encoding", encoding, "PCD encoding: ascii, binary or binary_compressed")
      ->check(CLI::IsMember({"ascii", "binary", "binary_compressed"}))
      ->capture_default_str();
  app.add_option("--camera-height", cam_height, "camera height above the origin [m]")->capture_default_str();
  app.add_option("--camera-x", cam_x, "camera x [m]")->capture_default_str();
  app.add_option("--camera-y", cam_y, "camera y [m]")->capture_default_str();
  app.add_option("--camera-yaw", cam_yaw_deg, "camera yaw [deg]")->capture_default_str();
  app.add_option("--width", cam.width, "image width [px]")->capture_default_str();
  app.add_option("--height", cam.height, "image height [px]")->capture_default_str();
  app.add_option("--fx", cam.fx, "focal length [px] (fy = fx; principal point at the centre)")->capture_default_str();
  app.add_option("--noise-scale", noise_scale, "multiplies depth noise, dropouts and outliers (0 = ideal)")
      ->capture_default_str();
  app.add_option("--azimuth", shape.azimuth_deg, "direction the incline rises / the step goes up [deg]")
      ->capture_default_str();
  app.add_option("--slope", shape.slope_deg, "incline angle [deg]")->capture_default_str();
  app.add_option("--step-height", shape.step_height, "step height [m]")->capture_default_str();
  app.add_option("--edge-offset", shape.edge_offset, "step edge distance from the origin [m]")->capture_default_str();
  app.add_option("--plateau-height", shape.plateau_height, "plateau height [m]")->capture_default_str();
  app.add_option("--plateau-size", plateau_size, "plateau length,width [m]")->delimiter(',')->expected(2);
  app.add_option("--rubble-count", shape.rubble_count, "number of rocks")->capture_default_str();
  app.add_option("--rubble-height", shape.rubble_max_height, "tallest rock [m]")->capture_default_str();
  std::vector<double> post;
  app.add_option("--post", post, "post: x,y,radius,height [m]")->delimiter(',')->expected(4);
  app.add_option("--seed", seed, "random seed")->capture_default_str();
  app.add_flag("--json", json, "print one JSON object on stdout");

  return td::app::run(app, argc, argv, [&]() -> int {
    shape.kind = syn::shape_kind_from_string(kind);
    if (plateau_size.size() == 2) shape.plateau_size = {plateau_size[0], plateau_size[1]};
    if (post.size() == 4) {
      shape.post_xy = {post[0], post[1]};
      shape.post_radius = post[2];
      shape.post_height = post[3];
    }
    shape.rubble_seed = seed;
    shape.prepare();
    if (cam.width <= 0 || cam.height <= 0 || !(cam.fx > 0))
      throw td::InvalidArgument("--width, --height and --fx must be positive");
    if (!(noise_scale >= 0)) throw td::InvalidArgument("--noise-scale must be >= 0");
    cam = syn::DepthCamera::centred(cam.width, cam.height, cam.fx);
    cam.subpixel *= noise_scale;
    cam.dropout_fraction *= noise_scale;
    cam.outlier_fraction *= noise_scale;
    cam.flying_pixels = noise_scale > 0;
    const Eigen::Isometry3d T = syn::nadir_camera_pose(cam_x, cam_y, cam_height, touchdown::deg_to_rad(cam_yaw_deg));
    td::PointCloud cloud = syn::render_depth_scan(shape, cam, T, seed);
    if (frame == "world") {
      td::terrain::remove_non_finite(cloud);
      td::terrain::transform_cloud(cloud, T);
    }
    if (td::cloud_format_from_path(output) == td::CloudFormat::Pcd) {
      const auto enc = encoding == "ascii"    ? td::PcdEncoding::Ascii
                       : encoding == "binary" ? td::PcdEncoding::Binary
                                              : td::PcdEncoding::BinaryCompressed;
      td::write_pcd(cloud, output, enc);
    } else {
      td::write_cloud(cloud, output);
    }
    if (!extrinsics_out.empty()) {
      td::terrain::Extrinsics e;
      if (frame == "camera") e.T_world_camera = T;
      const std::string text = td::terrain::format_extrinsics(e, false);
      td::write_file_atomically(extrinsics_out, [&](const std::filesystem::path& tmp) {
        std::ofstream out(tmp);
        out << text;
        if (!out) throw td::IoError(extrinsics_out + ": write failed");
      });
    }
    if (json) {
      nlohmann::json j{{"kind", kind},         {"output", output},       {"points", cloud.size()},
                       {"width", cloud.width}, {"height", cloud.height}, {"frame", frame},
                       {"seed", seed}};
      std::cout << j.dump() << "\n";
    } else {
      std::cout << "terrain_synth: " << kind << " -> " << output << " (" << cloud.size() << " points, " << frame
                << " frame)\n";
    }
    return td::app::kExitOk;
  });
}
