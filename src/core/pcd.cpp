// PCD reader and writer, following the PCD file format specification of the
// Point Cloud Library (pointclouds.org, "The PCD (Point Cloud Data) file
// format", v0.7), including the older v.5 header (no VIEWPOINT, COLUMNS as a
// synonym of FIELDS).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

#include "format.hpp"
#include "io_util.hpp"
#include "lzf.hpp"
#include "touchdown/core/cloud_io.hpp"

static_assert(std::endian::native == std::endian::little, "PCD binary data is little-endian");

namespace touchdown {
namespace {

using detail::parse_fail;

struct PcdField {
  std::string name;
  unsigned size = 4;
  char type = 'F';
  unsigned count = 1;
  std::size_t offset = 0;  // byte offset inside one binary point record
};

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t width = 0;
  std::uint64_t height = 1;
  std::uint64_t points = 0;
  bool have_points = false;
  bool have_width = false;
  PcdEncoding data = PcdEncoding::Ascii;
  std::size_t point_size = 0;  // bytes per point record
  std::array<int, 3> xyz{-1, -1, -1};
  std::array<double, 7> viewpoint{0, 0, 0, 1, 0, 0, 0};
};

// Reads one scalar of the given PCD type from raw little-endian bytes.
double read_scalar(const std::uint8_t* p, char type, unsigned size) {
  switch (type) {
    case 'F':
      if (size == 4) {
        float v;
        std::memcpy(&v, p, 4);
        return v;
      } else {
        double v;
        std::memcpy(&v, p, 8);
        return v;
      }
    case 'I':
      switch (size) {
        case 1:
          return static_cast<std::int8_t>(*p);
        case 2: {
          std::int16_t v;
          std::memcpy(&v, p, 2);
          return v;
        }
        case 4: {
          std::int32_t v;
          std::memcpy(&v, p, 4);
          return v;
        }
        default: {
          std::int64_t v;
          std::memcpy(&v, p, 8);
          return static_cast<double>(v);
        }
      }
    default:  // 'U'
      switch (size) {
        case 1:
          return *p;
        case 2: {
          std::uint16_t v;
          std::memcpy(&v, p, 2);
          return v;
        }
        case 4: {
          std::uint32_t v;
          std::memcpy(&v, p, 4);
          return v;
        }
        default: {
          std::uint64_t v;
          std::memcpy(&v, p, 8);
          return static_cast<double>(v);
        }
      }
  }
}

template <typename T>
void parse_list(std::string_view source, std::size_t line_no, const std::vector<std::string_view>& tok,
                std::string_view key, std::vector<T>& out) {
  out.clear();
  for (std::size_t i = 1; i < tok.size(); ++i) {
    T v{};
    if (!detail::parse_int(tok[i], v)) {
      detail::parse_fail_line(
          source, line_no,
          "header " + std::string(key) + ": '" + std::string(tok[i]) + "' is not a non-negative integer");
    }
    out.push_back(v);
  }
}

PcdHeader read_header(std::istream& in, std::string_view source) {
  PcdHeader h;
  std::vector<std::string> names;
  std::vector<unsigned> sizes, counts;
  std::vector<char> types;
  bool have_fields = false, have_size = false, have_type = false, have_count = false, have_data = false;
  std::string line;
  std::vector<std::string_view> tok;
  std::size_t line_no = 0;
  while (!have_data) {
    if (!detail::read_line(in, line)) {
      parse_fail(source, line_no == 0 ? "empty file, not a PCD file" : "PCD header ends before the DATA line");
    }
    ++line_no;
    if (line_no == 1 && line.find('\0') != std::string::npos) parse_fail(source, "not a PCD file (binary content)");
    const auto hash = line.find('#');
    std::string_view body = detail::trim(std::string_view(line).substr(0, hash));
    if (body.empty()) continue;
    detail::split(body, tok);
    const std::string_view key = tok[0];
    if (key == "VERSION") {
      continue;
    } else if (key == "FIELDS" || key == "COLUMNS") {
      names.assign(tok.begin() + 1, tok.end());
      have_fields = true;
    } else if (key == "SIZE") {
      parse_list(source, line_no, tok, key, sizes);
      have_size = true;
    } else if (key == "TYPE") {
      types.clear();
      for (std::size_t i = 1; i < tok.size(); ++i) {
        if (tok[i].size() != 1 || (tok[i][0] != 'F' && tok[i][0] != 'I' && tok[i][0] != 'U')) {
          detail::parse_fail_line(source, line_no, "header TYPE: '" + std::string(tok[i]) + "' is not F, I or U");
        }
        types.push_back(tok[i][0]);
      }
      have_type = true;
    } else if (key == "COUNT") {
      parse_list(source, line_no, tok, key, counts);
      have_count = true;
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      std::uint64_t v = 0;
      if (tok.size() != 2 || !detail::parse_int(tok[1], v)) {
        detail::parse_fail_line(source, line_no, "header " + std::string(key) + ": expected one non-negative integer");
      }
      if (key == "WIDTH") {
        h.width = v;
        h.have_width = true;
      } else if (key == "HEIGHT") {
        h.height = v;
      } else {
        h.points = v;
        h.have_points = true;
      }
    } else if (key == "VIEWPOINT") {
      // tx ty tz qw qx qy qz: kept as evidence of a sensor-frame cloud.
      if (tok.size() != 8) {
        detail::parse_fail_line(source, line_no, "header VIEWPOINT: expected 7 numbers (tx ty tz qw qx qy qz)");
      }
      for (std::size_t i = 0; i < 7; ++i) {
        if (!detail::parse_double(tok[i + 1], h.viewpoint[i]) || !std::isfinite(h.viewpoint[i])) {
          detail::parse_fail_line(source, line_no,
                                  "header VIEWPOINT: '" + std::string(tok[i + 1]) + "' is not a finite number");
        }
      }
    } else if (key == "DATA") {
      if (tok.size() != 2) detail::parse_fail_line(source, line_no, "header DATA: expected one word");
      try {
        h.data = from_string<PcdEncoding>(tok[1]);
      } catch (const InvalidArgument&) {
        detail::parse_fail_line(
            source, line_no,
            "unknown DATA type '" + std::string(tok[1]) + "' (expected one of " + enum_names_list<PcdEncoding>() + ")");
      }
      have_data = true;
    } else {
      detail::parse_fail_line(source, line_no,
                              line_no == 1 ? "not a PCD file (unknown header line '" + std::string(key) + "')"
                                           : "unknown PCD header key '" + std::string(key) + "'");
    }
  }
  if (!have_fields) parse_fail(source, "PCD header has no FIELDS line");
  if (!have_size) parse_fail(source, "PCD header has no SIZE line");
  if (!have_type) parse_fail(source, "PCD header has no TYPE line");
  const std::size_t nf = names.size();
  if (nf == 0) parse_fail(source, "PCD header FIELDS is empty");
  if (!have_count) counts.assign(nf, 1);
  if (sizes.size() != nf || types.size() != nf || counts.size() != nf) {
    parse_fail(source, "PCD header mismatch: " + std::to_string(nf) + " FIELDS but " + std::to_string(sizes.size()) +
                           " SIZE, " + std::to_string(types.size()) + " TYPE, " + std::to_string(counts.size()) +
                           " COUNT entries");
  }
  std::size_t offset = 0;
  for (std::size_t i = 0; i < nf; ++i) {
    PcdField f{names[i], sizes[i], types[i], counts[i], offset};
    if (f.size != 1 && f.size != 2 && f.size != 4 && f.size != 8) {
      parse_fail(source, "PCD field '" + f.name + "' has SIZE " + std::to_string(f.size) + " (expected 1, 2, 4 or 8)");
    }
    if (f.type == 'F' && f.size != 4 && f.size != 8) {
      parse_fail(source,
                 "PCD field '" + f.name + "' is TYPE F with SIZE " + std::to_string(f.size) + " (expected 4 or 8)");
    }
    if (f.count == 0 || f.count > 1u << 20) {
      parse_fail(source, "PCD field '" + f.name + "' has COUNT " + std::to_string(f.count));
    }
    offset += std::size_t{f.size} * f.count;
    for (int a = 0; a < 3; ++a) {
      if (f.name == std::string(1, "xyz"[a]) && h.xyz[a] < 0) h.xyz[a] = static_cast<int>(i);
    }
    h.fields.push_back(std::move(f));
  }
  h.point_size = offset;
  for (int a = 0; a < 3; ++a) {
    if (h.xyz[a] < 0) parse_fail(source, std::string("PCD file has no '") + "xyz"[a] + "' field");
  }
  if (!h.have_width) parse_fail(source, "PCD header has no WIDTH line");
  if (h.width > (1ull << 32) || h.height > (1ull << 32)) parse_fail(source, "PCD WIDTH/HEIGHT too large");
  const std::uint64_t wh = h.width * h.height;
  if (!h.have_points) h.points = wh;
  if (h.points != wh) {
    parse_fail(source, "PCD header mismatch: POINTS " + std::to_string(h.points) + " but WIDTH*HEIGHT = " +
                           std::to_string(h.width) + "*" + std::to_string(h.height) + " = " + std::to_string(wh));
  }
  return h;
}

PointCloud make_cloud(const PcdHeader& h) {
  PointCloud c;
  c.width = static_cast<std::uint32_t>(h.width);
  c.height = static_cast<std::uint32_t>(h.height);
  c.viewpoint = h.viewpoint;
  return c;
}

void read_ascii(std::istream& in, std::string_view source, const PcdHeader& h, PointCloud& cloud) {
  // Token index of each coordinate within a line.
  std::array<std::size_t, 3> col{};
  std::size_t tokens_per_point = 0;
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      if (static_cast<int>(i) == h.xyz[a]) col[a] = tokens_per_point;
    }
    tokens_per_point += h.fields[i].count;
  }
  const std::uint64_t budget = detail::remaining_bytes(in);
  cloud.points.reserve(static_cast<std::size_t>(std::min<std::uint64_t>(h.points, budget / 2 + 1)));
  std::string line;
  std::vector<std::string_view> tok;
  std::uint64_t n = 0;
  std::size_t line_no = 0;
  while (detail::read_line(in, line)) {
    ++line_no;
    detail::split(line, tok);
    if (tok.empty()) continue;
    if (n == h.points) {
      parse_fail(source, "header/count mismatch: more data lines than POINTS " + std::to_string(h.points));
    }
    if (tok.size() != tokens_per_point) {
      parse_fail(source, "data line " + std::to_string(line_no) + " (point " + std::to_string(n) + ") has " +
                             std::to_string(tok.size()) + " values, header says " + std::to_string(tokens_per_point));
    }
    Eigen::Vector3f p;
    for (int a = 0; a < 3; ++a) {
      double v;
      if (!detail::parse_double(tok[col[a]], v)) {
        parse_fail(source,
                   "data line " + std::to_string(line_no) + ": '" + std::string(tok[col[a]]) + "' is not a number");
      }
      p[a] = static_cast<float>(v);
    }
    cloud.points.push_back(p);
    ++n;
  }
  if (n != h.points) {
    parse_fail(source, "header/count mismatch: POINTS " + std::to_string(h.points) + " but the file holds " +
                           std::to_string(n) + " points");
  }
}

