// touchdown's system protocol, version 1 (system_protocol.hpp,
// docs/formats.md "System protocol"). JSON through nlohmann-json: doubles
// are written with the shortest text that reads back to the same bits, so
// a system in another process sees exactly what one in the host would.
#include "touchdown/scenario/system_protocol.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/json_read.hpp"
#include "scenario/fd_wait.hpp"
#include "touchdown/scenario/process_system.hpp"

namespace touchdown::scenario::protocol {

namespace {

using Json = nlohmann::json;

[[noreturn]] void fail(const std::string& what) { throw ProtocolError(what); }

Json parse_json(std::string_view text, const char* what) {
  if (text.size() > kMaxJsonPayload) fail(std::string(what) + ": JSON payload over 16 MiB");
  Json j = Json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded()) fail(std::string(what) + ": not JSON");
  if (!j.is_object()) fail(std::string(what) + ": not a JSON object");
  return j;
}

void only_keys(const Json& j, const char* what, std::initializer_list<const char*> keys) {
  for (const auto& item : j.items()) {
    bool known = false;
    for (const char* k : keys) known = known || item.key() == k;
    if (!known) fail(std::string(what) + ": unknown key '" + item.key() + "'");
  }
}

int integer(const Json& j, const std::string& key) {
  const std::optional<int> i = touchdown::detail::json_int(j);
  if (!i) fail(key + ": " + touchdown::detail::json_int_problem(j));
  return *i;
}

double number(const Json& j, const std::string& key) {
  if (!j.is_number()) fail(key + ": not a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) fail(key + ": not finite");
  return v;
}

bool boolean(const Json& j, const std::string& key) {
  if (!j.is_boolean()) fail(key + ": not true or false");
  return j.get<bool>();
}

template <int N>
Eigen::Matrix<double, N, 1> vec(const Json& j, const std::string& key) {
  if (!j.is_array() || j.size() != static_cast<std::size_t>(N)) {
    fail(key + ": not an array of " + std::to_string(N) + " numbers");
  }
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) v(i) = number(j[static_cast<std::size_t>(i)], key);
  return v;
}

template <class Derived>
Json array(const Eigen::MatrixBase<Derived>& v) {
  Json a = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

std::string dump(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace); }

}  // namespace

Header parse_header(std::string_view line) {
  Header h;
  const auto printable = [](char c) { return c >= 0x20 && c < 0x7f; };
  for (const char c : line) {
    if (!printable(c)) fail("header: not printable ASCII");
  }
  std::size_t i = 0;
  const auto word = [&] {
    while (i < line.size() && line[i] == ' ') ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ') ++i;
    return line.substr(start, i - start);
  };
  const std::string_view verb = word();
  if (verb.empty()) fail("header: empty");
  for (const char c : verb) {
    if (!((c >= 'a' && c <= 'z') || c == '-')) fail("header: '" + std::string(line.substr(0, 40)) + "' has no verb");
  }
  h.verb = std::string(verb);
  for (std::string_view w = word(); !w.empty(); w = word()) {
    std::size_t n = 0;
    const auto r = std::from_chars(w.data(), w.data() + w.size(), n);
    if (r.ec != std::errc() || r.ptr != w.data() + w.size()) {
      fail("header '" + h.verb + "': '" + std::string(w.substr(0, 20)) + "' is not a byte count");
    }
    if (n > kMaxPayload) fail("header '" + h.verb + "': a payload of " + std::to_string(n) + " bytes (over 256 MiB)");
    h.sizes.push_back(n);
  }
  return h;
}

std::string header(std::string_view verb, const std::vector<std::size_t>& sizes) {
  std::string s(verb);
  for (const std::size_t n : sizes) s += " " + std::to_string(n);
  return s + "\n";
}

Hello parse_hello(const Header& h, std::string_view json) {
  if (h.verb != "touchdown-system") fail("hello: expected 'touchdown-system', got '" + h.verb + "'");
  if (h.sizes.size() != 2) fail("hello: expected 'touchdown-system VERSION JSON_BYTES'");
  Hello hello;
  hello.version = static_cast<int>(std::min<std::size_t>(h.sizes[0], 1000000));
  if (hello.version != kSystemProtocolVersion) {
    fail("hello: the system speaks protocol version " + std::to_string(h.sizes[0]) + ", the host version " +
         std::to_string(kSystemProtocolVersion));
  }
  const Json j = parse_json(json, "hello");
  only_keys(j, "hello", {"name", "wants"});
  if (!j.contains("name") || !j["name"].is_string() || j["name"].get<std::string>().empty()) {
    fail("hello: name: missing or not a non-empty string");
  }
  hello.name = j["name"].get<std::string>();
  hello.image = hello.depth = hello.mask = false;
  if (j.contains("wants")) {
    if (!j["wants"].is_array()) fail("hello: wants: not an array");
    for (const Json& w : j["wants"]) {
      const std::string s = w.is_string() ? w.get<std::string>() : "";
      if (s == "image") {
        hello.image = true;
      } else if (s == "depth") {
        hello.depth = true;
      } else if (s == "mask") {
        hello.mask = true;
      } else {
        fail("hello: wants: '" + s + "' is not image, depth or mask");
      }
    }
  }
  return hello;
}

