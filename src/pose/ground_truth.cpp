// ground_truth.jsonl: writer and a strict hand-written JSON Lines reader.
#include "touchdown/pose/ground_truth.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <iterator>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/format.hpp"
#include "core/io_util.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::pose {

namespace fs = std::filesystem;

std::string ground_truth_to_json(const GroundTruthSample& s) {
  using detail::format_exact;
  Eigen::Quaterniond q(s.T_camera_body.rotation());
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d t = s.T_camera_body.translation();
  std::string out = "{\"frame\":\"";
  for (char c : s.frame) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      static const char kHex[] = "0123456789abcdef";
      out += "\\u00";
      out += kHex[(static_cast<unsigned char>(c) >> 4) & 0xF];
      out += kHex[static_cast<unsigned char>(c) & 0xF];
    } else {
      out += c;
    }
  }
  out += "\",\"t_s\":" + format_exact(s.t_s);
  out += ",\"t\":[" + format_exact(t.x()) + "," + format_exact(t.y()) + "," + format_exact(t.z()) + "]";
  out += ",\"q\":[" + format_exact(q.w()) + "," + format_exact(q.x()) + "," + format_exact(q.y()) + "," +
         format_exact(q.z()) + "]";
  out += ",\"leds_visible\":[";
  for (std::size_t i = 0; i < s.leds_visible.size(); ++i)
    out += (i ? "," : "") + std::string(s.leds_visible[i] ? "true" : "false");
  out += "],\"marker_visible\":";
  out += s.marker_visible ? "true" : "false";
  out += "}";
  return out;
}

namespace {
// How far from 1 a gravity direction's norm may be: printed unit vectors
// with 6 or more digits are well within it.
constexpr double kAttitudeUnitTolerance = 1e-3;

// A small strict JSON reader (RFC 8259) for one ground-truth line: an object
// whose values are strings, numbers, booleans, null, arrays and nested
// objects (the latter only skipped). Nesting is bounded so that hostile
// input cannot exhaust the stack.
class LineParser {
 public:
  LineParser(std::string_view text, std::string_view source, std::size_t line)
      : s_(text), source_(source), line_(line) {}

  GroundTruthSample parse() {
    GroundTruthSample out;
    double tq[7] = {};
    parse_object(
        {{"frame", true}, {"t_s", true}, {"t", true}, {"q", true}, {"leds_visible", false}, {"marker_visible", false}},
        [&](const std::string& key) {
          if (key == "frame") {
            parse_frame(out.frame);
          } else if (key == "t_s") {
            out.t_s = parse_number(key);
          } else if (key == "t") {
            parse_number_array(key, tq, 3);
          } else if (key == "q") {
            parse_number_array(key, tq + 3, 4);
          } else if (key == "leds_visible") {
            parse_bool_array(key, out.leds_visible);
          } else {
            out.marker_visible = parse_bool(key);
          }
        });
    Eigen::Quaterniond q(tq[3], tq[4], tq[5], tq[6]);
    const double n = q.norm();
    if (!(std::abs(n - 1) <= 1e-6)) fail("q: not a unit quaternion (norm " + detail::format_exact(n) + ")");
    q.coeffs() /= n;
    out.T_camera_body = Eigen::Isometry3d::Identity();
    out.T_camera_body.linear() = q.toRotationMatrix();
    out.T_camera_body.translation() = Eigen::Vector3d(tq[0], tq[1], tq[2]);
    return out;
  }

  // One attitude line (ground_truth.hpp): the same strict reader.
  AttitudeSample parse_attitude() {
    AttitudeSample out;
    double g[6] = {};
    parse_object({{"frame", true}, {"t_s", true}, {"g_camera", true}, {"g_body", true}, {"sigma_deg", true}},
                 [&](const std::string& key) {
                   if (key == "frame") {
                     parse_frame(out.frame);
                   } else if (key == "t_s") {
                     out.t_s = parse_number(key);
                   } else if (key == "g_camera") {
                     parse_number_array(key, g, 3);
                   } else if (key == "g_body") {
                     parse_number_array(key, g + 3, 3);
                   } else {
                     out.sigma_deg = parse_number(key);
                   }
                 });
    out.g_camera = Eigen::Vector3d(g[0], g[1], g[2]);
    out.g_body = Eigen::Vector3d(g[3], g[4], g[5]);
    for (const auto& [name, v] : {std::pair{"g_camera", out.g_camera}, std::pair{"g_body", out.g_body}}) {
      const double n = v.norm();
      if (!(std::abs(n - 1) <= kAttitudeUnitTolerance)) {
        fail(std::string(name) + ": not a unit vector (norm " + detail::format_exact(n) + ")");
      }
    }
    if (!(out.sigma_deg > 0 && out.sigma_deg <= 90)) {
      fail("sigma_deg: must be in (0, 90] (got " + detail::format_exact(out.sigma_deg) + ")");
    }
    out.g_camera.normalize();
    out.g_body.normalize();
    return out;
  }

