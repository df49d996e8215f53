#include "touchdown/core/cloud_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace td = touchdown;
using td::test::TempDir;

namespace {

td::PointCloud organized_cloud() {
  td::PointCloud c = td::test::random_cloud(6 * 4, 11);
  c.width = 6;
  c.height = 4;
  return c;
}

using touchdown::test::error_of;

td::PointCloud parse_pcd(const std::string& text) {
  std::istringstream in(text);
  return td::read_pcd(in, "mem.pcd");
}

std::string pcd_error(const std::string& text) {
  return error_of([&] { parse_pcd(text); });
}

std::string binary_bytes(std::initializer_list<float> v) {
  std::string s(v.size() * 4, '\0');
  std::memcpy(s.data(), std::data(v), s.size());
  return s;
}

}  // namespace

// ---- round trips -----------------------------------------------------------

TEST(CloudIo, PcdRoundTripIsExactForEveryEncoding) {
  TempDir dir;
  const td::PointCloud c = organized_cloud();
  for (auto enc : {td::PcdEncoding::Ascii, td::PcdEncoding::Binary, td::PcdEncoding::BinaryCompressed}) {
    const auto path = dir / ("c" + std::to_string(static_cast<int>(enc)) + ".pcd");
    td::write_pcd(c, path, enc);
    const td::PointCloud back = td::read_cloud(path);
    EXPECT_TRUE(td::test::same_points(c, back)) << "encoding " << static_cast<int>(enc);
    EXPECT_EQ(back.width, 6u);
    EXPECT_EQ(back.height, 4u);
    EXPECT_TRUE(back.is_organized());
  }
}

TEST(CloudIo, PcdCompressedRoundTripOfALargeCloud) {
  const td::PointCloud c = td::test::random_cloud(200000, 5);
  std::stringstream buf;
  td::write_pcd(c, buf, td::PcdEncoding::BinaryCompressed);
  EXPECT_TRUE(td::test::same_points(c, td::read_pcd(buf, "mem")));
}

TEST(CloudIo, PlyRoundTripIsExactForEveryEncoding) {
  TempDir dir;
  const td::PointCloud c = td::test::random_cloud(1000, 3);
  for (auto enc : {td::PlyEncoding::Ascii, td::PlyEncoding::BinaryLittleEndian, td::PlyEncoding::BinaryBigEndian}) {
    const auto path = dir / ("c" + std::to_string(static_cast<int>(enc)) + ".ply");
    td::write_ply_cloud(c, path, enc);
    EXPECT_TRUE(td::test::same_points(c, td::read_cloud(path))) << "encoding " << static_cast<int>(enc);
  }
}

TEST(CloudIo, XyzRoundTripIsExact) {
  TempDir dir;
  const td::PointCloud c = td::test::random_cloud(500, 4);
  td::write_cloud(c, dir / "c.xyz");
  EXPECT_TRUE(td::test::same_points(c, td::read_cloud(dir / "c.xyz")));
  td::write_cloud(c, dir / "c.csv");
  EXPECT_TRUE(td::test::same_points(c, td::read_cloud(dir / "c.csv")));
}

// ---- PCD details -------------------------------------------------------------

TEST(CloudIo, PcdAnyFieldOrderAndTypesWithExtraFields) {
  // Fields in a scrambled order, x as double, y as int16, extra fields with counts.
  const std::string ascii =
      "VERSION 0.7\nFIELDS rgb z normal y x\nSIZE 4 4 4 2 8\nTYPE F F F I F\nCOUNT 1 1 3 1 1\n"
      "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
      "4.2e6 3.5 0 0 1 -7 1.25\n0 -1 1 1 1 12 2.5\n";
  const auto c = parse_pcd(ascii);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[0], Eigen::Vector3f(1.25f, -7.f, 3.5f));
  EXPECT_EQ(c.points[1], Eigen::Vector3f(2.5f, 12.f, -1.f));

  // The same as binary: rgb(4) z(4) normal(12) y(2) x(8) = 30 bytes a point.
  std::string bin =
      "VERSION 0.7\nFIELDS rgb z normal y x\nSIZE 4 4 4 2 8\nTYPE F F F I F\nCOUNT 1 1 3 1 1\n"
      "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary\n";
  for (const auto& [x, y, z] : {std::tuple{1.25, std::int16_t{-7}, 3.5f}, std::tuple{2.5, std::int16_t{12}, -1.f}}) {
    char rec[30] = {};
    std::memcpy(rec + 4, &z, 4);
    std::memcpy(rec + 20, &y, 2);
    std::memcpy(rec + 22, &x, 8);
    bin.append(rec, 30);
  }
  const auto cb = parse_pcd(bin);
  ASSERT_EQ(cb.size(), 2u);
  EXPECT_EQ(cb.points[0], Eigen::Vector3f(1.25f, -7.f, 3.5f));
  EXPECT_EQ(cb.points[1], Eigen::Vector3f(2.5f, 12.f, -1.f));
}

