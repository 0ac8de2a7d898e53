// LZF decompression and compression, written from the format description:
//   ctrl < 32:  literal run of ctrl + 1 bytes follows.
//   otherwise:  back-reference; len = ctrl >> 5 (7 -> add the next byte),
//               offset = ((ctrl & 0x1f) << 8) + next byte + 1; copy len + 2 bytes
//               from offset bytes back in the output (byte by byte: may overlap).
#include "io/formats/lzf.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

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
      std::memcpy(out + op, in + ip, run);
      op += run, ip += run;
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
    // The copy repeats the last `offset` bytes: copied in chunks whose source ends where they
    // start (no overlap), each a whole number of periods and twice the last (long runs of one
    // repeated value, the NaNs of missing pixels, take a few copies instead of a byte each).
    const std::size_t from = op - offset, end = op + len;
    while (op < end) {
      const std::size_t chunk = std::min(end - op, op - from);
      std::memcpy(out + op, out + from, chunk);
      op += chunk;
    }
  }
  if (op != out_size)
    throw std::runtime_error("LZF data ends after " + std::to_string(op) + " of " +
                             std::to_string(out_size) + " bytes");
}

namespace {

constexpr std::size_t kMaxLiteral = 32;         // ctrl 0..31
constexpr std::size_t kMaxOffset = 8192;        // 13 bits of offset - 1
constexpr std::size_t kMinMatch = 3;            // a 2-byte back-reference codes 3 bytes
constexpr std::size_t kMaxMatch = 7 + 255 + 2;  // len field 7 plus the extra byte, plus 2
constexpr int kHashBits = 14;

std::uint32_t load32(const unsigned char* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}
std::uint64_t load64(const unsigned char* p) {
  std::uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

// The 3 bytes at p as one number (the 4th byte masked off), independent of the byte order.
std::uint32_t three_bytes(const unsigned char* p) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  return load32(p) >> 8;
#else
  return load32(p) & 0xffffffu;
#endif
}

std::uint32_t hash3(std::uint32_t v) {
  // Multiplicative hashing: the top bits of the product depend on all three bytes.
  return (v * 2654435761u) >> (32 - kHashBits);
}

// How many bytes from a and b agree, at most limit.
std::size_t common_length(const unsigned char* a, const unsigned char* b, std::size_t limit) {
  std::size_t len = 0;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  // Eight bytes per step: the lowest differing byte of the XOR is the first mismatch.
  while (len + 8 <= limit) {
    const std::uint64_t diff = load64(a + len) ^ load64(b + len);
    if (diff != 0) return len + static_cast<std::size_t>(__builtin_ctzll(diff) >> 3);
    len += 8;
  }
#endif
  while (len < limit && a[len] == b[len]) ++len;
  return len;
}

// Writes in[from, to) as literal runs of at most 32 bytes at op; returns the new op.
unsigned char* put_literals(const unsigned char* in, std::size_t from, std::size_t to,
                            unsigned char* op) {
  while (from < to) {
    const std::size_t run = to - from < kMaxLiteral ? to - from : kMaxLiteral;
    *op++ = static_cast<unsigned char>(run - 1);
    std::memcpy(op, in + from, run);
    op += run;
    from += run;
  }
  return op;
}

}  // namespace

std::string lzf_compress(const unsigned char* in, std::size_t size) {
  std::string out(lzf_bound(size), '\0');
  out.resize(lzf_compress(in, size, reinterpret_cast<unsigned char*>(out.data())));
  return out;
}

std::size_t lzf_compress(const unsigned char* in, std::size_t size, unsigned char* out) {
  if (size == 0) return 0;
  // lzf_bound: the worst case is all literals, one control byte per 32.
  unsigned char* const out_begin = out;
  unsigned char* op = out_begin;
  // Position + 1 of the last occurrence of each hashed 3-byte prefix; 0 = none. Zero-initialised
  // so that the output depends on the input only.
  std::vector<std::uint32_t> table(std::size_t{1} << kHashBits, 0);
  std::size_t lit_start = 0;  // first input byte not yet written
  std::size_t ip = 0;
  // Positions up to size - 4 may start a match: four bytes are loaded to hash three. Past a
  // 32-bit position table entries would wrap: larger inputs go in 2 GiB windows of their own.
  while (ip + 4 <= size) {
    const std::size_t window = ip & ~std::size_t{0x7fffffff};
    const std::uint32_t h = hash3(three_bytes(in + ip));
    const std::size_t ref = window + table[h];  // candidate position + 1
    table[h] = static_cast<std::uint32_t>(ip - window + 1);
    if (ref > window && ref <= ip && ip - (ref - 1) <= kMaxOffset &&
        three_bytes(in + ref - 1) == three_bytes(in + ip)) {
      const std::size_t from = ref - 1;
      const std::size_t limit = size - ip < kMaxMatch ? size - ip : kMaxMatch;
      const std::size_t len =
          kMinMatch + common_length(in + from + kMinMatch, in + ip + kMinMatch, limit - kMinMatch);
      op = put_literals(in, lit_start, ip, op);
      const std::size_t off = ip - from - 1;  // 0..8191
      const std::size_t code = len - 2;       // 1..262
      if (code < 7) {
        *op++ = static_cast<unsigned char>((code << 5) | (off >> 8));
      } else {
        *op++ = static_cast<unsigned char>((7 << 5) | (off >> 8));
        *op++ = static_cast<unsigned char>(code - 7);
      }
      *op++ = static_cast<unsigned char>(off & 0xff);
      ip += len;
      lit_start = ip;
      // The last two positions of the match go into the table too, so that a run continues
      // from near its end (as liblzf's fast mode does); hashing all of them costs more than it
      // gains on point data.
      for (std::size_t p = ip - 2; p < ip && p + 4 <= size; ++p)
        if ((p & ~std::size_t{0x7fffffff}) == window)
          table[hash3(three_bytes(in + p))] = static_cast<std::uint32_t>(p - window + 1);
    } else {
      ++ip;
    }
  }
  op = put_literals(in, lit_start, size, op);
  return static_cast<std::size_t>(op - out_begin);
}

}  // namespace proxseg::detail