 private:
  struct Key {
    std::string_view name;
    bool required;
  };

  // The whole line as one object: each known key (given once at most) is
  // handed to on_key, which parses its value; unknown keys are skipped; then
  // the required keys are checked in the order given. Nothing may follow.
  template <class OnKey>
  void parse_object(std::initializer_list<Key> known, OnKey&& on_key) {
    std::vector<bool> seen(known.size(), false);
    skip_ws();
    expect('{', "expected a JSON object");
    skip_ws();
    if (peek() == '}') fail("missing key \"" + std::string(known.begin()->name) + "\"");
    std::string key;
    for (;;) {
      skip_ws();
      parse_string(key);
      skip_ws();
      expect(':', "expected ':' after a key");
      skip_ws();
      const auto it = std::find_if(known.begin(), known.end(), [&](const Key& k) { return k.name == key; });
      if (it == known.end()) {
        skip_value(0);
      } else {
        const auto index = static_cast<std::size_t>(it - known.begin());
        if (seen[index]) fail("duplicate key \"" + key + "\"");
        seen[index] = true;
        on_key(key);
      }
      skip_ws();
      if (peek() == ',') {
        ++i_;
        continue;
      }
      expect('}', "expected ',' or '}' in the object");
      break;
    }
    skip_ws();
    if (i_ != s_.size()) fail("unexpected text after the JSON object");
    std::size_t index = 0;
    for (const Key& k : known) {
      if (k.required && !seen[index]) fail("missing key \"" + std::string(k.name) + "\"");
      ++index;
    }
  }
  void parse_frame(std::string& frame) {
    if (peek() != '"') fail("frame: expected a string");
    parse_string(frame);
  }
  void parse_bool_array(const std::string& key, std::vector<bool>& out) {
    expect('[', (key + ": expected an array of booleans").c_str());
    skip_ws();
    if (peek() != ']') {
      for (;;) {
        skip_ws();
        out.push_back(parse_bool(key));
        if (out.size() > 1024) fail(key + ": more than 1024 entries");
        skip_ws();
        if (peek() == ',') {
          ++i_;
          continue;
        }
        break;
      }
    }
    expect(']', (key + ": expected ',' or ']'").c_str());
  }
  [[noreturn]] void fail(const std::string& what) const { detail::parse_fail_line(source_, line_, what); }
  [[nodiscard]] char peek() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  void skip_ws() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\r' || s_[i_] == '\n')) ++i_;
  }
  void expect(char c, const char* what) {
    if (peek() != c || i_ >= s_.size()) fail(what);
    ++i_;
  }
  bool literal(std::string_view word) {
    if (s_.substr(i_, word.size()) != word) return false;
    i_ += word.size();
    return true;
  }
  bool parse_bool(const std::string& key) {
    if (literal("true")) return true;
    if (literal("false")) return false;
    fail(key + ": expected true or false");
  }

