#include "lzf.hpp"

#include <algorithm>
#include <cstring>

namespace touchdown::detail {

bool lzf_decompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out, std::size_t out_size) {
  std::size_t ip = 0;
  std::size_t op = 0;
  while (ip < in_size) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {  // literal run
      const std::size_t len = ctrl + 1;
      if (ip + len > in_size || op + len > out_size) return false;
      std::memcpy(out + op, in + ip, len);
      ip += len;
      op += len;
    } else {  // back reference
      std::size_t len = ctrl >> 5;
      if (len == 7) {
        if (ip >= in_size) return false;
        len += in[ip++];
      }
      if (ip >= in_size) return false;
      const std::size_t offset = ((static_cast<std::size_t>(ctrl & 0x1f) << 8) | in[ip++]) + 1;
      len += 2;
      if (offset > op || op + len > out_size) return false;
      const std::uint8_t* ref = out + op - offset;
      for (std::size_t k = 0; k < len; ++k) out[op + k] = ref[k];  // may overlap
      op += len;
    }
  }
  return op == out_size;
}

std::vector<std::uint8_t> lzf_compress(const std::uint8_t* in, std::size_t in_size) {
  constexpr std::size_t kMaxOffset = 1u << 13;  // 8192
  constexpr std::size_t kMaxLen = 255 + 7 + 2;  // 264
  constexpr int kHashBits = 14;
  std::vector<std::uint8_t> out;
  out.reserve(in_size + in_size / 32 + 16);
  std::vector<std::int64_t> table(std::size_t{1} << kHashBits, -1);

  std::size_t lit_start = 0;
  auto flush_literals = [&](std::size_t end) {
    while (lit_start < end) {
      const std::size_t n = std::min<std::size_t>(32, end - lit_start);
      out.push_back(static_cast<std::uint8_t>(n - 1));
      out.insert(out.end(), in + lit_start, in + lit_start + n);
      lit_start += n;
    }
  };
  auto hash3 = [&](std::size_t p) {
    const std::uint32_t v = (std::uint32_t{in[p]} << 16) | (std::uint32_t{in[p + 1]} << 8) | in[p + 2];
    return (v * 2654435761u) >> (32 - kHashBits);
  };

  std::size_t ip = 0;
  while (ip + 2 < in_size) {
    const auto h = hash3(ip);
    const std::int64_t cand = table[h];
    table[h] = static_cast<std::int64_t>(ip);
    if (cand >= 0 && ip - static_cast<std::size_t>(cand) <= kMaxOffset && std::memcmp(in + cand, in + ip, 3) == 0) {
      const std::size_t ref = static_cast<std::size_t>(cand);
      std::size_t len = 3;
      const std::size_t max_len = std::min(kMaxLen, in_size - ip);
      while (len < max_len && in[ref + len] == in[ip + len]) ++len;
      flush_literals(ip);
      const std::size_t off = ip - ref - 1;
      const std::size_t l = len - 2;
      if (l < 7) {
        out.push_back(static_cast<std::uint8_t>((l << 5) | (off >> 8)));
      } else {
        out.push_back(static_cast<std::uint8_t>((7u << 5) | (off >> 8)));
        out.push_back(static_cast<std::uint8_t>(l - 7));
      }
      out.push_back(static_cast<std::uint8_t>(off & 0xff));
      ip += len;
      lit_start = ip;
    } else {
      ++ip;
    }
  }
  flush_literals(in_size);
  return out;
}

}  // namespace touchdown::detail
