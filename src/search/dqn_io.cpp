// The DQN weights file (dqn.hpp; docs/formats.md "DQN weights file").
#include <cmath>
#include <string>
#include <vector>

#include "core/format.hpp"
#include "core/io_util.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/search/dqn.hpp"

namespace touchdown::search {

std::string weights_text(const QNetwork& net) {
  std::string out;
  out.reserve(static_cast<std::size_t>(net.parameter_count()) * 24 + 96);
  out += std::string(kDqnWeightsFormat) + " " + std::to_string(kDqnWeightsVersion) + "\n";
  out += "hidden " + std::to_string(net.hidden()) + "\n";
  out += "parameters " + std::to_string(net.parameter_count()) + "\n";
  for (const double p : net.parameter_view()) {
    out += detail::format_exact(p);
    out += '\n';
  }
  out += "end\n";
  return out;
}

namespace {

// The text's lines, one at a time, with their 1-based numbers.
class Lines {
 public:
  Lines(std::string_view text, std::string_view source) : text_(text), source_(source) {}
  /// The next line (a trailing '\r' dropped); false at the end of the text.
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    auto e = text_.find('\n', pos_);
    if (e == std::string_view::npos) e = text_.size();
    line = text_.substr(pos_, e - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = e + 1;
    ++number_;
    return true;
  }
  [[noreturn]] void fail(const std::string& what) const { detail::parse_fail_line(source_, number_, what); }
  [[noreturn]] void fail_end(const std::string& what) const { detail::parse_fail(source_, what); }
  /// "key value" on the next line; the value's text.
  std::string_view keyed(std::string_view key) {
    std::string_view line;
    if (!next(line)) fail_end("truncated: missing the '" + std::string(key) + "' line");
    std::vector<std::string_view> tok;
    detail::split(line, tok);
    if (tok.size() != 2 || tok[0] != key) fail("expected '" + std::string(key) + " <integer>'");
    return tok[1];
  }

 private:
  std::string_view text_, source_;
  std::size_t pos_ = 0;
  std::size_t number_ = 0;
};

}  // namespace

QNetwork parse_weights(std::string_view text, std::string_view source) {
  Lines lines(text, source);
  std::string_view line;
  const std::string header = std::string(kDqnWeightsFormat) + " <version>";
  if (!lines.next(line)) lines.fail_end("empty: not a DQN weights file (expected '" + header + "')");
  std::vector<std::string_view> tok;
  detail::split(line, tok);
  if (tok.size() != 2 || tok[0] != kDqnWeightsFormat) lines.fail("not a DQN weights file (expected '" + header + "')");
  int version = 0;
  if (!detail::parse_int(tok[1], version)) lines.fail("version: not an integer");
  if (version != kDqnWeightsVersion)
    lines.fail("version " + std::to_string(version) + " not supported (this build reads version " +
               std::to_string(kDqnWeightsVersion) + ")");
  int hidden = 0;
  if (!detail::parse_int(lines.keyed("hidden"), hidden) || hidden < 1 || hidden > kDqnMaxHidden)
    lines.fail("hidden: must be an integer in 1.." + std::to_string(kDqnMaxHidden));
  const int expected = QNetwork::parameter_count(hidden);
  long count = 0;
  if (!detail::parse_int(lines.keyed("parameters"), count) || count < 0)
    lines.fail("parameters: not a non-negative integer");
  if (count != expected)
    lines.fail("parameters: " + std::to_string(count) + " given, a network with hidden " + std::to_string(hidden) +
               " has " + std::to_string(expected));
  std::vector<double> params;
  params.reserve(static_cast<std::size_t>(expected));
  while (static_cast<int>(params.size()) < expected) {
    if (!lines.next(line))
      lines.fail_end("truncated: " + std::to_string(params.size()) + " of " + std::to_string(expected) +
                     " parameters, no 'end' line");
    double v = 0;
    const std::string_view t = detail::trim(line);
    if (t == "end")
      lines.fail("'end' after " + std::to_string(params.size()) + " of " + std::to_string(expected) + " parameters");
    if (!detail::parse_double(t, v)) lines.fail("parameter " + std::to_string(params.size()) + ": not a number");
    if (!std::isfinite(v)) lines.fail("parameter " + std::to_string(params.size()) + ": not finite");
    params.push_back(v);
  }
  if (!lines.next(line)) lines.fail_end("truncated: no 'end' line after the parameters");
  if (detail::trim(line) != "end") lines.fail("expected 'end' after " + std::to_string(expected) + " parameters");
  while (lines.next(line))
    if (!detail::trim(line).empty()) lines.fail("content after the 'end' line");
  QNetwork net(hidden);
  net.set_parameters(params);
  return net;
}

void save_weights(const QNetwork& net, const std::filesystem::path& path) {
  const std::string text = weights_text(net);
  write_file_atomically(path,
                        [&](const std::filesystem::path& tmp) { detail::write_text_file(tmp, text, path.string()); });
}

QNetwork load_weights(const std::filesystem::path& path) {
  return parse_weights(detail::read_text_file(path), path.string());
}

}  // namespace touchdown::search