TEST(CloudIo, PcdOldHeaderWithoutViewpointOrPoints) {
  const auto c = parse_pcd(
      "# .PCD v.5\nVERSION .5\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
      "WIDTH 1\nHEIGHT 1\nDATA ascii\n1 2 3\n");
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c.points[0], Eigen::Vector3f(1, 2, 3));
}

TEST(CloudIo, PcdAsciiNanValues) {
  const auto c =
      parse_pcd("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\nnan nan nan\n1 2 3\n");
  ASSERT_EQ(c.size(), 2u);
  EXPECT_TRUE(std::isnan(c.points[0].x()));
  EXPECT_EQ(c.points[1], Eigen::Vector3f(1, 2, 3));
}

// ---- real files written by PCL ------------------------------------------------

TEST(CloudIo, ReadsPclAsciiFiles) {
  const auto bunny = td::read_cloud(td::test::data_path("pcl/bunny.pcd"));
  ASSERT_EQ(bunny.size(), 397u);
  EXPECT_EQ(bunny.points[0], Eigen::Vector3f(0.0054216f, 0.11349f, 0.040749f));
  EXPECT_EQ(bunny.points[1], Eigen::Vector3f(-0.0017447f, 0.11425f, 0.041273f));
  const auto plane = td::read_cloud(td::test::data_path("pcl/sac_plane_test.pcd"));
  ASSERT_EQ(plane.size(), 3283u);
  EXPECT_EQ(plane.points[0], Eigen::Vector3f(1.068f, 0.094720997f, -0.016231f));
}

// Organized frames from a pinhole camera: along each image row x/z grows with
// the column, and y/z is constant-ish along the row. A wrongly decoded LZF
// stream or a field mix-up (SoA vs AoS) breaks both.
void expect_pinhole_frame(const std::string& name) {
  SCOPED_TRACE(name);
  const auto c = td::read_cloud(td::test::data_path("pcl/" + name));
  ASSERT_EQ(c.width, 640u);
  ASSERT_EQ(c.height, 480u);
  ASSERT_EQ(c.size(), 640u * 480u);
  std::size_t finite = 0, monotone = 0, pairs = 0;
  for (std::uint32_t v = 0; v < c.height; ++v) {
    double last = -1e9;
    for (std::uint32_t u = 0; u < c.width; ++u) {
      const auto& p = c.points[v * c.width + u];
      if (!p.allFinite()) continue;
      ++finite;
      EXPECT_GT(p.z(), 0.2f);
      EXPECT_LT(p.z(), 15.f);
      const double xz = p.x() / p.z();
      if (last > -1e9) {
        ++pairs;
        if (xz > last) ++monotone;
      }
      last = xz;
    }
  }
  EXPECT_GT(finite, 100000u);
  EXPECT_GT(static_cast<double>(monotone), 0.99 * static_cast<double>(pairs));
}

TEST(CloudIo, ReadsPclCompressedOrganizedFrames) {
  expect_pinhole_frame("frame_20121214T142255.814212.pcd");
  expect_pinhole_frame("table_scene_mug_stereo_textured.pcd");
  expect_pinhole_frame("office1.pcd");
}

TEST(CloudIo, ReadsPclCompressedUnorganizedCloud) {
  const auto c = td::read_cloud(td::test::data_path("pcl/milk_color.pcd"));
  ASSERT_EQ(c.size(), 13704u);
  EXPECT_FALSE(c.is_organized());
  for (const auto& p : c.points) {
    ASSERT_TRUE(p.allFinite());
    ASSERT_LT(p.norm(), 10.f);
  }
  // Re-encoding in every format reproduces it exactly.
  std::stringstream a, b;
  td::write_pcd(c, a, td::PcdEncoding::Ascii);
  td::write_pcd(c, b, td::PcdEncoding::BinaryCompressed);
  EXPECT_TRUE(td::test::same_points(c, td::read_pcd(a, "a")));
  EXPECT_TRUE(td::test::same_points(c, td::read_pcd(b, "b")));
}

// ---- bad PCD input: one clear error each --------------------------------------

const std::string kHead3 = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";