void read_binary(std::istream& in, std::string_view source, const PcdHeader& h, PointCloud& cloud) {
  const std::uint64_t need = h.points * h.point_size;
  const std::uint64_t have = detail::remaining_bytes(in);
  if (have < need) {
    parse_fail(source, "truncated binary data: " + std::to_string(h.points) + " points need " + std::to_string(need) +
                           " bytes, file has " + std::to_string(have));
  }
  std::array<const PcdField*, 3> f{};
  for (int a = 0; a < 3; ++a) f[a] = &h.fields[static_cast<std::size_t>(h.xyz[a])];
  cloud.points.resize(static_cast<std::size_t>(h.points));
  // At most the bytes the file holds (`need` <= `have`): a header with a
  // huge COUNT and few points must not size the buffer by the chunk.
  const std::size_t chunk_points = std::min<std::size_t>(std::size_t{1} << 14, cloud.points.size());
  std::vector<std::uint8_t> buf(chunk_points * h.point_size);
  const bool fast = f[0]->type == 'F' && f[0]->size == 4 && f[1]->type == 'F' && f[1]->size == 4 && f[2]->type == 'F' &&
                    f[2]->size == 4;
  for (std::size_t start = 0; start < cloud.points.size(); start += chunk_points) {
    const std::size_t n = std::min(chunk_points, cloud.points.size() - start);
    in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(n * h.point_size));
    if (static_cast<std::size_t>(in.gcount()) != n * h.point_size) {
      parse_fail(source, "truncated binary data at point " +
                             std::to_string(start + static_cast<std::size_t>(in.gcount()) / h.point_size));
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint8_t* rec = buf.data() + i * h.point_size;
      Eigen::Vector3f& p = cloud.points[start + i];
      if (fast) {
        for (int a = 0; a < 3; ++a) std::memcpy(&p[a], rec + f[a]->offset, 4);
      } else {
        for (int a = 0; a < 3; ++a) p[a] = static_cast<float>(read_scalar(rec + f[a]->offset, f[a]->type, f[a]->size));
      }
    }
  }
}

