// PLY vertex reader and writer, following Greg Turk's PLY format description
// ("The PLY Polygon File Format", and the property type names of rply/PLY
// 1.0: char/int8, uchar/uint8, short/int16, ushort/uint16, int/int32,
// uint/uint32, float/float32, double/float64). Only the vertex element's
// x, y, z are kept; other elements (faces, ...) are skipped or ignored.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <istream>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "io_util.hpp"
#include "touchdown/core/cloud_io.hpp"

namespace touchdown {
namespace {

using detail::parse_fail;

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };

std::optional<PlyType> ply_type(std::string_view s) {
  if (s == "char" || s == "int8") return PlyType::I8;
  if (s == "uchar" || s == "uint8") return PlyType::U8;
  if (s == "short" || s == "int16") return PlyType::I16;
  if (s == "ushort" || s == "uint16") return PlyType::U16;
  if (s == "int" || s == "int32") return PlyType::I32;
  if (s == "uint" || s == "uint32") return PlyType::U32;
  if (s == "float" || s == "float32") return PlyType::F32;
  if (s == "double" || s == "float64") return PlyType::F64;
  return std::nullopt;
}

std::size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::I8:
    case PlyType::U8:
      return 1;
    case PlyType::I16:
    case PlyType::U16:
      return 2;
    case PlyType::I32:
    case PlyType::U32:
    case PlyType::F32:
      return 4;
    case PlyType::F64:
      return 8;
  }
  return 0;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::F32;  // item type for lists
  bool is_list = false;
  PlyType count_type = PlyType::U8;
  std::size_t offset = 0;  // within a fixed-size record
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> props;
  bool has_list = false;
  std::size_t record_size = 0;  // valid when !has_list
};