std::string hello_json(const Hello& hello) {
  Json wants = Json::array();
  if (hello.image) wants.push_back("image");
  if (hello.depth) wants.push_back("depth");
  if (hello.mask) wants.push_back("mask");
  return dump(Json{{"name", hello.name}, {"wants", wants}});
}

std::string setup_json(const SystemSetup& s) {
  const CameraOptions& c = s.camera;
  Json T = Json::array();
  const Eigen::Matrix4d m = c.T_body_camera().matrix();
  for (int r = 0; r < 4; ++r) T.push_back(array(m.row(r).transpose()));
  Json camera{{"width", c.width},           {"height", c.height},
              {"hfov_deg", c.hfov_deg},     {"fx", c.fx()},
              {"tilt_deg", c.tilt_deg},     {"rate_hz", c.rate_hz},
              {"exposure_s", c.exposure_s}, {"offset_body", array(c.offset_body)},
              {"T_body_camera", T}};
  return dump(Json{{"camera", camera},
                   {"dictionary", s.dictionary},
                   {"marker_id", s.marker_id},
                   {"marker_size", s.marker_size},
                   {"gps_target", array(s.gps_target)},
                   {"drone_radius", s.drone_radius}});
}

SystemSetup parse_setup(std::string_view json) {
  const Json j = parse_json(json, "setup");
  SystemSetup s;
  try {
    const Json& c = j.at("camera");
    s.camera.width = integer(c.at("width"), "setup: camera.width");
    s.camera.height = integer(c.at("height"), "setup: camera.height");
    s.camera.hfov_deg = c.at("hfov_deg").get<double>();
    s.camera.tilt_deg = c.at("tilt_deg").get<double>();
    s.camera.rate_hz = c.at("rate_hz").get<double>();
    s.camera.exposure_s = c.at("exposure_s").get<double>();
    s.camera.offset_body = vec<3>(c.at("offset_body"), "camera.offset_body");
    s.dictionary = j.at("dictionary").get<std::string>();
    s.marker_id = integer(j.at("marker_id"), "setup: marker_id");
    s.marker_size = j.at("marker_size").get<double>();
    s.gps_target = vec<2>(j.at("gps_target"), "gps_target");
    s.drone_radius = j.at("drone_radius").get<double>();
  } catch (const Json::exception& e) {
    fail(std::string("setup: ") + e.what());
  }
  return s;
}

std::string state_json(const SystemInput& in) {
  const DroneState& d = in.state;
  Json T = Json::array();
  const Eigen::Matrix4d m = d.T_world_body().matrix();
  for (int r = 0; r < 4; ++r) T.push_back(array(m.row(r).transpose()));
  Json j{{"t", d.t},
         {"position", array(d.position)},
         {"velocity", array(d.velocity)},
         {"acceleration", array(d.acceleration)},
         {"yaw_deg", d.yaw_deg},
         {"T_world_body", T},
         {"land_mode", d.land_mode},
         {"on_ground", d.on_ground},
         {"landed", d.landed}};
  j["frame"] = in.frame != nullptr ? Json{{"width", in.frame->width}, {"height", in.frame->height}} : Json(nullptr);
  return dump(j);
}

StepState parse_state(std::string_view json) {
  const Json j = parse_json(json, "state");
  StepState s;
  try {
    s.state.t = number(j.at("t"), "t");
    s.state.position = vec<3>(j.at("position"), "position");
    s.state.velocity = vec<3>(j.at("velocity"), "velocity");
    s.state.acceleration = vec<3>(j.at("acceleration"), "acceleration");
    s.state.yaw_deg = number(j.at("yaw_deg"), "yaw_deg");
    const Json& T = j.at("T_world_body");
    if (!T.is_array() || T.size() != 4) fail("state: T_world_body: expected 4 rows");
    for (int r = 0; r < 3; ++r) {
      s.state.R_world_body.row(r) = vec<4>(T[static_cast<std::size_t>(r)], "T_world_body").head<3>().transpose();
    }
    s.state.land_mode = boolean(j.at("land_mode"), "land_mode");
    s.state.on_ground = boolean(j.at("on_ground"), "on_ground");
    s.state.landed = boolean(j.at("landed"), "landed");
    const Json& f = j.at("frame");
    if (!f.is_null()) {
      s.frame = true;
      s.width = integer(f.at("width"), "state: frame.width");
      s.height = integer(f.at("height"), "state: frame.height");
    }
  } catch (const Json::exception& e) {
    fail(std::string("state: ") + e.what());
  }
  return s;
}

