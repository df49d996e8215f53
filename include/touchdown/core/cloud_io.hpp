#pragma once
/// \file
/// Point cloud readers and writers: PCD v0.7 (and the older v.5 header) in
/// `ascii`, `binary` and `binary_compressed` (LZF); PLY vertex data in ascii,
/// binary little- and big-endian; and XYZ/CSV text. Formats: docs/formats.md.
///
/// Readers take only x, y, z (any numeric type, any field order, any extra
/// fields) and throw touchdown::IoError or touchdown::ParseError whose message
/// starts with the source name: `"scan.pcd: truncated binary data: ..."`.
/// Writers write to a temporary file and rename it, so a failure never leaves
/// a partial file behind.
#include <array>
#include <filesystem>
#include <iosfwd>
#include <string_view>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/point_cloud.hpp"

namespace touchdown {

enum class CloudFormat { Auto, Pcd, Ply, Xyz };
/// Named as a PCD header's DATA line spells them.
enum class PcdEncoding { Ascii, Binary, BinaryCompressed };
/// Named as a PLY header's format line spells them.
enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

template <>
struct EnumNames<CloudFormat> {
  static constexpr std::array<std::string_view, 4> names{"auto", "pcd", "ply", "xyz"};
};
template <>
struct EnumNames<PcdEncoding> {
  static constexpr std::array<std::string_view, 3> names{"ascii", "binary", "binary_compressed"};
};
template <>
struct EnumNames<PlyEncoding> {
  static constexpr std::array<std::string_view, 3> names{"ascii", "binary_little_endian", "binary_big_endian"};
};
inline std::string_view to_string(CloudFormat format) { return enum_name(format); }
inline std::string_view to_string(PcdEncoding encoding) { return enum_name(encoding); }
inline std::string_view to_string(PlyEncoding encoding) { return enum_name(encoding); }

/// Format from a file extension (.pcd, .ply, .xyz/.csv/.txt/.pts); throws
/// InvalidArgument naming the path for anything else.
CloudFormat cloud_format_from_path(const std::filesystem::path& path);

/// Reads a point cloud file; `format == Auto` picks by extension.
PointCloud read_cloud(const std::filesystem::path& path, CloudFormat format = CloudFormat::Auto);

/// Stream readers; `source` names the input in error messages.
PointCloud read_pcd(std::istream& in, std::string_view source);
PointCloud read_ply_cloud(std::istream& in, std::string_view source);
PointCloud read_xyz(std::istream& in, std::string_view source);

/// Writes by extension: .pcd (binary), .ply (binary little-endian),
/// .xyz/.csv/.txt (text).
void write_cloud(const PointCloud& cloud, const std::filesystem::path& path);
void write_pcd(const PointCloud& cloud, const std::filesystem::path& path, PcdEncoding encoding = PcdEncoding::Binary);
void write_ply_cloud(const PointCloud& cloud, const std::filesystem::path& path,
                     PlyEncoding encoding = PlyEncoding::BinaryLittleEndian);
void write_xyz(const PointCloud& cloud, const std::filesystem::path& path);

/// Stream writers (no atomic rename; the caller owns the stream).
void write_pcd(const PointCloud& cloud, std::ostream& out, PcdEncoding encoding);
void write_ply_cloud(const PointCloud& cloud, std::ostream& out, PlyEncoding encoding);
void write_xyz(const PointCloud& cloud, std::ostream& out);

}  // namespace touchdown
