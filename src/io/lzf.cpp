// LZF decompression, written from the format description:
//   ctrl < 32:  literal run of ctrl + 1 bytes follows.
//   otherwise:  back-reference; len = ctrl >> 5 (7 -> add the next byte),
//               offset = ((ctrl & 0x1f) << 8) + next byte + 1; copy len + 2 bytes
//               from offset bytes back in the output (byte by byte: may overlap).
#include "lzf.hpp"

#include <stdexcept>
#include <string>

namespace proxseg::detail {

void lzf_decompress(const unsigned char* in, std::size_t in_size, unsigned char* out,
                    std::size_t out_size) {
  std::size_t ip = 0, op = 0;
  while (ip < in_size) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {
      const std::size_t run = ctrl + 1;
      if (run > in_size - ip) throw std::runtime_error("LZF literal run past the end of the input");
      if (run > out_size - op) throw std::runtime_error("LZF output longer than declared");
      for (std::size_t k = 0; k < run; ++k) out[op++] = in[ip++];
      continue;
    }
    std::size_t len = ctrl >> 5;
    if (len == 7) {
      if (ip >= in_size) throw std::runtime_error("LZF back-reference past the end of the input");
      len += in[ip++];
    }
    if (ip >= in_size) throw std::runtime_error("LZF back-reference past the end of the input");
    const std::size_t offset = ((static_cast<std::size_t>(ctrl & 0x1f)) << 8) + in[ip++] + 1;
    len += 2;
    if (offset > op) throw std::runtime_error("LZF back-reference before the start of the output");
    if (len > out_size - op) throw std::runtime_error("LZF output longer than declared");
    for (std::size_t k = 0; k < len; ++k, ++op) out[op] = out[op - offset];
  }
  if (op != out_size)
    throw std::runtime_error("LZF data ends after " + std::to_string(op) + " of " +
                             std::to_string(out_size) + " bytes");
}

}  // namespace proxseg::detail
