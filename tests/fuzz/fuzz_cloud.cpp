// libFuzzer target for one point cloud parser, chosen at compile time by
// TOUCHDOWN_FUZZ_FORMAT (0 = PCD, 1 = PLY, 2 = XYZ). Any input must either
// parse or throw touchdown::Error; crashes, leaks, UB and other exceptions
// are bugs.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "touchdown/core/cloud_io.hpp"
#include "touchdown/core/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
#if TOUCHDOWN_FUZZ_FORMAT == 0
    const auto cloud = touchdown::read_pcd(in, "fuzz.pcd");
#elif TOUCHDOWN_FUZZ_FORMAT == 1
    const auto cloud = touchdown::read_ply_cloud(in, "fuzz.ply");
#else
    const auto cloud = touchdown::read_xyz(in, "fuzz.xyz");
#endif
    // Written back and read again, it must be the same cloud.
    std::stringstream again;
    touchdown::write_pcd(cloud, again, touchdown::PcdEncoding::BinaryCompressed);
    const auto back = touchdown::read_pcd(again, "again.pcd");
    if (back.size() != cloud.size()) __builtin_trap();
  } catch (const touchdown::Error&) {
  }
  return 0;
}