double decode(const std::uint8_t* p, PlyType t, bool swap) {
  std::uint8_t b[8];
  const std::size_t n = type_size(t);
  std::memcpy(b, p, n);
  if (swap) std::reverse(b, b + n);
  switch (t) {
    case PlyType::I8:
      return static_cast<std::int8_t>(b[0]);
    case PlyType::U8:
      return b[0];
    case PlyType::I16: {
      std::int16_t v;
      std::memcpy(&v, b, 2);
      return v;
    }
    case PlyType::U16: {
      std::uint16_t v;
      std::memcpy(&v, b, 2);
      return v;
    }
    case PlyType::I32: {
      std::int32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case PlyType::U32: {
      std::uint32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case PlyType::F32: {
      float v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case PlyType::F64: {
      double v;
      std::memcpy(&v, b, 8);
      return v;
    }
  }
  return 0;
}

struct PlyHeader {
  PlyEncoding format = PlyEncoding::Ascii;
  std::vector<PlyElement> elements;
  std::size_t vertex = 0;  // index of the vertex element
  std::array<std::size_t, 3> xyz{};
};

PlyHeader read_header(std::istream& in, std::string_view source) {
  PlyHeader h;
  std::string line;
  std::vector<std::string_view> tok;
  if (!detail::read_line(in, line) || detail::trim(line) != "ply")
    parse_fail(source, "not a PLY file (first line is not 'ply')");
  std::size_t line_no = 1;
  bool have_format = false;
  for (;;) {
    if (!detail::read_line(in, line)) parse_fail(source, "PLY header ends before 'end_header'");
    ++line_no;
    detail::split(line, tok);
    if (tok.empty()) continue;
    const auto key = tok[0];
    if (key == "end_header") break;
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (tok.size() != 3) detail::parse_fail_line(source, line_no, "PLY format line must be 'format <type> 1.0'");
      try {
        h.format = from_string<PlyEncoding>(tok[1]);
      } catch (const InvalidArgument&) {
        detail::parse_fail_line(source, line_no,
                                "unknown PLY format '" + std::string(tok[1]) + "' (expected one of " +
                                    enum_names_list<PlyEncoding>() + ")");
      }
      have_format = true;
    } else if (key == "element") {
      PlyElement e;
      if (tok.size() != 3 || !detail::parse_int(tok[2], e.count)) {
        detail::parse_fail_line(source, line_no, "PLY element line must be 'element <name> <count>'");
      }
      e.name = std::string(tok[1]);
      h.elements.push_back(std::move(e));
    } else if (key == "property") {
      if (h.elements.empty()) detail::parse_fail_line(source, line_no, "PLY property before any element");
      PlyProperty p;
      std::optional<PlyType> t;
      if (tok.size() == 5 && tok[1] == "list") {
        auto ct = ply_type(tok[2]);
        t = ply_type(tok[3]);
        if (!ct || !t || *ct == PlyType::F32 || *ct == PlyType::F64) {
          detail::parse_fail_line(source, line_no, "bad PLY list property types");
        }
        p.is_list = true;
        p.count_type = *ct;
        p.name = std::string(tok[4]);
      } else if (tok.size() == 3) {
        t = ply_type(tok[1]);
        if (!t) detail::parse_fail_line(source, line_no, "unknown PLY property type '" + std::string(tok[1]) + "'");
        p.name = std::string(tok[2]);
      } else {
        detail::parse_fail_line(source, line_no, "PLY property line must be 'property <type> <name>'");
      }
      p.type = *t;
      h.elements.back().props.push_back(std::move(p));
    } else {
      detail::parse_fail_line(source, line_no, "unknown PLY header keyword '" + std::string(key) + "'");
    }
  }
  if (!have_format) parse_fail(source, "PLY header has no format line");
  bool found = false;
  for (std::size_t i = 0; i < h.elements.size(); ++i) {
    auto& e = h.elements[i];
    std::size_t off = 0;
    for (auto& p : e.props) {
      p.offset = off;
      if (p.is_list) e.has_list = true;
      off += type_size(p.type);
    }
    e.record_size = off;
    if (e.count > 0 && e.props.empty()) parse_fail(source, "PLY element '" + e.name + "' has no properties");
    if (e.name == "vertex" && !found) {
      found = true;
      h.vertex = i;
      for (int a = 0; a < 3; ++a) {
        const std::string want(1, "xyz"[a]);
        auto it = std::find_if(e.props.begin(), e.props.end(), [&](const PlyProperty& p) { return p.name == want; });
        if (it == e.props.end() || it->is_list) parse_fail(source, "PLY vertex element has no '" + want + "' property");
        h.xyz[static_cast<std::size_t>(a)] = static_cast<std::size_t>(it - e.props.begin());
      }
    }
  }
  if (!found) parse_fail(source, "PLY file has no vertex element");
  return h;
}

// Minimal whitespace token reader over the ASCII body.
class TokenReader {
 public:
  explicit TokenReader(std::istream& in) : in_(in) {}
  bool next(std::string& tok) { return static_cast<bool>(in_ >> tok); }

 private:
  std::istream& in_;
};

void read_ascii(std::istream& in, std::string_view source, const PlyHeader& h, PointCloud& cloud) {
  TokenReader reader(in);
  std::string tok;
  auto next_number = [&](const std::string& where) {
    if (!reader.next(tok)) parse_fail(source, "truncated PLY data: ends inside " + where);
    double v;
    if (!detail::parse_double(tok, v)) parse_fail(source, "PLY " + where + ": '" + tok + "' is not a number");
    return v;
  };
  for (std::size_t ei = 0; ei <= h.vertex; ++ei) {
    const PlyElement& e = h.elements[ei];
    const bool is_vertex = ei == h.vertex;
    if (is_vertex) {
      const std::uint64_t budget = detail::remaining_bytes(in);
      if (e.count > budget / 2 + 1) {
        parse_fail(source, "header/count mismatch: " + std::to_string(e.count) + " vertices cannot fit in " +
                               std::to_string(budget) + " bytes");
      }
      cloud.points.reserve(static_cast<std::size_t>(e.count));
    }
    for (std::uint64_t i = 0; i < e.count; ++i) {
      Eigen::Vector3f p = Eigen::Vector3f::Zero();
      for (std::size_t k = 0; k < e.props.size(); ++k) {
        const PlyProperty& prop = e.props[k];
        const std::string where = "element '" + e.name + "' " + std::to_string(i) + " property '" + prop.name + "'";
        if (prop.is_list) {
          const double n = next_number(where);
          if (!(n >= 0) || n > 1e6) parse_fail(source, "PLY " + where + ": bad list length");
          for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) next_number(where);
        } else {
          const double v = next_number(where);
          if (is_vertex) {
            for (int a = 0; a < 3; ++a) {
              if (h.xyz[static_cast<std::size_t>(a)] == k) p[a] = static_cast<float>(v);
            }
          }
        }
      }
      if (is_vertex) cloud.points.push_back(p);
    }
  }
}

void read_binary(std::istream& in, std::string_view source, const PlyHeader& h, PointCloud& cloud) {
  const bool swap = (h.format == PlyEncoding::BinaryBigEndian) != (std::endian::native == std::endian::big);
  std::vector<std::uint8_t> buf;
  auto read_exact = [&](std::uint8_t* dst, std::size_t n, const std::string& where) {
    in.read(reinterpret_cast<char*>(dst), static_cast<std::streamsize>(n));
    if (static_cast<std::size_t>(in.gcount()) != n) parse_fail(source, "truncated binary PLY data in " + where);
  };
  for (std::size_t ei = 0; ei <= h.vertex; ++ei) {
    const PlyElement& e = h.elements[ei];
    const bool is_vertex = ei == h.vertex;
    const std::uint64_t budget = detail::remaining_bytes(in);
    const std::size_t min_size = e.has_list ? std::max<std::size_t>(1, e.props.size()) : e.record_size;
    if (min_size > 0 && e.count > budget / min_size) {
      parse_fail(source, "truncated binary PLY data: " + std::to_string(e.count) + " '" + e.name +
                             "' elements need more than the " + std::to_string(budget) + " bytes left");
    }
    if (is_vertex) cloud.points.resize(static_cast<std::size_t>(e.count));
    if (!e.has_list) {
      constexpr std::size_t kChunk = 1 << 14;
      buf.resize(kChunk * e.record_size);
      for (std::uint64_t start = 0; start < e.count; start += kChunk) {
        const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, e.count - start));
        read_exact(buf.data(), n * e.record_size, "element '" + e.name + "'");
        if (!is_vertex) continue;
        for (std::size_t i = 0; i < n; ++i) {
          const std::uint8_t* rec = buf.data() + i * e.record_size;
          auto& p = cloud.points[static_cast<std::size_t>(start) + i];
          for (int a = 0; a < 3; ++a) {
            const PlyProperty& prop = e.props[h.xyz[static_cast<std::size_t>(a)]];
            p[a] = static_cast<float>(decode(rec + prop.offset, prop.type, swap));
          }
        }
      }
      continue;
    }
    std::uint8_t item[8];
    for (std::uint64_t i = 0; i < e.count; ++i) {
      for (std::size_t k = 0; k < e.props.size(); ++k) {
        const PlyProperty& prop = e.props[k];
        const std::string where = "element '" + e.name + "'";
        if (prop.is_list) {
          read_exact(item, type_size(prop.count_type), where);
          const double n = decode(item, prop.count_type, swap);
          if (!(n >= 0)) parse_fail(source, "PLY " + where + ": negative list length");
          // Checked against the bytes left before allocating: a corrupt
          // length must not ask for gigabytes (found by fuzz_ply).
          const double left = static_cast<double>(detail::remaining_bytes(in));
          if (n * static_cast<double>(type_size(prop.type)) > left) {
            const std::string items = n < 1e18 ? std::to_string(static_cast<std::uint64_t>(n)) : std::to_string(n);
            parse_fail(source, "truncated binary PLY data: a list of " + items + " items in " + where +
                                   " needs more than the " + std::to_string(static_cast<std::uint64_t>(left)) +
                                   " bytes left");
          }
          const std::size_t bytes = static_cast<std::size_t>(n) * type_size(prop.type);
          buf.resize(bytes);
          read_exact(buf.data(), bytes, where);
        } else {
          read_exact(item, type_size(prop.type), where);
          if (is_vertex) {
            for (int a = 0; a < 3; ++a) {
              if (h.xyz[static_cast<std::size_t>(a)] == k) {
                cloud.points[static_cast<std::size_t>(i)][a] = static_cast<float>(decode(item, prop.type, swap));
              }
            }
          }
        }
      }
    }
  }
}

}  // namespace

