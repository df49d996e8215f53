#include "touchdown/core/cloud_io.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>

#include "io_util.hpp"
#include "touchdown/core/atomic_file.hpp"

namespace touchdown {

static_assert(sizeof(Eigen::Vector3f) == 12, "points are stored as packed float triples");

namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

template <typename WriteFn>
void write_stream_atomically(const std::filesystem::path& path, WriteFn&& fn) {
  write_file_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(path.string() + ": cannot write");
    fn(out);
    out.flush();
    if (!out) throw IoError(path.string() + ": write failed");
  });
}

}  // namespace

CloudFormat cloud_format_from_path(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".pcd") return CloudFormat::Pcd;
  if (ext == ".ply") return CloudFormat::Ply;
  if (ext == ".xyz" || ext == ".csv" || ext == ".txt" || ext == ".pts") return CloudFormat::Xyz;
  throw InvalidArgument(path.string() + ": unknown point cloud format '" + ext +
                        "' (expected .pcd, .ply, .xyz, .csv, .txt or .pts)");
}

PointCloud read_cloud(const std::filesystem::path& path, CloudFormat format) {
  // Opened first: a directory or a missing file says so, not "unknown format".
  std::ifstream in = detail::open_for_read(path);
  if (format == CloudFormat::Auto) format = cloud_format_from_path(path);
  const std::string source = path.string();
  PointCloud cloud;
  switch (format) {
    case CloudFormat::Pcd:
      cloud = read_pcd(in, source);
      break;
    case CloudFormat::Ply:
      cloud = read_ply_cloud(in, source);
      break;
    default:
      cloud = read_xyz(in, source);
      break;
  }
  if (in.bad()) throw IoError(source + ": read error");
  return cloud;
}

void write_pcd(const PointCloud& cloud, const std::filesystem::path& path, PcdEncoding encoding) {
  write_stream_atomically(path, [&](std::ostream& out) { write_pcd(cloud, out, encoding); });
}

void write_ply_cloud(const PointCloud& cloud, const std::filesystem::path& path, PlyEncoding encoding) {
  write_stream_atomically(path, [&](std::ostream& out) { write_ply_cloud(cloud, out, encoding); });
}

void write_xyz(const PointCloud& cloud, const std::filesystem::path& path) {
  write_stream_atomically(path, [&](std::ostream& out) { write_xyz(cloud, out); });
}

void write_cloud(const PointCloud& cloud, const std::filesystem::path& path) {
  switch (cloud_format_from_path(path)) {
    case CloudFormat::Pcd:
      write_pcd(cloud, path);
      break;
    case CloudFormat::Ply:
      write_ply_cloud(cloud, path);
      break;
    default:
      write_xyz(cloud, path);
      break;
  }
}

}  // namespace touchdown