SystemOutput parse_output(std::string_view json, std::string& phase) {
  const Json j = parse_json(json, "command");
  only_keys(j, "command", {"velocity", "yaw_rate_deg", "land", "phase", "descent_started", "target", "detections"});
  SystemOutput out;
  if (!j.contains("velocity")) fail("command: velocity: missing");
  out.command.velocity_world = vec<3>(j["velocity"], "command: velocity");
  if (j.contains("yaw_rate_deg")) out.command.yaw_rate_deg = number(j["yaw_rate_deg"], "command: yaw_rate_deg");
  if (j.contains("land")) out.command.land = boolean(j["land"], "command: land");
  phase.clear();
  if (j.contains("phase")) {
    if (!j["phase"].is_string()) fail("command: phase: not a string");
    phase = j["phase"].get<std::string>();
    if (phase.size() > 64) fail("command: phase: over 64 characters");
  }
  out.phase = phase;
  if (j.contains("descent_started")) out.descent_started = boolean(j["descent_started"], "command: descent_started");
  if (j.contains("target")) out.target = vec<2>(j["target"], "command: target");
  if (j.contains("detections")) {
    const Json& ds = j["detections"];
    if (!ds.is_array()) fail("command: detections: not an array");
    if (ds.size() > 1000) fail("command: detections: over 1000");
    for (std::size_t k = 0; k < ds.size(); ++k) {
      const Json& d = ds[k];
      const std::string key = "command: detections[" + std::to_string(k) + "]";
      if (!d.is_object()) fail(key + ": not an object");
      only_keys(d, key.c_str(), {"id", "corners", "quality", "confidence", "accepted", "ground"});
      Detection r;
      if (d.contains("id")) {
        r.id = integer(d["id"], key + ".id");
      }
      if (!d.contains("corners") || !d["corners"].is_array() || d["corners"].size() != 4) {
        fail(key + ".corners: not four [u, v] pairs");
      }
      for (std::size_t c = 0; c < 4; ++c) r.corners[c] = vec<2>(d["corners"][c], key + ".corners");
      if (d.contains("quality")) r.quality = number(d["quality"], key + ".quality");
      if (d.contains("confidence")) r.confidence = number(d["confidence"], key + ".confidence");
      if (d.contains("accepted")) r.accepted = boolean(d["accepted"], key + ".accepted");
      if (d.contains("ground")) r.ground = vec<2>(d["ground"], key + ".ground");
      out.detections.push_back(r);
    }
  }
  return out;
}

std::string output_json(const SystemOutput& o) {
  Json detections = Json::array();
  for (const Detection& d : o.detections) {
    Json corners = Json::array();
    for (const Eigen::Vector2d& c : d.corners) corners.push_back(array(c));
    detections.push_back(Json{{"id", d.id},
                              {"corners", corners},
                              {"quality", d.quality},
                              {"confidence", d.confidence},
                              {"accepted", d.accepted},
                              {"ground", array(d.ground)}});
  }
  return dump(Json{{"velocity", array(o.command.velocity_world)},
                   {"yaw_rate_deg", o.command.yaw_rate_deg},
                   {"land", o.command.land},
                   {"phase", std::string(o.phase)},
                   {"descent_started", o.descent_started},
                   {"target", array(o.target)},
                   {"detections", detections}});
}

// ---- serve_system: the system's side -------------------------------------------------

namespace {

// Buffered reads and unbuffered writes on file descriptors. A read that
// finds nothing looks again a while (yielding the core) before it sleeps
// in poll(): the host's next message usually comes within microseconds,
// and a wake-up from poll() costs as much again.
class Channel {
 public:
  Channel(int in, int out) : in_(in), out_(out) {}

  // False at the end of the input.
  bool line(std::string& text) {
    for (;;) {
      if (const auto eol = buffer_.find('\n', 0); eol != std::string::npos) {
        text.assign(buffer_, 0, eol);
        buffer_.erase(0, eol + 1);
        return true;
      }
      if (buffer_.size() >= kMaxHeader) fail("header: over 256 bytes");
      if (!more()) return false;
    }
  }