PointCloud read_ply_cloud(std::istream& in, std::string_view source) {
  const PlyHeader h = read_header(in, source);
  PointCloud cloud;
  if (h.format == PlyEncoding::Ascii) {
    read_ascii(in, source, h, cloud);
  } else {
    read_binary(in, source, h, cloud);
  }
  cloud.mark_unorganized();
  return cloud;
}

void write_ply_cloud(const PointCloud& cloud, std::ostream& out, PlyEncoding encoding) {
  out << "ply\nformat " << to_string(encoding) << " 1.0\ncomment written by touchdown\n"
      << "element vertex " << cloud.size() << "\n"
      << "property float x\nproperty float y\nproperty float z\nend_header\n";
  if (encoding == PlyEncoding::Ascii) {
    write_xyz(cloud, out);  // an ASCII vertex line is an XYZ line: "x y z"
    return;
  }
  const bool swap = (encoding == PlyEncoding::BinaryBigEndian) != (std::endian::native == std::endian::big);
  std::vector<std::uint8_t> buf;
  constexpr std::size_t kChunk = 1 << 14;
  for (std::size_t start = 0; start < cloud.size(); start += kChunk) {
    const std::size_t n = std::min(kChunk, cloud.size() - start);
    buf.resize(n * 12);
    std::memcpy(buf.data(), cloud.points[start].data(), n * 12);
    if (swap) {
      for (std::size_t i = 0; i < n * 3; ++i) std::reverse(buf.data() + 4 * i, buf.data() + 4 * i + 4);
    }
    out.write(reinterpret_cast<const char*>(buf.data()), static_cast<std::streamsize>(buf.size()));
  }
}

}  // namespace touchdown
