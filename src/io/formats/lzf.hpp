// LZF compression and decompression (the format of PCD "binary_compressed" data). Private to the
// library.
#pragma once
#include <cstddef>
#include <string>

namespace proxseg::detail {

// Decompresses in[0, in_size) into exactly out_size bytes at out. Throws std::runtime_error
// (one-line reason, no path) if the input is corrupt, ends early, or does not produce exactly
// out_size bytes. Never reads or writes outside the given ranges.
void lzf_decompress(const unsigned char* in, std::size_t in_size, unsigned char* out,
                    std::size_t out_size);

// The LZF encoding of in[0, size): literal runs of at most 32 bytes and back-references of 3 to
// 264 bytes at most 8192 bytes back, found greedily through a hash table of the last position of
// every 3-byte prefix. Deterministic (the same input gives the same bytes) and always valid LZF,
// also when it is not smaller than the input (incompressible data: size + size / 32 + 1 bytes at
// most). An empty input gives an empty output.
std::string lzf_compress(const unsigned char* in, std::size_t size);

// The same bytes into out[0, lzf_bound(size)) (the caller's buffer, not cleared first); returns
// how many were written.
std::size_t lzf_compress(const unsigned char* in, std::size_t size, unsigned char* out);
inline std::size_t lzf_bound(std::size_t size) {
  return size == 0 ? 0 : size + size / 32 + 1;
}

}  // namespace proxseg::detail