  void exact(void* data, std::size_t n) {
    auto* p = static_cast<char*>(data);
    const std::size_t from_buffer = std::min(n, buffer_.size());
    if (from_buffer > 0) std::memcpy(p, buffer_.data(), from_buffer);  // p may be null when n == 0
    buffer_.erase(0, from_buffer);
    for (std::size_t done = from_buffer; done < n;) {
      wait();
      const ssize_t k = ::read(in_, p + done, n - done);
      if (k == 0) fail("payload: cut short");
      if (k < 0 && errno != EINTR && errno != EAGAIN) fail(std::string("read: ") + std::strerror(errno));
      if (k > 0) done += static_cast<std::size_t>(k);
    }
  }

  std::string exact(std::size_t n) {
    std::string s(n, '\0');
    exact(s.data(), n);
    return s;
  }

  void write(std::string_view bytes) {
    for (std::size_t done = 0; done < bytes.size();) {
      const ssize_t k = ::write(out_, bytes.data() + done, bytes.size() - done);
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) fail(std::string("write: ") + std::strerror(errno));
      done += static_cast<std::size_t>(k);
    }
  }

  void send(std::string_view verb, const std::string& payload) { write(header(verb, {payload.size()}) + payload); }

 private:
  void wait() { (void)detail::wait_fd(in_, POLLIN, 200, -1); }

  bool more() {
    char chunk[65536];
    for (;;) {
      wait();
      const ssize_t k = ::read(in_, chunk, sizeof chunk);
      if (k > 0) {
        buffer_.append(chunk, static_cast<std::size_t>(k));
        return true;
      }
      if (k == 0) return false;
      if (errno != EINTR && errno != EAGAIN) fail(std::string("read: ") + std::strerror(errno));
    }
  }

  int in_, out_;
  std::string buffer_;
};

Header read_header(Channel& c) {
  std::string line;
  if (!c.line(line)) return Header{};  // the end: like bye
  return parse_header(line);
}

}  // namespace

int serve_system(LandingSystem& system, const Hello& wanted, int in_fd, int out_fd) {
  Channel c(in_fd, out_fd);
  try {
    const Header first = read_header(c);
    if (first.verb != "touchdown-system" || first.sizes.size() != 1 || first.sizes[0] != 1) {
      fail("hello: expected 'touchdown-system 1'");
    }
    Hello hello = wanted;
    hello.name = std::string(system.name());
    const std::string hj = hello_json(hello);
    c.write(header("touchdown-system", {static_cast<std::size_t>(kSystemProtocolVersion), hj.size()}) + hj);
    CameraFrame frame;
    for (;;) {
      const Header h = read_header(c);
      if (h.verb.empty() || h.verb == "bye") return 0;
      if (h.verb == "reset") {
        if (h.sizes.size() != 1) fail("reset: expected one payload");
        const SystemSetup setup = parse_setup(c.exact(h.sizes[0]));
        try {
          system.reset(setup);
          c.write(header("ready"));
        } catch (const std::exception& e) {
          c.send("error", std::string("reset() threw: ") + e.what());
        }
      } else if (h.verb == "step") {
        if (h.sizes.size() != 4) fail("step: expected four payloads");
        const StepState s = parse_state(c.exact(h.sizes[0]));
        SystemInput input;
        input.state = s.state;
        // The frame's payloads straight into its buffers.
        const std::size_t pixels = s.frame ? static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height) : 0;
        const auto sized = [&](std::size_t got, std::size_t want, const char* what) {
          if (got != 0 && got != want) {
            fail(std::string("step: the ") + what + " has " + std::to_string(got) + " bytes, the frame needs " +
                 std::to_string(want));
          }
        };
        sized(h.sizes[1], pixels * 3, "image");
        sized(h.sizes[2], pixels, "mask");
        sized(h.sizes[3], pixels * sizeof(float), "depth");
        frame.width = s.width;
        frame.height = s.height;
        frame.image.resize(h.sizes[1] > 0 ? s.width : 0, h.sizes[1] > 0 ? s.height : 0);
        c.exact(frame.image.pixels.data(), h.sizes[1]);
        frame.mask.resize(h.sizes[2]);
        c.exact(frame.mask.data(), h.sizes[2]);
        frame.depth.resize(h.sizes[3] / sizeof(float));
        c.exact(frame.depth.data(), h.sizes[3]);
        if (s.frame) input.frame = &frame;
        std::string answer;
        try {
          answer = output_json(system.update(input));
        } catch (const std::exception& e) {
          c.send("error", e.what());
          continue;
        }
        c.send("command", answer);
      } else {
        fail("unknown verb '" + h.verb + "'");
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "serve_system: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace touchdown::scenario::protocol
