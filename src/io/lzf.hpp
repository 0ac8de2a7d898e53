// LZF decompression (the format of PCD "binary_compressed" data). Private to the library.
#pragma once
#include <cstddef>

namespace proxseg::detail {

// Decompresses in[0, in_size) into exactly out_size bytes at out. Throws std::runtime_error
// (one-line reason, no path) if the input is corrupt, ends early, or does not produce exactly
// out_size bytes. Never reads or writes outside the given ranges.
void lzf_decompress(const unsigned char* in, std::size_t in_size, unsigned char* out,
                    std::size_t out_size);

}  // namespace proxseg::detail
