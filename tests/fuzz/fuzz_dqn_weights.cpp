// libFuzzer target for the DQN weights reader (search/dqn.hpp).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/search/dqn.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace ts = touchdown::search;
  try {
    const auto net = ts::parse_weights(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.txt");
    // What was parsed reads back bit-exact from what the writer makes of it.
    const auto back = ts::parse_weights(ts::weights_text(net), "fuzz.txt");
    const auto a = net.parameters(), b = back.parameters();
    if (back.hidden() != net.hidden() || a.size() != b.size()) __builtin_trap();
    if (std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) != 0) __builtin_trap();
    (void)net.greedy({1, -2, 3, -4});
  } catch (const touchdown::Error&) {
  }
  return 0;
}
