// XYZ/CSV text clouds: one point per line, `x y z` or `x,y,z` (further numeric
// columns ignored), `#` starts a comment.
#include <cmath>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

#include "format.hpp"
#include "io_util.hpp"
#include "touchdown/core/cloud_io.hpp"

namespace touchdown {

PointCloud read_xyz(std::istream& in, std::string_view source) {
  PointCloud cloud;
  std::string line;
  std::vector<std::string_view> tok;
  std::size_t line_no = 0;
  while (detail::read_line(in, line)) {
    ++line_no;
    std::string_view body(line);
    body = body.substr(0, body.find('#'));
    detail::split(body, tok, " \t\r\v\f,;");
    if (tok.empty()) continue;
    if (line_no == 1 && line.find('\0') != std::string::npos)
      detail::parse_fail(source, "not a text point cloud (binary content)");
    if (tok.size() < 3) {
      detail::parse_fail_line(source, line_no, "expected 3 numbers (x y z), found " + std::to_string(tok.size()));
    }
    Eigen::Vector3f p;
    for (std::size_t a = 0; a < tok.size(); ++a) {
      double v;
      if (!detail::parse_double(tok[a], v)) {
        detail::parse_fail_line(source, line_no, "'" + std::string(tok[a]) + "' is not a number");
      }
      if (a < 3) p[static_cast<int>(a)] = static_cast<float>(v);
    }
    cloud.points.push_back(p);
  }
  if (in.bad()) throw IoError(std::string(source) + ": read error");
  cloud.mark_unorganized();
  return cloud;
}

void write_xyz(const PointCloud& cloud, std::ostream& out) {
  char buf[32];
  std::string line;
  for (const auto& p : cloud.points) {
    line.clear();
    for (int a = 0; a < 3; ++a) {
      if (a) line += ' ';
      line += std::isnan(p[a]) ? std::string_view("nan") : detail::format_exact(p[a], buf);
    }
    line += '\n';
    out << line;
  }
}

}  // namespace touchdown