// Issue 11: the VIEWPOINT is kept as evidence of a sensor-frame cloud (PCL's
// organized frames record the sensor's orientation, 180 deg about x).
TEST(CloudIo, PcdViewpointIsKept) {
  const auto table = td::read_cloud(td::test::data_path("pcl/table_scene_mug_stereo_textured.pcd"));
  EXPECT_TRUE(table.has_viewpoint());
  EXPECT_EQ(table.viewpoint, (std::array<double, 7>{0, 0, 0, 0, 1, 0, 0}));
  EXPECT_FALSE(td::read_cloud(td::test::data_path("pcl/bunny.pcd")).has_viewpoint());  // v.5: no VIEWPOINT
  EXPECT_FALSE(td::read_cloud(td::test::data_path("pcl/milk_color.pcd")).has_viewpoint());
  // -q is the same rotation as q.
  EXPECT_FALSE(parse_pcd(kHead3 + "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 -1 0 0 0\nDATA ascii\n1 2 3\n").has_viewpoint());
  EXPECT_TRUE(parse_pcd(kHead3 + "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 1.5 1 0 0 0\nDATA ascii\n1 2 3\n").has_viewpoint());
  // Writers write the identity.
  std::stringstream out;
  td::write_pcd(table, out, td::PcdEncoding::Binary);
  EXPECT_FALSE(td::read_pcd(out, "out").has_viewpoint());
}

TEST(CloudIoBadInput, PcdViewpointNotSevenNumbers) {
  auto e = pcd_error(kHead3 + "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0\nDATA ascii\n1 2 3\n");
  EXPECT_NE(e.find("mem.pcd:8: header VIEWPOINT: expected 7 numbers"), std::string::npos) << e;
  e = pcd_error(kHead3 + "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 nan\nDATA ascii\n1 2 3\n");
  EXPECT_NE(e.find("header VIEWPOINT: 'nan' is not a finite number"), std::string::npos) << e;
}

TEST(CloudIoBadInput, PcdTruncatedBinary) {
  const std::string text = kHead3 + "WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA binary\n" + binary_bytes({1, 2, 3, 4, 5, 6, 7});
  const auto e = pcd_error(text);
  EXPECT_NE(e.find("mem.pcd: truncated binary data"), std::string::npos) << e;
}

TEST(CloudIoBadInput, PcdTruncatedCompressed) {
  std::stringstream full;
  td::write_pcd(td::test::random_cloud(100, 1), full, td::PcdEncoding::BinaryCompressed);
  const std::string s = full.str();
  const auto e = pcd_error(s.substr(0, s.size() - 10));
  EXPECT_NE(e.find("truncated binary_compressed"), std::string::npos) << e;
}

TEST(CloudIoBadInput, PcdCorruptCompressedStream) {
  std::stringstream full;
  td::write_pcd(td::test::random_cloud(100, 1), full, td::PcdEncoding::BinaryCompressed);
  std::string s = full.str();
  const auto data = s.find("DATA binary_compressed\n") + 23 + 8;
  s[data] = static_cast<char>(0xE0);  // a back reference before any output
  const auto e = pcd_error(s);
  EXPECT_NE(e.find("corrupt binary_compressed"), std::string::npos) << e;
}

// Found by fuzz_pcd: a field with a huge COUNT sized the binary reader's
// chunk buffer by it (16,384 points × 4 MB) although the file held no
// point; a compressed block claiming more output than LZF can produce from
// its size allocated that output before failing.
TEST(CloudIoBadInput, PcdHugeCountsAllocateOnlyWhatTheFileHolds) {
  const std::string head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1000000\n";
  EXPECT_EQ(parse_pcd(head + "WIDTH 0\nHEIGHT 2\nDATA binary\n" + binary_bytes({1, 2, 3})).points.size(), 0u);
  auto e = pcd_error(head + "WIDTH 2\nHEIGHT 1\nDATA binary\n" + binary_bytes({1, 2, 3, 4, 5, 6}));
  EXPECT_NE(e.find("truncated binary data: 2 points need 8000016 bytes, file has 24"), std::string::npos) << e;
  std::string block(8, '\0');
  const std::uint32_t sizes[2] = {10, 1200000000u};  // 10 bytes claimed to decode to 1.2 GB
  std::memcpy(block.data(), sizes, 8);
  e = pcd_error(kHead3 + "WIDTH 100000000\nHEIGHT 1\nDATA binary_compressed\n" + block + std::string(10, '\x01'));
  EXPECT_NE(e.find("corrupt binary_compressed data: 10 bytes cannot decode to 1200000000"), std::string::npos) << e;
}

