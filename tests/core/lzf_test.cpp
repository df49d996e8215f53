#include "core/lzf.hpp"

#include <gtest/gtest.h>

#include <random>

namespace d = touchdown::detail;

namespace {

void round_trip(const std::vector<std::uint8_t>& in) {
  const auto packed = d::lzf_compress(in.data(), in.size());
  std::vector<std::uint8_t> out(in.size());
  ASSERT_TRUE(d::lzf_decompress(packed.data(), packed.size(), out.data(), out.size()));
  EXPECT_EQ(out, in);
}

}  // namespace

TEST(Lzf, HandMadeStreamDecodes) {
  // literal "ab" (ctrl 1), then back reference length 3+2-... : ctrl (1<<5) = len 1+2 = 3, offset 1+1 = 2
  const std::vector<std::uint8_t> packed = {0x01, 'a', 'b', 0x20, 0x01};
  std::vector<std::uint8_t> out(5);
  ASSERT_TRUE(d::lzf_decompress(packed.data(), packed.size(), out.data(), out.size()));
  EXPECT_EQ(std::string(out.begin(), out.end()), "ababa");
  // Long form: ctrl 0xE0 (len 7 + next byte 1 = 8, +2 = 10), offset 1.
  const std::vector<std::uint8_t> packed2 = {0x00, 'z', 0xE0, 0x01, 0x00};
  std::vector<std::uint8_t> out2(11);
  ASSERT_TRUE(d::lzf_decompress(packed2.data(), packed2.size(), out2.data(), out2.size()));
  EXPECT_EQ(std::string(out2.begin(), out2.end()), std::string(11, 'z'));
}

TEST(Lzf, RoundTrips) {
  std::mt19937 rng(1);
  std::vector<std::uint8_t> random(100000), repetitive(100000), empty;
  for (auto& b : random) b = static_cast<std::uint8_t>(rng());
  for (std::size_t i = 0; i < repetitive.size(); ++i) repetitive[i] = static_cast<std::uint8_t>((i / 7) % 13);
  round_trip(random);
  round_trip(repetitive);
  round_trip(empty);
  round_trip({1, 2});
  EXPECT_LT(d::lzf_compress(repetitive.data(), repetitive.size()).size(), repetitive.size() / 10);
}

TEST(Lzf, RejectsMalformedStreams) {
  std::vector<std::uint8_t> out(10);
  const std::vector<std::uint8_t> ref_before_start = {0x20, 0x00};
  EXPECT_FALSE(d::lzf_decompress(ref_before_start.data(), ref_before_start.size(), out.data(), out.size()));
  const std::vector<std::uint8_t> short_literal = {0x05, 'a'};
  EXPECT_FALSE(d::lzf_decompress(short_literal.data(), short_literal.size(), out.data(), out.size()));
  const std::vector<std::uint8_t> too_long = {0x0F, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16};
  EXPECT_FALSE(d::lzf_decompress(too_long.data(), too_long.size(), out.data(), out.size()));
  const std::vector<std::uint8_t> too_short = {0x00, 'a'};
  EXPECT_FALSE(d::lzf_decompress(too_short.data(), too_short.size(), out.data(), out.size()));
}
