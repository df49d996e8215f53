// A process system for process_system_test.cpp: the GPS lander of
// gps_lander.hpp served with serve_system() (so that a campaign through
// exec: can be compared with the same code in the host, bit for bit), or,
// with a fault mode, one that breaks at its N-th step:
//   exec_child lander              (asks for the image, as a vision system would)
//   exec_child lander-no-frames    (asks for no frame payload)
//   exec_child exit N | sleep N | garbage N | truncate N | wrong-size N | error N
//   exec_child version      (says protocol version 2)
//   exec_child silent       (never says hello)
#include <unistd.h>

#include <cstdlib>
#include <iostream>
#include <string>

#include "gps_lander.hpp"
#include "touchdown/scenario/system_protocol.hpp"

namespace {

namespace ts = touchdown::scenario;

class Saboteur final : public ts::LandingSystem {
 public:
  Saboteur(std::string mode, int at) : mode_(std::move(mode)), at_(at) {}
  [[nodiscard]] std::string_view name() const override { return "saboteur"; }
  void reset(const ts::SystemSetup& setup) override { lander_.reset(setup), steps_ = 0; }
  ts::SystemOutput update(const ts::SystemInput& in) override {
    if (++steps_ == at_) {
      if (mode_ == "exit") std::exit(3);
      if (mode_ == "sleep") ::sleep(600);
      if (mode_ == "garbage") std::cout << "!!! this is not a header\n" << std::flush;
      if (mode_ == "truncate") std::cout << "command 100\n{\"velocity\"" << std::flush, std::_Exit(0);
      if (mode_ == "wrong-size") std::cout << "command 3\n{\"velocity\":[0,0,0]}" << std::flush;
      if (mode_ == "error") throw std::runtime_error("planted error at step " + std::to_string(at_));
      if (mode_ == "garbage" || mode_ == "wrong-size") ::sleep(600);  // the host must give up on it
    }
    return lander_.update(in);
  }

 private:
  std::string mode_;
  int at_;
  int steps_ = 0;
  touchdown::test_plugin::GpsLander lander_{"saboteur"};
};

}  // namespace

int main(int argc, char** argv) {
  std::ios::sync_with_stdio(false);
  const std::string mode = argc > 1 ? argv[1] : "lander";
  if (mode == "silent") {
    ::sleep(600);
    return 0;
  }
  if (mode == "version") {
    std::string line;
    std::getline(std::cin, line);
    std::cout << "touchdown-system 2 14\n{\"name\":\"new\"}" << std::flush;
    ::sleep(600);
    return 0;
  }
  ts::protocol::Hello hello;  // the image only
  if (mode == "lander" || mode == "lander-no-frames") {
    hello.image = mode == "lander";  // lander-no-frames: the protocol's cost without the image payloads
    touchdown::test_plugin::GpsLander lander("test-gps-lander");
    return ts::protocol::serve_system(lander, hello);
  }
  Saboteur saboteur(mode, argc > 2 ? std::atoi(argv[2]) : 1);
  return ts::protocol::serve_system(saboteur, hello);
}
