// PCD reading (read_pcd in cloud_io.hpp): after the header (pcd_header.hpp), the fields a frame
// is read from (x y z, the packed colour, the label field) and the point data, DATA ascii (one
// checked line per point), binary (points one after another) or binary_compressed (LZF, fields
// one after another, lzf.hpp). Only as many bytes as the header promises are read, from a file or
// from any other source of bytes (pcd_reader.hpp: standard input).
#include <proxseg/io/cloud_io.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "io/formats/lzf.hpp"
#include "io/formats/pcd_header.hpp"
#include "io/formats/pcd_reader.hpp"
#include "io/formats/text_fields.hpp"
#include "io/formats/text_numbers.hpp"
#include "io/input_file.hpp"
#include "io/reader_errors.hpp"

namespace proxseg {
namespace {

using detail::fail;
using detail::next_line;
using detail::parse_number;
using detail::parse_pcd_header;
using detail::PcdField;
using detail::PcdHeader;
using detail::quote;
using detail::split_ws;

template <typename T>
T load(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

// An integer element of 1, 2, 4 or 8 bytes, of the types T1..T8 of those sizes, as a double.
template <typename T1, typename T2, typename T4, typename T8>
double load_integer(const unsigned char* p, int size) {
  switch (size) {
    case 1:
      return load<T1>(p);
    case 2:
      return load<T2>(p);
    case 4:
      return load<T4>(p);
    default:
      return static_cast<double>(load<T8>(p));
  }
}

// Reads one binary element as a double (x, y, z).
double load_number(const unsigned char* p, char type, int size) {
  if (type == 'F') return size == 8 ? load<double>(p) : static_cast<double>(load<float>(p));
  if (type == 'U')
    return load_integer<std::uint8_t, std::uint16_t, std::uint32_t, std::uint64_t>(p, size);
  return load_integer<std::int8_t, std::int16_t, std::int32_t, std::int64_t>(p, size);
}

const PcdField* find_field(const std::string& path, const PcdHeader& h, const char* name) {
  const PcdField* found = nullptr;
  for (const auto& f : h.fields) {
    if (f.name != name) continue;
    if (found) fail(path, std::string("field ") + name + " appears twice (expected it once)");
    found = &f;
  }
  return found;
}

// Where the values of one field are: point i's element at base + i * stride.
struct FieldData {
  const unsigned char* base = nullptr;
  std::size_t stride = 0;
  const unsigned char* at(std::size_t i) const { return base + i * stride; }
};

// The fields a frame is read from: x, y, z (single floats) and, when the file has them, the packed
// colour (none: an XYZ-only cloud, Frame::rgb left empty) and the integer label field.
struct PcdFields {
  const PcdField *x = nullptr, *y = nullptr, *z = nullptr, *colour = nullptr, *label = nullptr;
};

PcdFields pcd_fields(const std::string& path, const PcdHeader& h, const std::string& label_field) {
  PcdFields f;
  f.x = find_field(path, h, "x");
  f.y = find_field(path, h, "y");
  f.z = find_field(path, h, "z");
  if (!f.x || !f.y || !f.z)
    fail(path, "has no x/y/z field (expected FIELDS to include x, y and z)");
  for (const PcdField* c : {f.x, f.y, f.z})
    if (c->type != 'F' || c->count != 1)
      fail(path, "field " + c->name + " is not a single float (expected TYPE F, COUNT 1)");
  f.colour = find_field(path, h, "rgb");
  if (!f.colour) f.colour = find_field(path, h, "rgba");
  if (f.colour && (f.colour->size != 4 || f.colour->count != 1))
    fail(path,
         "field " + f.colour->name + " is not 4 bytes (expected SIZE 4, COUNT 1: packed colour)");
  f.label = find_field(path, h, label_field.c_str());
  if (f.label && (f.label->type == 'F' || f.label->size > 4 || f.label->count != 1))
    fail(path, "field " + label_field +
                   " is not an integer (expected TYPE U or I, SIZE 1, 2 or 4, COUNT 1)");
  return f;
}

std::uint32_t pcd_label(const std::string& path, double v, std::size_t i) {
  if (v < 0)
    fail(path, "point " + std::to_string(i) + " has negative label " +
                   std::to_string(static_cast<long long>(v)) + " (expected labels >= 0)");
  return static_cast<std::uint32_t>(v);
}

Rgb unpack_rgb(std::uint32_t packed) {
  return {static_cast<std::uint8_t>(packed >> 16), static_cast<std::uint8_t>(packed >> 8),
          static_cast<std::uint8_t>(packed)};
}

// DATA ascii: one line of values per point, each checked (line number, field, what was expected).
void read_pcd_ascii(const std::string& path, const std::string& text, const PcdHeader& h,
                    const PcdFields& f, Frame& frame) {
  const std::size_t n = static_cast<std::size_t>(h.points);
  const std::size_t avail = text.size() - h.data_start;
  frame.xyz.reserve(std::min(n, avail / 2 + 1));
  if (f.colour) frame.rgb.reserve(std::min(n, avail / 2 + 1));
  if (f.label) frame.label.reserve(std::min(n, avail / 2 + 1));
  const std::string_view all(text);
  std::size_t pos = h.data_start, line_no = h.data_line;
  std::size_t got = 0;
  while (pos < all.size()) {
    const auto tok = split_ws(next_line(all, pos));
    ++line_no;
    if (tok.empty()) continue;
    const std::string where = "line " + std::to_string(line_no);
    if (got == n)
      fail(path, where + " has data beyond POINTS " + std::to_string(n) + " (expected " +
                     std::to_string(n) + " data line(s))");
    if (tok.size() != h.values_per_line)
      fail(path, where + " has " + std::to_string(tok.size()) + " values (expected " +
                     std::to_string(h.values_per_line) + ", one per field element)");
    auto number = [&](const PcdField* c) {
      double v;
      if (!parse_number(tok[c->value_index], v))
        fail(path, where + ": " + c->name + " value " + quote(tok[c->value_index]) +
                       " is not a number (expected a number)");
      return v;
    };
    Eigen::Vector3f p(static_cast<float>(number(f.x)), static_cast<float>(number(f.y)),
                      static_cast<float>(number(f.z)));
    if (f.colour) {
      std::uint32_t packed = 0;
      const std::string_view ct = tok[f.colour->value_index];
      if (f.colour->type == 'F') {
        float c;
        if (!parse_number(ct, c))
          fail(path, where + ": " + f.colour->name + " value " + quote(ct) +
                         " is not a number (expected a packed float colour)");
        std::memcpy(&packed, &c, 4);
      } else {
        const double v = number(f.colour);
        if (!(v >= -2147483648.0 && v <= 4294967295.0) || v != std::floor(v))
          fail(path, where + ": " + f.colour->name + " value " + quote(ct) +
                         " is not a 32-bit integer (expected a packed colour)");
        packed = static_cast<std::uint32_t>(static_cast<std::int64_t>(v));
      }
      frame.rgb.push_back(unpack_rgb(packed));
    }
    if (f.label) {
      const double v = number(f.label);
      if (v != std::floor(v) || v > 4294967295.0)
        fail(path, where + ": label value " + quote(tok[f.label->value_index]) +
                       " is not an integer (expected a non-negative integer)");
      frame.label.push_back(pcd_label(path, v, got));
    }
    frame.xyz.push_back(p);
    ++got;
  }
  if (got != n)
    fail(path, "has " + std::to_string(got) + " data line(s) but POINTS " + std::to_string(n) +
                   " (expected " + std::to_string(n) + " lines; file truncated?)");
}

// DATA binary_compressed: the LZF block after its two sizes, checked before anything is
// allocated, decompressed into buffer (fields one after another, n values each).
void decompress_pcd(const std::string& path, const PcdHeader& h, const unsigned char* data,
                    std::size_t avail, std::vector<unsigned char>& buffer) {
  const std::size_t n = static_cast<std::size_t>(h.points);
  const std::size_t need = n * h.point_size;  // n < 2^31, point_size < 2^33: no overflow
  if (avail < 8)
    fail(path, "binary_compressed data is truncated: " + std::to_string(avail) +
                   " bytes (expected 8 bytes of sizes and the compressed data)");
  const std::uint32_t csize = load<std::uint32_t>(data);
  const std::uint32_t usize = load<std::uint32_t>(data + 4);
  if (usize != need)
    fail(path, "binary_compressed uncompressed size is " + std::to_string(usize) +
                   " bytes (expected " + std::to_string(n) + " points * " +
                   std::to_string(h.point_size) + " bytes = " + std::to_string(need) + ")");
  if (csize > avail - 8)
    fail(path, "binary_compressed data is truncated: compressed size is " + std::to_string(csize) +
                   " bytes but only " + std::to_string(avail - 8) +
                   " follow (expected the whole compressed block)");
  // One LZF back-reference of 3 bytes expands to at most 264: reject impossible ratios
  // before allocating.
  if (usize / 88 > static_cast<std::size_t>(csize) + 1)
    fail(path, "binary_compressed sizes are inconsistent: " + std::to_string(csize) +
                   " compressed bytes cannot hold " + std::to_string(usize) +
                   " (expected a valid LZF block)");
  buffer.resize(usize);
  try {
    detail::lzf_decompress(data + 8, csize, buffer.data(), buffer.size());
  } catch (const std::runtime_error& e) {
    fail(path, std::string("binary_compressed data is corrupt (") + e.what() + ")");
  }
}

// DATA binary (points one after another) or binary_compressed (fields one after another).
void read_pcd_binary(const std::string& path, const std::string& text, const PcdHeader& h,
                     const PcdFields& f, Frame& frame) {
  const std::size_t n = static_cast<std::size_t>(h.points);
  const std::size_t avail = text.size() - h.data_start;
  const auto* data = reinterpret_cast<const unsigned char*>(text.data()) + h.data_start;
  std::vector<unsigned char> buffer;
  if (h.data == "binary") {
    const std::size_t need = n * h.point_size;  // n < 2^31, point_size < 2^33: no overflow
    if (avail < need)
      fail(path, "binary data is truncated: " + std::to_string(avail) + " bytes (expected " +
                     std::to_string(n) + " points * " + std::to_string(h.point_size) +
                     " bytes = " + std::to_string(need) + ")");
  } else {
    decompress_pcd(path, h, data, avail, buffer);
  }
  const auto locate = [&](const PcdField* c) -> FieldData {
    if (h.data == "binary") return {data + c->offset, h.point_size};
    return {buffer.data() + n * c->offset, c->count * static_cast<std::size_t>(c->size)};
  };
  const FieldData dx = locate(f.x), dy = locate(f.y), dz = locate(f.z);
  frame.xyz.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    frame.xyz[i] = Eigen::Vector3f(static_cast<float>(load_number(dx.at(i), 'F', f.x->size)),
                                   static_cast<float>(load_number(dy.at(i), 'F', f.y->size)),
                                   static_cast<float>(load_number(dz.at(i), 'F', f.z->size)));
  if (f.colour) {
    const FieldData dc = locate(f.colour);
    frame.rgb.resize(n);
    for (std::size_t i = 0; i < n; ++i) frame.rgb[i] = unpack_rgb(load<std::uint32_t>(dc.at(i)));
  }
  if (f.label) {
    const FieldData dl = locate(f.label);
    frame.label.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      frame.label[i] = pcd_label(path, load_number(dl.at(i), f.label->type, f.label->size), i);
  }
}

// The header is read from the first kPcdHeaderBytes of a file: it must end within them.
constexpr std::size_t kPcdHeaderBytes = std::size_t{1} << 20;

// The most bytes a PCD can need, from its header in `text` (the file's first bytes): header and
// data, as the header promises them. ascii data promises no byte count: its bound allows 128
// characters per value, more than any number written in full.
std::size_t pcd_promised_bytes(const std::string& path, const std::string& text) {
  const PcdHeader h = parse_pcd_header(path, text);
  const std::size_t n = static_cast<std::size_t>(h.points);  // < 2^31
  if (h.data == "binary") return h.data_start + n * h.point_size;
  if (h.data == "binary_compressed") {
    if (text.size() < h.data_start + 8) return h.data_start + 8;  // read_pcd_data says truncated
    return h.data_start + 8 +
           load<std::uint32_t>(reinterpret_cast<const unsigned char*>(text.data()) + h.data_start);
  }
  return h.data_start + n * (h.values_per_line + 1) * 128 + kPcdHeaderBytes;
}

Frame read_pcd_data(const std::string& path, const std::string& text,
                    const std::string& label_field) {
  const PcdHeader h = parse_pcd_header(path, text);
  const PcdFields fields = pcd_fields(path, h, label_field);
  Frame frame;
  frame.width = static_cast<int>(h.width);
  frame.height = static_cast<int>(h.height);
  if (h.data == "ascii")
    read_pcd_ascii(path, text, h, fields, frame);
  else
    read_pcd_binary(path, text, h, fields, frame);
  if (frame.valid_count() == 0)
    fail(path, "has no valid points (all " + std::to_string(h.points) +
                   " points have NaN or infinite coordinates; expected at least one)");
  return frame;
}

}  // namespace

Frame read_pcd(const std::string& path, const std::string& label_field) {
  std::string text;
  return detail::read_pcd_from(
      path,
      [&](std::size_t n) -> const std::string& { return text = detail::read_input_file(path, n); },
      label_field);
}

namespace detail {

Frame read_pcd_from(const std::string& name,
                    const std::function<const std::string&(std::size_t)>& first,
                    const std::string& label_field) {
  // The header first; then only as many bytes as it promises (a file far longer than its header
  // says, or no PCD at all, is not read to its end).
  const std::string* text = &first(kPcdHeaderBytes);
  const std::size_t want = pcd_promised_bytes(name, *text);
  if (want > text->size()) text = &first(want);
  return read_pcd_data(name, *text, label_field);
}

}  // namespace detail

}  // namespace proxseg