  static void append_utf8(std::string& out, std::uint32_t cp) {
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }
  std::uint32_t hex4() {
    if (i_ + 4 > s_.size()) fail("truncated \\u escape");
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = s_[i_++];
      v <<= 4;
      if (c >= '0' && c <= '9') {
        v |= static_cast<std::uint32_t>(c - '0');
      } else if (c >= 'a' && c <= 'f') {
        v |= static_cast<std::uint32_t>(c - 'a' + 10);
      } else if (c >= 'A' && c <= 'F') {
        v |= static_cast<std::uint32_t>(c - 'A' + 10);
      } else {
        fail("bad hex digit in a \\u escape");
      }
    }
    return v;
  }
  void parse_string(std::string& out) {
    out.clear();
    expect('"', "expected a string");
    for (;;) {
      if (i_ >= s_.size()) fail("unterminated string");
      const char c = s_[i_++];
      if (c == '"') return;
      if (static_cast<unsigned char>(c) < 0x20) fail("control character in a string");
      if (c != '\\') {
        out += c;
        continue;
      }
      if (i_ >= s_.size()) fail("unterminated string");
      const char e = s_[i_++];
      switch (e) {
        case '"':
          out += '"';
          break;
        case '\\':
          out += '\\';
          break;
        case '/':
          out += '/';
          break;
        case 'b':
          out += '\b';
          break;
        case 'f':
          out += '\f';
          break;
        case 'n':
          out += '\n';
          break;
        case 'r':
          out += '\r';
          break;
        case 't':
          out += '\t';
          break;
        case 'u': {
          std::uint32_t cp = hex4();
          if (cp >= 0xD800 && cp < 0xDC00) {  // high surrogate: a low one must follow
            if (!literal("\\u")) fail("unpaired surrogate in a \\u escape");
            const std::uint32_t lo = hex4();
            if (lo < 0xDC00 || lo >= 0xE000) fail("unpaired surrogate in a \\u escape");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
          } else if (cp >= 0xDC00 && cp < 0xE000) {
            fail("unpaired surrogate in a \\u escape");
          }
          append_utf8(out, cp);
          break;
        }
        default:
          fail("bad escape in a string");
      }
    }
  }
  // JSON number grammar: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
  double parse_number(const std::string& key) {
    const std::size_t b = i_;
    auto digits = [&] {
      const std::size_t d = i_;
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
      return i_ > d;
    };
    if (peek() == '-') ++i_;
    if (peek() == '0') {
      ++i_;
    } else if (!digits()) {
      fail(key + ": expected a number");
    }
    if (peek() == '.') {
      ++i_;
      if (!digits()) fail(key + ": expected digits after '.'");
    }
    if (peek() == 'e' || peek() == 'E') {
      ++i_;
      if (peek() == '+' || peek() == '-') ++i_;
      if (!digits()) fail(key + ": expected digits in the exponent");
    }
    double v = 0;
    if (!detail::parse_double(s_.substr(b, i_ - b), v) || !std::isfinite(v)) {
      fail(key + ": number out of range");
    }
    return v;
  }
  void parse_number_array(const std::string& key, double* out, int n) {
    expect('[', (key + ": expected an array of " + std::to_string(n) + " numbers").c_str());
    for (int k = 0; k < n; ++k) {
      skip_ws();
      out[k] = parse_number(key);
      skip_ws();
      if (k + 1 < n) expect(',', (key + ": expected " + std::to_string(n) + " numbers").c_str());
    }
    expect(']', (key + ": expected " + std::to_string(n) + " numbers").c_str());
  }
  void skip_value(int depth) {
    if (depth > 32) fail("JSON nested too deeply");
    std::string scratch;
    const char c = peek();
    if (c == '"') {
      parse_string(scratch);
    } else if (c == '{' || c == '[') {
      const char close = c == '{' ? '}' : ']';
      ++i_;
      skip_ws();
      if (peek() == close) {
        ++i_;
        return;
      }
      for (;;) {
        skip_ws();
        if (c == '{') {
          parse_string(scratch);
          skip_ws();
          expect(':', "expected ':' after a key");
          skip_ws();
        }
        skip_value(depth + 1);
        skip_ws();
        if (peek() == ',') {
          ++i_;
          continue;
        }
        expect(close, c == '{' ? "expected ',' or '}' in an object" : "expected ',' or ']' in an array");
        return;
      }
    } else if (literal("true") || literal("false") || literal("null")) {
    } else {
      (void)parse_number("value");
    }
  }

  std::string_view s_;
  std::string_view source_;
  std::size_t line_;
  std::size_t i_ = 0;
};

}  // namespace

std::vector<GroundTruthSample> parse_ground_truth(std::string_view text, std::string_view source) {
  std::vector<GroundTruthSample> out;
  std::size_t line = 0, pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    ++line;
    const std::string_view l = detail::trim(text.substr(pos, end - pos));
    pos = end + 1;
    if (l.empty()) continue;
    out.push_back(LineParser(l, source, line).parse());
  }
  return out;
}

std::vector<GroundTruthSample> read_ground_truth(const fs::path& path) {
  return parse_ground_truth(detail::read_text_file(path), path.string());
}

std::vector<AttitudeSample> parse_attitude(std::string_view text, std::string_view source) {
  std::vector<AttitudeSample> out;
  std::size_t line = 0, pos = 0;
  std::vector<std::pair<std::string, std::size_t>> seen;  // frame, line: duplicates are an error
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    ++line;
    const std::string_view l = detail::trim(text.substr(pos, end - pos));
    pos = end + 1;
    if (l.empty()) continue;
    out.push_back(LineParser(l, source, line).parse_attitude());
    out.back().line = line;
  }
  std::vector<std::size_t> order(out.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return out[a].frame < out[b].frame; });
  for (std::size_t i = 1; i < order.size(); ++i) {
    const AttitudeSample& a = out[order[i - 1]];
    const AttitudeSample& b = out[order[i]];
    if (a.frame == b.frame) {
      detail::parse_fail_line(source, b.line,
                              "frame \"" + b.frame + "\" again (first on line " + std::to_string(a.line) + ")");
    }
  }
  return out;
}

std::vector<AttitudeSample> read_attitude(const fs::path& path) {
  return parse_attitude(detail::read_text_file(path), path.string());
}

}  // namespace touchdown::pose