void read_compressed(std::istream& in, std::string_view source, const PcdHeader& h, PointCloud& cloud) {
  std::uint32_t sizes[2];
  in.read(reinterpret_cast<char*>(sizes), 8);
  if (in.gcount() != 8) parse_fail(source, "truncated binary_compressed data: missing the size words");
  const std::uint64_t compressed = sizes[0], uncompressed = sizes[1];
  const std::uint64_t need = h.points * h.point_size;
  if (uncompressed != need) {
    parse_fail(source, "header/count mismatch: binary_compressed block holds " + std::to_string(uncompressed) +
                           " bytes but " + std::to_string(h.points) + " points need " + std::to_string(need));
  }
  const std::uint64_t have = detail::remaining_bytes(in);
  if (have < compressed) {
    parse_fail(source, "truncated binary_compressed data: block of " + std::to_string(compressed) +
                           " bytes, file has " + std::to_string(have));
  }
  // LZF expands at most 264 bytes per 3-byte back-reference: a block that
  // claims more is corrupt (checked before allocating its output).
  if (uncompressed > 88 * compressed + 264) {
    parse_fail(source, "corrupt binary_compressed data: " + std::to_string(compressed) + " bytes cannot decode to " +
                           std::to_string(uncompressed));
  }
  std::vector<std::uint8_t> packed(static_cast<std::size_t>(compressed));
  in.read(reinterpret_cast<char*>(packed.data()), static_cast<std::streamsize>(compressed));
  if (static_cast<std::uint64_t>(in.gcount()) != compressed) parse_fail(source, "truncated binary_compressed data");
  std::vector<std::uint8_t> raw(static_cast<std::size_t>(uncompressed));
  if (need > 0 && !detail::lzf_decompress(packed.data(), packed.size(), raw.data(), raw.size())) {
    parse_fail(source,
               "corrupt binary_compressed data (LZF stream does not decode to " + std::to_string(need) + " bytes)");
  }
  packed = {};
  // Decompressed data is stored field by field: all x, then all y, ...
  const std::size_t n = static_cast<std::size_t>(h.points);
  cloud.points.resize(n);
  for (int a = 0; a < 3; ++a) {
    const PcdField& f = h.fields[static_cast<std::size_t>(h.xyz[a])];
    const std::uint8_t* col = raw.data() + f.offset * n;
    const std::size_t stride = std::size_t{f.size} * f.count;
    for (std::size_t i = 0; i < n; ++i) {
      cloud.points[i][a] = static_cast<float>(read_scalar(col + i * stride, f.type, f.size));
    }
  }
}

