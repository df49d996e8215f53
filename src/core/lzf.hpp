#pragma once
// LZF (the compressor PCL uses for `binary_compressed` PCD), written from the
// format description in Marc Lehmann's liblzf (lzf_d.c header comment):
//   000LLLLL                    literal run of L+1 bytes follows
//   LLLooooo oooooooo           back reference, length L+2 (L = 1..6), offset o+1
//   111ooooo LLLLLLLL oooooooo  back reference, length L+9, offset o+1
#include <cstddef>
#include <cstdint>
#include <vector>

namespace touchdown::detail {

/// Decompresses exactly `out_size` bytes; false on any malformed or
/// truncated input, or if the output size does not match.
bool lzf_decompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out, std::size_t out_size);

/// Compresses `in`; the output is always decodable by lzf_decompress.
std::vector<std::uint8_t> lzf_compress(const std::uint8_t* in, std::size_t in_size);

}  // namespace touchdown::detail