TEST(CloudIoBadInput, PcdHeaderCountMismatch) {
  auto e = pcd_error(kHead3 + "WIDTH 3\nHEIGHT 1\nPOINTS 4\nDATA ascii\n1 2 3\n");
  EXPECT_NE(e.find("header mismatch: POINTS 4 but WIDTH*HEIGHT"), std::string::npos) << e;
  e = pcd_error(kHead3 + "WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 2 3\n4 5 6\n");
  EXPECT_NE(e.find("header/count mismatch: POINTS 3 but the file holds 2"), std::string::npos) << e;
  e = pcd_error(kHead3 + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n4 5 6\n");
  EXPECT_NE(e.find("more data lines than POINTS"), std::string::npos) << e;
  e = pcd_error("FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  EXPECT_NE(e.find("3 FIELDS but 2 SIZE"), std::string::npos) << e;
}

TEST(CloudIoBadInput, PcdUnknownDataType) {
  const auto e = pcd_error(kHead3 + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary_zstd\n");
  EXPECT_NE(e.find("mem.pcd:9: unknown DATA type 'binary_zstd'"), std::string::npos) << e;
}

TEST(CloudIoBadInput, PcdMissingXyzField) {
  const auto e = pcd_error("FIELDS x y intensity\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  EXPECT_NE(e.find("mem.pcd: PCD file has no 'z' field"), std::string::npos) << e;
}

TEST(CloudIoBadInput, PcdNonNumericAscii) {
  const auto e = pcd_error(kHead3 + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n4 five 6\n");
  EXPECT_NE(e.find("'five' is not a number"), std::string::npos) << e;
}

TEST(CloudIoBadInput, PcdBadSizesAndTypes) {
  EXPECT_NE(pcd_error("FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nWIDTH 1\nDATA ascii\n").find("SIZE 3"), std::string::npos);
  EXPECT_NE(pcd_error("FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nWIDTH 1\nDATA ascii\n").find("TYPE F with SIZE 2"),
            std::string::npos);
  EXPECT_NE(pcd_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F Q\nWIDTH 1\nDATA ascii\n").find("'Q' is not F, I or U"),
            std::string::npos);
  EXPECT_NE(pcd_error("").find("empty file"), std::string::npos);
  EXPECT_NE(pcd_error("hello world\n").find("not a PCD file"), std::string::npos);
  EXPECT_NE(pcd_error(kHead3 + "WIDTH 1\n").find("ends before the DATA line"), std::string::npos);
}

TEST(CloudIoBadInput, PcdHugePointCountDoesNotAllocate) {
  const auto e = pcd_error(kHead3 + "WIDTH 4000000000\nHEIGHT 1000\nDATA binary\n");
  EXPECT_NE(e.find("truncated binary data"), std::string::npos) << e;
}

// ---- PLY -----------------------------------------------------------------------

TEST(CloudIo, PlyMixedTypesAndFacesBeforeVertices) {
  // A face element before the vertex element must be skipped, lists included.
  std::string ply =
      "ply\nformat binary_big_endian 1.0\ncomment test\nelement face 2\nproperty list uchar int vertex_indices\n"
      "element vertex 2\nproperty uchar red\nproperty double x\nproperty short y\nproperty float z\nend_header\n";
  auto be = [](auto v) {
    std::string s(sizeof(v), '\0');
    std::memcpy(s.data(), &v, sizeof(v));
    std::reverse(s.begin(), s.end());
    return s;
  };
  ply += std::string(1, '\3') + be(std::int32_t{0}) + be(std::int32_t{1}) + be(std::int32_t{2});
  ply += std::string(1, '\1') + be(std::int32_t{9});
  ply += std::string(1, '\xff') + be(1.5) + be(std::int16_t{-3}) + be(0.25f);
  ply += std::string(1, '\x00') + be(-2.0) + be(std::int16_t{300}) + be(8.f);
  std::istringstream in(ply);
  const auto c = td::read_ply_cloud(in, "mem.ply");
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[0], Eigen::Vector3f(1.5f, -3.f, 0.25f));
  EXPECT_EQ(c.points[1], Eigen::Vector3f(-2.f, 300.f, 8.f));

  std::istringstream ascii(
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float z\nproperty float y\n"
      "property float x\nproperty uchar alpha\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n3 2 1 255\n6 5 4 0\n3 0 1 1\n");
  const auto ca = td::read_ply_cloud(ascii, "mem.ply");
  ASSERT_EQ(ca.size(), 2u);
  EXPECT_EQ(ca.points[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(ca.points[1], Eigen::Vector3f(4, 5, 6));
}

std::string ply_error(const std::string& text) {
  return error_of([&] {
    std::istringstream in(text);
    td::read_ply_cloud(in, "mem.ply");
  });
}

// Found by fuzz_ply: a binary list whose length field says 2^32 − 1 items
// must fail as truncated, without allocating for them.
TEST(CloudIoBadInput, PlyHugeListLengthIsTruncationNotAnAllocation) {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty list uint32 int32 extra\nend_header\n";
  ply += std::string(12, '\0');   // x, y, z
  ply += std::string(4, '\xff');  // list length 4294967295
  ply += std::string(16, '\0');
  std::istringstream in(ply);
  try {
    td::read_ply_cloud(in, "mem.ply");
    FAIL() << "no error";
  } catch (const td::ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("4294967295 items"), std::string::npos) << e.what();
  }
}

TEST(CloudIoBadInput, PlyErrors) {
  EXPECT_NE(ply_error("plx\n").find("mem.ply: not a PLY file"), std::string::npos);
  EXPECT_NE(ply_error("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int v\nend_header\n3 0 1 2\n")
                .find("no vertex element"),
            std::string::npos);
  EXPECT_NE(ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n")
                .find("no 'z' property"),
            std::string::npos);
  EXPECT_NE(ply_error("ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                      "property float z\nend_header\n" +
                      binary_bytes({1, 2, 3, 4}))
                .find("truncated binary PLY data"),
            std::string::npos);
  EXPECT_NE(ply_error("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                      "property float z\nend_header\n1 2 3\n4 x 6\n")
                .find("'x' is not a number"),
            std::string::npos);
  EXPECT_NE(ply_error("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                      "property float z\nend_header\n1 2 3\n4 5\n")
                .find("truncated PLY data"),
            std::string::npos);
  EXPECT_NE(ply_error("ply\nformat ascii 2.0 x\n").find("format line"), std::string::npos);
  EXPECT_NE(ply_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float64x x\nend_header\n")
                .find("unknown PLY property type"),
            std::string::npos);
}

// ---- XYZ -----------------------------------------------------------------------

TEST(CloudIo, XyzCommentsSeparatorsAndExtraColumns) {
  std::istringstream in(
      "# a comment\nx_is_not_here_either_but_commented # \n\n1 2 3\n4,5,6 # trailing\n 7\t8\t9 255\n");
  // The second line has no '#' before text: it must fail. Use a clean one instead.
  std::istringstream ok("# a comment\n\n1 2 3\n4,5,6 # trailing\n 7\t8\t9 255\n-1e-3;+2;3.5e2\n");
  const auto c = td::read_xyz(ok, "mem.xyz");
  ASSERT_EQ(c.size(), 4u);
  EXPECT_EQ(c.points[1], Eigen::Vector3f(4, 5, 6));
  EXPECT_EQ(c.points[2], Eigen::Vector3f(7, 8, 9));
  EXPECT_EQ(c.points[3], Eigen::Vector3f(-1e-3f, 2, 350));
  const auto e = error_of([&] { td::read_xyz(in, "mem.xyz"); });
  EXPECT_NE(e.find("mem.xyz:2: expected 3 numbers"), std::string::npos) << e;
}

TEST(CloudIoBadInput, XyzNonNumeric) {
  std::istringstream in("1 2 3\n4 5 six\n");
  const auto e = error_of([&] { td::read_xyz(in, "mem.xyz"); });
  EXPECT_EQ(e, "mem.xyz:2: 'six' is not a number");
  std::istringstream header("x,y,z\n1,2,3\n");
  const auto e2 = error_of([&] { td::read_xyz(header, "mem.csv"); });
  EXPECT_EQ(e2, "mem.csv:1: 'x' is not a number");
}

// ---- files -----------------------------------------------------------------------

TEST(CloudIoBadInput, UnreadableFiles) {
  TempDir dir;
  auto e = error_of([&] { td::read_cloud(dir / "missing.pcd"); });
  EXPECT_NE(e.find("missing.pcd: cannot open: no such file"), std::string::npos) << e;
  std::filesystem::create_directory(dir / "adir.pcd");
  e = error_of([&] { td::read_cloud(dir / "adir.pcd"); });
  EXPECT_NE(e.find("is a directory"), std::string::npos) << e;
  td::test::write_text(dir / "c.las", "x");
  e = error_of([&] { td::read_cloud(dir / "c.las"); });
  EXPECT_NE(e.find("unknown point cloud format '.las'"), std::string::npos) << e;
}

TEST(CloudIoBadInput, WriteToMissingDirectoryLeavesNothing) {
  TempDir dir;
  const auto e = error_of([&] { td::write_pcd(td::test::random_cloud(10, 1), dir / "nope" / "c.pcd"); });
  EXPECT_NE(e.find("output directory"), std::string::npos) << e;
  EXPECT_TRUE(dir.files().empty());
}