void write_header(std::ostream& out, const PointCloud& cloud, PcdEncoding data) {
  const bool organized = cloud.is_organized();
  out << "# .PCD v0.7 - Point Cloud Data file format\n"
      << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
      << "WIDTH " << (organized ? cloud.width : cloud.size()) << "\n"
      << "HEIGHT " << (organized ? cloud.height : 1) << "\n"
      << "VIEWPOINT 0 0 0 1 0 0 0\n"
      << "POINTS " << cloud.size() << "\n"
      << "DATA " << to_string(data) << "\n";
}

}  // namespace

PointCloud read_pcd(std::istream& in, std::string_view source) {
  const PcdHeader h = read_header(in, source);
  PointCloud cloud = make_cloud(h);
  switch (h.data) {
    case PcdEncoding::Ascii:
      read_ascii(in, source, h, cloud);
      break;
    case PcdEncoding::Binary:
      read_binary(in, source, h, cloud);
      break;
    case PcdEncoding::BinaryCompressed:
      read_compressed(in, source, h, cloud);
      break;
  }
  if (!cloud.is_organized()) cloud.mark_unorganized();
  return cloud;
}

void write_pcd(const PointCloud& cloud, std::ostream& out, PcdEncoding encoding) {
  switch (encoding) {
    case PcdEncoding::Ascii:
      write_header(out, cloud, encoding);
      write_xyz(cloud, out);  // PCD's ASCII body is an XYZ text cloud: "x y z" a line, nan as "nan"
      break;
    case PcdEncoding::Binary:
      write_header(out, cloud, encoding);
      out.write(reinterpret_cast<const char*>(cloud.points.data()),
                static_cast<std::streamsize>(cloud.points.size() * sizeof(Eigen::Vector3f)));
      break;
    case PcdEncoding::BinaryCompressed: {
      write_header(out, cloud, encoding);
      const std::size_t n = cloud.size();
      std::vector<std::uint8_t> soa(n * 12);
      for (std::size_t i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a)
          std::memcpy(soa.data() + (static_cast<std::size_t>(a) * n + i) * 4, &cloud.points[i][a], 4);
      }
      const std::vector<std::uint8_t> packed = detail::lzf_compress(soa.data(), soa.size());
      const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(packed.size()),
                                      static_cast<std::uint32_t>(soa.size())};
      out.write(reinterpret_cast<const char*>(sizes), 8);
      out.write(reinterpret_cast<const char*>(packed.data()), static_cast<std::streamsize>(packed.size()));
      break;
    }
  }
}

}  // namespace touchdown
