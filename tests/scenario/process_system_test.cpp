// A landing system in another process (process_system.hpp) and the system
// protocol (system_protocol.hpp): the same campaign through exec: as in the
// host, bit for bit; every fault a child can have ends its run as "system
// failed" with the reason, and leaves no process behind; the protocol's
// readers refuse what breaks it.
#include "touchdown/scenario/process_system.hpp"

#include <dirent.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "plugins/gps_lander.hpp"
#include "same_campaign.hpp"
#include "touchdown/scenario/campaign.hpp"
#include "touchdown/scenario/run.hpp"
#include "touchdown/scenario/system_protocol.hpp"
#include "touchdown/scenario/system_registry.hpp"
#include "touchdown/scenario/testing/scenarios.hpp"

namespace touchdown::scenario {
namespace {

const std::string kChild = TOUCHDOWN_EXEC_CHILD;

bool mentions(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// This process's living children (zombies count: they were not reaped).
int children() {
  int n = 0;
  DIR* proc = ::opendir("/proc");
  if (proc == nullptr) return -1;
  const std::string me = std::to_string(::getpid());
  while (const dirent* e = ::readdir(proc)) {
    std::ifstream stat(std::string("/proc/") + e->d_name + "/stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    const auto close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    std::string state, ppid;
    rest >> state >> ppid;
    n += ppid == me ? 1 : 0;
  }
  ::closedir(proc);
  return n;
}

TEST(ProcessSystem, ACampaignThroughExecEqualsTheSameCodeInTheHost) {
  std::vector<Scenario> scenarios = random_scenarios(11, 4, MapKind::Ground);
  for (Scenario& s : scenarios) s.time_limit = 30;
  CampaignOptions o;
  o.threads = 2;
  o.system = "exec:" + kChild + " lander";
  const CampaignResult via_exec = run_campaign(scenarios, o);
  o.threads = 1;
  o.system = SystemFactory(
      "in-host", [](const MlsOptions&) { return std::make_unique<test_plugin::GpsLander>("test-gps-lander"); });
  const CampaignResult in_host = run_campaign(scenarios, o);
  EXPECT_GT(test::expect_same_outcomes(via_exec, in_host), 0);  // bit for bit, and the lander does land
  EXPECT_EQ(children(), 0);  // the campaign's systems are gone, and so are their processes
}

struct Fault {
  std::string mode;
  std::string reason;
};

TEST(ProcessSystem, EveryFaultIsSystemFailedWithItsReasonAndLeavesNoProcess) {
  const std::vector<Fault> faults{
      {"exit 40", "the system's process exited with status 3 (while answering step)"},
      {"sleep 40", "no answer from the system within 1.0 s (while it was answering step)"},
      {"garbage 40", "the system answered a malformed header: header: '!!! this is not a header' has no verb"},
      {"truncate 40", "the system's process exited with status 0 (while sending a payload): 11 of 100 bytes came"},
      {"wrong-size 40", "the system answered a bad command: command: not JSON"},
      {"error 40", "the system reported an error: planted error at step 40"},
      {"version", "hello: the system speaks protocol version 2, the host version 1"},
      {"silent", "no answer from the system within 1.0 s (while it was answering hello)"},
  };
  for (const Fault& f : faults) {
    ProcessOptions o;
    o.command = kChild + " " + f.mode;
    o.start_timeout_s = o.step_timeout_s = 1.0;
    auto system = make_process_system(o);
    const auto t0 = std::chrono::steady_clock::now();
    const ScenarioResult r = run_scenario(contract::clear_scenario(20), *system, {});
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 15) << f.mode;
    EXPECT_EQ(r.status, Violation::SystemFailed) << f.mode << ": " << r.message;
    EXPECT_TRUE(mentions(r.failure, f.reason)) << f.mode << ": " << r.failure;
    if (f.mode.find(' ') != std::string::npos) {
      EXPECT_TRUE(mentions(r.failure, "update() threw at t = 0.78 s (step 40)")) << f.mode << ": " << r.failure;
    } else {
      EXPECT_TRUE(mentions(r.failure, "reset() threw: ")) << f.mode << ": " << r.failure;
    }
    EXPECT_EQ(children(), 0) << f.mode;  // the faulty process was killed and reaped at once
    // The next run starts a fresh process (which fails again at step 40).
    if (f.mode == "exit 40") {
      const ScenarioResult again = run_scenario(contract::clear_scenario(20), *system, {});
      EXPECT_TRUE(mentions(again.failure, "(step 40)")) << again.failure;
    }
  }
  EXPECT_EQ(children(), 0);
}

// Processes whose command line contains `tag` (any parent).
int processes_with(const std::string& tag) {
  int n = 0;
  DIR* proc = ::opendir("/proc");
  if (proc == nullptr) return -1;
  while (const dirent* e = ::readdir(proc)) {
    std::ifstream in(std::string("/proc/") + e->d_name + "/cmdline");
    std::string cmd((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::replace(cmd.begin(), cmd.end(), '\0', ' ');
    n += cmd.find(tag) != std::string::npos && cmd.find("sh -c") == std::string::npos ? 1 : 0;
  }
  ::closedir(proc);
  return n;
}

// A wrapper that starts something of its own and then runs the system (as
// a launch script, ros2 launch or docker run would): when the system ends,
// its end is the reason (not a timeout on the socket the other process
// still holds), and what it started is gone too.
TEST(ProcessSystem, WhatTheSystemStartedEndsWithIt) {
  const std::string tag = "47.3" + std::to_string(::getpid() % 1000);
  ProcessOptions o;
  o.command = "sh -c 'sleep " + tag + " & exec " + kChild + " exit 40'";
  o.start_timeout_s = o.step_timeout_s = 5.0;
  auto system = make_process_system(o);
  const auto t0 = std::chrono::steady_clock::now();
  const ScenarioResult r = run_scenario(contract::clear_scenario(20), *system, {});
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 4);
  EXPECT_TRUE(mentions(r.failure, "the system's process exited with status 3 (while answering step)")) << r.failure;
  for (int i = 0; i < 100 && processes_with("sleep " + tag) > 0; ++i) ::usleep(10000);  // SIGKILL is asynchronous
  EXPECT_EQ(processes_with("sleep " + tag), 0);
  EXPECT_EQ(children(), 0);
}

TEST(ProcessSystem, ACommandThatCannotRunFailsItsFirstRun) {
  auto system = make_landing_system("exec:/nonexistent/system --flag");
  const ScenarioResult r = run_scenario(contract::clear_scenario(20), *system, {});
  EXPECT_EQ(r.status, Violation::SystemFailed);
  EXPECT_TRUE(mentions(r.failure, "exited with status 127")) << r.failure;
  EXPECT_THROW((void)make_landing_system("exec:   "), InvalidArgument);
  ProcessOptions o;
  o.command = "true";
  o.step_timeout_s = 0;
  EXPECT_THROW((void)make_process_system(o), InvalidArgument);
  EXPECT_EQ(children(), 0);
}

TEST(ProcessSystem, TheSpecSetsTheTimeoutsOrSaysWhatIsWrong) {
  const ProcessOptions plain = parse_exec_spec("exec:a b:c");
  EXPECT_EQ(plain.command, "a b:c");  // the options end at the first ':'
  EXPECT_EQ(plain.step_timeout_s, ProcessOptions{}.step_timeout_s);
  const ProcessOptions set = parse_exec_spec("exec,step-timeout=0.5,start-timeout=60:x --y");
  EXPECT_EQ(set.command, "x --y");
  EXPECT_EQ(set.step_timeout_s, 0.5);
  EXPECT_EQ(set.start_timeout_s, 60);
  const auto message = [](const std::string& spec) {
    try {
      (void)resolve_system(spec);
    } catch (const InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_TRUE(
      mentions(message("exec,step-timeout=abc:x"), "exec,step-timeout=abc:x: step-timeout: 'abc' is not a number"));
  EXPECT_TRUE(mentions(message("exec,step-timeout=0:x"), "step_timeout_s: must be in (0, 3600] s"));
  EXPECT_TRUE(mentions(message("exec,stepp-timeout=1:x"), "option 'stepp-timeout=1': the options are"));
  EXPECT_TRUE(mentions(message("exec,step-timeout=1"), "not exec:COMMAND nor exec,KEY=SECONDS"));
  EXPECT_TRUE(mentions(message("exec,step-timeout=nan:x"), "must be in (0, 3600] s"));
  // The timeout set in the spec is the one a run waits for.
  auto system = SystemFactory("exec,step-timeout=0.3:" + kChild + " sleep 40").make();
  const auto t0 = std::chrono::steady_clock::now();
  const ScenarioResult r = run_scenario(contract::clear_scenario(20), *system, {});
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5);
  EXPECT_TRUE(mentions(r.failure, "no answer from the system within 0.3 s")) << r.failure;
  EXPECT_EQ(children(), 0);
}

// ---- the protocol's readers -------------------------------------------------------------

namespace tp = protocol;

std::string protocol_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const tp::ProtocolError& e) {
    return e.what();
  }
  return "(no ProtocolError)";
}

TEST(SystemProtocol, HeadersParseOrSayWhatIsWrong) {
  const tp::Header h = tp::parse_header("step 12 0 7 3");
  EXPECT_EQ(h.verb, "step");
  EXPECT_EQ(h.sizes, (std::vector<std::size_t>{12, 0, 7, 3}));
  EXPECT_EQ(tp::header("step", {12, 0, 7, 3}), "step 12 0 7 3\n");
  EXPECT_EQ(tp::parse_header("ready").sizes.size(), 0U);
  EXPECT_EQ(protocol_error([] { (void)tp::parse_header(""); }), "header: empty");
  EXPECT_TRUE(mentions(protocol_error([] { (void)tp::parse_header("step 1x"); }), "'1x' is not a byte count"));
  EXPECT_TRUE(mentions(protocol_error([] { (void)tp::parse_header("step -1"); }), "is not a byte count"));
  EXPECT_TRUE(mentions(protocol_error([] { (void)tp::parse_header("step 999999999999"); }), "over 256 MiB"));
  EXPECT_TRUE(mentions(protocol_error([] { (void)tp::parse_header("Step 1"); }), "has no verb"));
  EXPECT_TRUE(mentions(protocol_error([] { (void)tp::parse_header(std::string("step\0 1", 7)); }), "printable"));
}

TEST(SystemProtocol, OutputsRoundTripExactlyAndBadOnesNameTheirKey) {
  SystemOutput o;
  o.command.velocity_world = {0.1, -1.0 / 3.0, 2.5e-17};
  o.command.yaw_rate_deg = -7.25;
  o.command.land = true;
  o.phase = "descend";
  o.descent_started = true;
  o.target = {1.0 / 7.0, -2};
  Detection d;
  d.id = 4;
  d.corners = {Eigen::Vector2d(1.5, 2), Eigen::Vector2d(3, 4.125), Eigen::Vector2d(5, 6), Eigen::Vector2d(7, 8)};
  d.quality = 31.7;
  d.confidence = 0.875;
  d.accepted = true;
  d.ground = {0.3, 0.6};
  o.detections = {d};
  std::string phase;
  const SystemOutput back = tp::parse_output(tp::output_json(o), phase);
  EXPECT_EQ(back.command.velocity_world, o.command.velocity_world);  // exact, not near
  EXPECT_EQ(back.command.yaw_rate_deg, o.command.yaw_rate_deg);
  EXPECT_TRUE(back.command.land);
  EXPECT_EQ(back.phase, "descend");
  EXPECT_EQ(back.target, o.target);
  ASSERT_EQ(back.detections.size(), 1U);
  EXPECT_EQ(back.detections[0].corners[1], d.corners[1]);
  EXPECT_EQ(back.detections[0].ground, d.ground);
  EXPECT_EQ(back.detections[0].id, 4);
  EXPECT_TRUE(back.detections[0].accepted);

  const auto bad = [&](const std::string& json) {
    return protocol_error([&] { (void)tp::parse_output(json, phase); });
  };
  EXPECT_EQ(bad("{}"), "command: velocity: missing");
  EXPECT_EQ(bad("[1]"), "command: not a JSON object");
  EXPECT_EQ(bad("{\"velocity\":[0,0]}"), "command: velocity: not an array of 3 numbers");
  EXPECT_EQ(bad("{\"velocity\":[0,0,\"x\"]}"), "command: velocity: not a number");
  EXPECT_EQ(bad("{\"velocity\":[0,0,0],\"speed\":1}"), "command: unknown key 'speed'");
  EXPECT_EQ(bad("{\"velocity\":[0,0,0],\"land\":1}"), "command: land: not true or false");
  EXPECT_EQ(bad("{\"velocity\":[0,0,1e999]}"), "command: not JSON");  // out of double range
  EXPECT_EQ(bad("{\"velocity\":[0,0,0],\"detections\":[{\"corners\":[[1,2]]}]}"),
            "command: detections[0].corners: not four [u, v] pairs");
  EXPECT_EQ(bad("{\"velocity\":[0,0,0],\"detections\":[{\"corners\":[[1,2],[1,2],[1,2],[1,2]],\"idx\":1}]}"),
            "command: detections[0]: unknown key 'idx'");
}

TEST(SystemProtocol, SetupAndStateRoundTrip) {
  SystemSetup s;
  s.camera.width = 320;
  s.camera.tilt_deg = 12.5;
  s.marker_id = 7;
  s.dictionary = "5X5_100";
  s.gps_target = {1.25, -0.5};
  const SystemSetup back = tp::parse_setup(tp::setup_json(s));
  EXPECT_EQ(back.camera.width, 320);
  EXPECT_EQ(back.camera.tilt_deg, 12.5);
  EXPECT_EQ(back.marker_id, 7);
  EXPECT_EQ(back.dictionary, "5X5_100");
  EXPECT_EQ(back.gps_target, s.gps_target);
  SystemInput in;
  in.state.t = 1.0 / 3.0;
  in.state.position = {1, 2, 9.75};
  in.state.yaw_deg = 33;
  in.state.R_world_body = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const tp::StepState st = tp::parse_state(tp::state_json(in));
  EXPECT_EQ(st.state.t, in.state.t);
  EXPECT_EQ(st.state.position, in.state.position);
  EXPECT_EQ(st.state.R_world_body, in.state.R_world_body);  // the child sees the attitude the world has
  EXPECT_FALSE(st.frame);
  const tp::Header hello_header{"touchdown-system", {1, 0}};
  EXPECT_EQ(tp::parse_hello(hello_header, "{\"name\":\"x\",\"wants\":[\"depth\"]}").depth, true);
  EXPECT_TRUE(mentions(protocol_error([&] { (void)tp::parse_hello(hello_header, "{\"name\":\"\"}"); }), "name"));
  EXPECT_TRUE(
      mentions(protocol_error([&] { (void)tp::parse_hello(hello_header, "{\"name\":\"x\",\"wants\":[\"lidar\"]}"); }),
               "'lidar' is not image, depth or mask"));
}

}  // namespace
}  // namespace touchdown::scenario
