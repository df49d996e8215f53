// A consumer that links only touchdown::pose (what an onboard computer
// links): reads the installed constellation file, observes it through a
// camera and recovers the pose with EPnP + Gauss–Newton. Its link line must
// not name OpenCV or Ceres (tests/package/CMakeLists.txt checks with ldd).
#include <Eigen/Geometry>
#include <iostream>
#include <touchdown/pose/camera.hpp>
#include <touchdown/pose/constellation.hpp>
#include <touchdown/pose/epnp.hpp>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: touchdown_pose_consumer CONSTELLATION.yaml\n";
    return 2;
  }
  const auto constellation = touchdown::pose::load_constellation(argv[1]);
  const touchdown::pose::PinholeCamera camera{615.0, 615.0, 423.5, 239.5};
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.1, -0.05, 1.5);
  std::vector<Eigen::Vector3d> p_body;
  std::vector<Eigen::Vector2d> uv;
  for (const auto& led : constellation.leds) {
    p_body.push_back(led.p_body);
    uv.push_back(camera.project(T * led.p_body));
  }
  const auto r = touchdown::pose::solve_pnp(camera, p_body, uv);
  const double error = (r.T_camera_body.translation() - T.translation()).norm();
  if (!r.ok() || !(error < 1e-6)) {
    std::cerr << "pose not recovered: error " << error << " m\n";
    return 1;
  }
  std::cout << "pose from " << p_body.size() << " LEDs: error " << error << " m\n";
  return 0;
}
