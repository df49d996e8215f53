#pragma once
// FNV-1a, 64 bit (Fowler, Noll and Vo; the IETF draft
// draft-eastlake-fnv): a content identity for files named in results (the
// DQN's weights, a learned detector's model), not a cryptographic hash.
// Internal to the library (not installed).
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace touchdown::detail {

/// FNV-1a of `bytes`, continuing from `h` (to hash several pieces as one).
inline std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t h = 0xcbf29ce484222325ULL) {
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

/// "fnv1a64:<hex>" without leading zeros, the form campaign.json records.
inline std::string fnv1a64_id(std::uint64_t h) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%llx", static_cast<unsigned long long>(h));
  return std::string("fnv1a64:") + hex;
}

}  // namespace touchdown::detail
