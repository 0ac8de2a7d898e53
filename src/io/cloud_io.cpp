// Readers and writers for frames. PCD is parsed here (Open3D's reader drops WIDTH/HEIGHT and
// the label field); PLY goes through Open3D, PNG/JPEG images through libpng/libjpeg
// (image_io.cpp), JSON through nlohmann::json.
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/obj_io.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <sstream>
#include <string_view>

#include "image_io.hpp"
#include "input_file.hpp"
#include "lzf.hpp"
#include "ply_io.hpp"
#include "text_fields.hpp"

namespace fs = std::filesystem;

namespace proxseg {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw InputError(path + ": " + what);
}
// The same for a file the system refuses (missing, unreadable, unwritable).
[[noreturn]] void fail_file(const std::string& path, const std::string& what) {
  throw FileError(path + ": " + what);
}

// Makes text from a file safe to quote in a one-line message.
std::string quote(std::string_view s, std::size_t max_len = 60) {
  std::string out;
  for (char c : s.substr(0, max_len)) {
    const auto u = static_cast<unsigned char>(c);
    out += (u >= 32 && u < 127) ? c : '?';
  }
  if (s.size() > max_len) out += "...";
  return "'" + out + "'";
}

std::string num(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

// Checks that path names a regular file (FileError otherwise: missing, a folder, a FIFO, ...).
void require_file(const std::string& path) {
  detail::require_regular_file(path);
}

std::string read_whole_file(const std::string& path) {
  return detail::read_input_file(path);
}

// ---------------------------------------------------------------------------------------------
// PCD

struct PcdField {
  std::string name;
  char type = 0;                // 'F', 'U', 'I'
  int size = 0;                 // bytes per element: 1, 2, 4, 8
  std::size_t count = 1;        // elements
  std::size_t offset = 0;       // byte offset of the field within a point
  std::size_t value_index = 0;  // index of the field's first value on an ascii line
};

// The line of `all` that starts at pos (without its '\n'); pos moves to the next line.
std::string_view next_line(std::string_view all, std::size_t& pos) {
  std::size_t end = all.find('\n', pos);
  if (end == std::string_view::npos) end = all.size();
  const std::string_view line = all.substr(pos, end - pos);
  pos = end < all.size() ? end + 1 : end;
  return line;
}

using detail::split_ws;

bool parse_u64(std::string_view s, std::uint64_t& v) {
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool parse_double(std::string_view s, double& v) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool parse_float(std::string_view s, float& v) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

template <typename T>
T load(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

// Reads one binary element as a double (x, y, z).
double load_number(const unsigned char* p, char type, int size) {
  if (type == 'F') return size == 8 ? load<double>(p) : static_cast<double>(load<float>(p));
  if (type == 'U') {
    switch (size) {
      case 1:
        return load<std::uint8_t>(p);
      case 2:
        return load<std::uint16_t>(p);
      case 4:
        return load<std::uint32_t>(p);
      default:
        return static_cast<double>(load<std::uint64_t>(p));
    }
  }
  switch (size) {
    case 1:
      return load<std::int8_t>(p);
    case 2:
      return load<std::int16_t>(p);
    case 4:
      return load<std::int32_t>(p);
    default:
      return static_cast<double>(load<std::int64_t>(p));
  }
}

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t width = 0, height = 0, points = 0;
  bool has_points = false;
  std::string data;            // ascii, binary, binary_compressed
  std::size_t data_start = 0;  // byte offset of the data in the file
  std::size_t data_line = 0;   // 1-based line number of the DATA line
  std::size_t point_size = 0;  // bytes per point
  std::size_t values_per_line = 0;
};

PcdHeader parse_pcd_header(const std::string& path, const std::string& text) {
  PcdHeader h;
  std::vector<std::string_view> names, sizes, types, counts;
  bool have_fields = false, have_size = false, have_type = false, have_count = false,
       have_width = false, have_height = false, have_data = false;
  std::vector<std::string> seen;
  std::size_t pos = 0, line_no = 0;
  const std::string_view all(text);
  while (pos < all.size() && !have_data) {
    const std::string_view line = next_line(all, pos);
    ++line_no;
    const auto tok = split_ws(line);
    if (tok.empty() || tok[0][0] == '#') continue;
    const std::string key(tok[0]);
    const std::string where = "header line " + std::to_string(line_no) + " ";
    auto bad = [&](const std::string& expected) {
      fail(path, where + quote(line) + " is invalid (expected " + expected + ")");
    };
    if (std::find(seen.begin(), seen.end(), key) != seen.end())
      fail(path, where + "repeats " + key + " (expected each header keyword once)");
    seen.push_back(key);
    const std::vector<std::string_view> args(tok.begin() + 1, tok.end());
    auto one_uint = [&](const char* what) {
      std::uint64_t v = 0;
      if (args.size() != 1 || !parse_u64(args[0], v)) bad(std::string(what));
      if (v > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
        fail(path, where + key + " " + std::string(args[0]) +
                       " is too large (expected at most 2147483647, 2^31 - 1)");
      return v;
    };
    if (key == "VERSION") {
      if (args.size() != 1) bad("VERSION <number>");
    } else if (key == "FIELDS") {
      if (args.empty()) bad("FIELDS <name>...");
      names = args;
      have_fields = true;
    } else if (key == "SIZE") {
      sizes = args;
      have_size = true;
    } else if (key == "TYPE") {
      types = args;
      have_type = true;
    } else if (key == "COUNT") {
      counts = args;
      have_count = true;
    } else if (key == "WIDTH") {
      h.width = one_uint("WIDTH <non-negative integer>");
      have_width = true;
    } else if (key == "HEIGHT") {
      h.height = one_uint("HEIGHT <positive integer>");
      if (h.height == 0) bad("HEIGHT <positive integer>");
      have_height = true;
    } else if (key == "VIEWPOINT") {
      double d;
      if (args.size() != 7 || !std::all_of(args.begin(), args.end(),
                                           [&](std::string_view a) { return parse_double(a, d); }))
        bad("VIEWPOINT with 7 numbers");
    } else if (key == "POINTS") {
      h.points = one_uint("POINTS <non-negative integer>");
      h.has_points = true;
    } else if (key == "DATA") {
      if (args.size() != 1) bad("DATA ascii, binary or binary_compressed");
      h.data = std::string(args[0]);
      if (h.data != "ascii" && h.data != "binary" && h.data != "binary_compressed")
        fail(path, where + "has unknown DATA type " + quote(args[0]) +
                       " (expected ascii, binary or binary_compressed)");
      have_data = true;
      h.data_start = pos;
      h.data_line = line_no;
    } else {
      bad("a PCD header keyword: VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, "
          "POINTS or DATA");
    }
  }
  if (!have_data) {
    if (line_no == 0) fail(path, "empty file (expected a PCD header)");
    fail(path, "header has no DATA line (expected DATA ascii, binary or binary_compressed)");
  }
  const char* missing = !have_fields   ? "FIELDS"
                        : !have_size   ? "SIZE"
                        : !have_type   ? "TYPE"
                        : !have_width  ? "WIDTH"
                        : !have_height ? "HEIGHT"
                                       : nullptr;
  if (missing)
    fail(path, std::string("header has no ") + missing + " line (expected it before DATA)");
  const std::size_t n = names.size();
  auto check_len = [&](const char* key, std::size_t len) {
    if (len != n)
      fail(path, std::string("header ") + key + " has " + std::to_string(len) +
                     " values but FIELDS has " + std::to_string(n) +
                     " names (expected one per field)");
  };
  check_len("SIZE", sizes.size());
  check_len("TYPE", types.size());
  if (have_count) check_len("COUNT", counts.size());

  std::size_t offset = 0, value_index = 0;
  for (std::size_t i = 0; i < n; ++i) {
    PcdField f;
    f.name = std::string(names[i]);
    std::uint64_t v = 0;
    if (!parse_u64(sizes[i], v) || (v != 1 && v != 2 && v != 4 && v != 8))
      fail(path, "field " + f.name + " has SIZE " + quote(sizes[i]) + " (expected 1, 2, 4 or 8)");
    f.size = static_cast<int>(v);
    if (types[i] != "F" && types[i] != "U" && types[i] != "I")
      fail(path, "field " + f.name + " has TYPE " + quote(types[i]) + " (expected F, U or I)");
    f.type = types[i][0];
    if (f.type == 'F' && f.size != 4 && f.size != 8)
      fail(path, "field " + f.name + " is TYPE F with SIZE " + std::to_string(f.size) +
                     " (expected SIZE 4 or 8 for F)");
    if (have_count) {
      if (!parse_u64(counts[i], v) || v == 0 || v > (1u << 20))
        fail(path, "field " + f.name + " has COUNT " + quote(counts[i]) +
                       " (expected a positive integer)");
      f.count = static_cast<std::size_t>(v);
    }
    f.offset = offset;
    f.value_index = value_index;
    offset += f.count * static_cast<std::size_t>(f.size);
    value_index += f.count;
    h.fields.push_back(f);
  }
  h.point_size = offset;
  h.values_per_line = value_index;

  const std::uint64_t wh = h.width * h.height;  // both <= INT_MAX: no overflow
  if (!h.has_points) h.points = wh;
  if (h.points != wh)
    fail(path, "POINTS " + std::to_string(h.points) + " but WIDTH*HEIGHT = " +
                   std::to_string(h.width) + "*" + std::to_string(h.height) + " = " +
                   std::to_string(wh) + " (expected POINTS = WIDTH*HEIGHT)");
  if (wh > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
    fail(path, "WIDTH*HEIGHT = " + std::to_string(wh) + " is too large (expected < 2^31 points)");
  return h;
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
      if (!parse_double(tok[c->value_index], v))
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
        if (!parse_float(ct, c))
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

// Number check for JSON readers.
double json_number(const std::string& path, const nlohmann::json& j, const char* name) {
  if (!j.is_number())
    fail(path, std::string("field \"") + name + "\" is " + j.type_name() + " (expected a number)");
  const double v = j.get<double>();
  if (!std::isfinite(v))
    fail(path, std::string("field \"") + name + "\" is not finite (expected a number)");
  return v;
}

nlohmann::json read_json(const std::string& path) {
  const std::string text = read_whole_file(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    fail(path, "invalid JSON (" + one_line(e.what()) + ")");
  }
}

void check_intrinsics(const std::string& path, const Intrinsics& k) {
  auto positive = [&](const char* name, double v) {
    if (!(v > 0) || !std::isfinite(v))
      fail(path, std::string("field \"") + name + "\" is " + num(v) + " (expected a number > 0)");
  };
  positive("fx", k.fx);
  positive("fy", k.fy);
  positive("depth_scale", k.depth_scale);
  if (!std::isfinite(k.cx) || !std::isfinite(k.cy))
    fail(path, "cx or cy is not finite (expected numbers)");
}

std::string mat_kind(const cv::Mat& m) {
  std::string d;
  switch (m.depth()) {
    case CV_8U:
      d = "8-bit";
      break;
    case CV_8S:
      d = "8-bit signed";
      break;
    case CV_16U:
      d = "16-bit";
      break;
    case CV_16S:
      d = "16-bit signed";
      break;
    case CV_32S:
      d = "32-bit integer";
      break;
    case CV_32F:
      d = "32-bit float";
      break;
    default:
      d = "64-bit float";
      break;
  }
  return d + " " + std::to_string(m.channels()) + "-channel";
}

// Larger images are refused from their header, before anything is decoded or allocated (a
// 16-bit 8192 x 8192 depth image is 128 MiB).
constexpr std::uint64_t kMaxImagePixels = std::uint64_t{8192} * 8192;

// PNG or JPEG through libpng / libjpeg (image_io.cpp), as cv::imread(IMREAD_UNCHANGED) gives it.
cv::Mat read_image(const std::string& path) {
  require_file(path);
  try {
    return detail::read_image_file(path, kMaxImagePixels);
  } catch (const std::runtime_error& e) {
    fail(path, one_line(e.what()));
  }
}

std::string size_str(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

}  // namespace

Frame read_pcd(const std::string& path, const std::string& label_field) {
  // The header first; then only as many bytes as it promises (a file far longer than its header
  // says, or no PCD at all, is not read to its end).
  std::string text = detail::read_input_file(path, kPcdHeaderBytes);
  const std::size_t want = pcd_promised_bytes(path, text);
  if (want > text.size()) text = detail::read_input_file(path, want);
  return read_pcd_data(path, text, label_field);
}

// Colours as Open3D's reader gave them (the stored value / 255, then back to 0..255).
Frame read_ply(const std::string& path) {
  require_file(path);
  detail::PlyData ply;
  try {
    ply = detail::parse_ply(read_whole_file(path));
  } catch (const std::runtime_error& e) {
    fail(path, one_line(e.what()));
  }
  if (ply.vertices.empty()) fail(path, "PLY has no vertices (expected at least one point)");
  if (ply.vertices.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    fail(path, "PLY has too many vertices (expected < 2^31)");
  Frame frame;
  const std::size_t n = ply.vertices.size();
  frame.width = static_cast<int>(n);
  frame.height = 1;
  frame.xyz.resize(n);
  frame.rgb.resize(ply.colours.empty() ? 0 : n);  // no colours: an XYZ-only cloud
  auto to_u8 = [](double stored) {
    const double c = stored / 255.0;
    if (!(c > 0)) return std::uint8_t{0};
    if (c >= 1) return std::uint8_t{255};
    return static_cast<std::uint8_t>(std::lround(c * 255.0));
  };
  for (std::size_t i = 0; i < n; ++i) frame.xyz[i] = ply.vertices[i].cast<float>();
  for (std::size_t i = 0; i < frame.rgb.size(); ++i) {
    const auto& c = ply.colours[i];
    frame.rgb[i] = {to_u8(c[0]), to_u8(c[1]), to_u8(c[2])};
  }
  if (frame.valid_count() == 0)
    fail(path, "has no valid points (all vertices have NaN or infinite coordinates)");
  return frame;
}

Frame read_point_cloud(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".pcd") return read_pcd(path);
  if (ext == ".ply") return read_ply(path);
  if (ext.empty()) fail(path, "has no file extension (expected .pcd or .ply)");
  fail(path, "unknown extension " + quote(ext) + " (expected .pcd or .ply)");
}

Mesh read_mesh(const std::string& path, double scale) {
  if (!(scale > 0) || !std::isfinite(scale)) fail(path, "mesh scale must be a positive number");
  require_file(path);
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".obj") return read_obj(path, scale);  // textured: obj_io.hpp
  if (ext != ".ply")
    fail(path, "unknown mesh extension " + quote(ext) + " (expected .ply or .obj)");
  detail::PlyData ply;
  try {
    ply = detail::parse_ply(read_whole_file(path));
  } catch (const std::runtime_error& e) {
    fail(path, one_line(e.what()));
  }
  if (ply.vertices.empty() || ply.triangles.empty())
    fail(path, "mesh has " + std::to_string(ply.vertices.size()) + " vertices and " +
                   std::to_string(ply.triangles.size()) + " faces (expected both)");
  Mesh m;
  const int n = static_cast<int>(ply.vertices.size());
  m.vertices.reserve(n);
  for (const auto& v : ply.vertices) {
    if (!v.allFinite()) fail(path, "mesh has a vertex with NaN or infinite coordinates");
    m.vertices.push_back((v * scale).cast<float>());
  }
  const bool coloured = ply.colours.size() == ply.vertices.size();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d c =
        coloured
            ? Eigen::Vector3d(
                  (Eigen::Vector3d(ply.colours[i][0], ply.colours[i][1], ply.colours[i][2]) / 255.0)
                      .cwiseMax(0.0)
                      .cwiseMin(1.0) *
                  255.0)
            : Eigen::Vector3d(128, 128, 128);
    m.colours.push_back({static_cast<std::uint8_t>(std::lround(c.x())),
                         static_cast<std::uint8_t>(std::lround(c.y())),
                         static_cast<std::uint8_t>(std::lround(c.z()))});
  }
  for (const auto& t : ply.triangles) {
    if ((t.array() < 0).any() || (t.array() >= n).any())
      fail(path, "mesh has a face with a vertex index outside 0.." + std::to_string(n - 1));
    m.triangles.push_back(t);
  }
  return m;
}

std::vector<Eigen::Vector3d> read_xyz(const std::string& path) {
  std::istringstream in(read_whole_file(path));
  std::vector<Eigen::Vector3d> points;
  std::string line;
  for (long number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    Eigen::Vector3d p;
    std::string extra;
    if (!(fields >> p.x() >> p.y() >> p.z()) || (fields >> extra) || !p.allFinite())
      fail(path, "line " + std::to_string(number) + ": " + quote(line) +
                     " is invalid (expected three finite numbers x y z)");
    points.push_back(p);
  }
  if (points.empty()) fail(path, "has no points (expected lines of x y z in metres)");
  return points;
}

Intrinsics read_intrinsics(const std::string& path) {
  const nlohmann::json j = read_json(path);
  if (!j.is_object())
    fail(path, std::string("top level is ") + j.type_name() +
                   " (expected an object with fx, fy, cx, cy, depth_scale)");
  Intrinsics k;
  auto get = [&](const char* name, double& out, bool required) {
    if (!j.contains(name)) {
      if (required) fail(path, std::string("missing field \"") + name + "\" (expected a number)");
      return;
    }
    out = json_number(path, j.at(name), name);
  };
  get("fx", k.fx, true);
  get("fy", k.fy, true);
  get("cx", k.cx, true);
  get("cy", k.cy, true);
  get("depth_scale", k.depth_scale, false);
  check_intrinsics(path, k);
  return k;
}

Intrinsics read_ycb_meta(const std::string& path) {
  const nlohmann::json j = read_json(path);
  if (!j.is_object()) fail(path, "top level is not an object (expected YCB-Video meta JSON)");
  if (!j.contains("intrinsic_matrix"))
    fail(path, "missing field \"intrinsic_matrix\" (expected a 3x3 array)");
  const auto& m = j.at("intrinsic_matrix");
  auto row_ok = [](const nlohmann::json& r) {
    return r.is_array() && r.size() == 3 &&
           std::all_of(r.begin(), r.end(), [](const nlohmann::json& v) { return v.is_number(); });
  };
  if (!m.is_array() || m.size() != 3 || !std::all_of(m.begin(), m.end(), row_ok))
    fail(path,
         "field \"intrinsic_matrix\" is not a 3x3 array of numbers (expected "
         "[[fx,0,cx],[0,fy,cy],[0,0,1]])");
  if (!j.contains("factor_depth"))
    fail(path, "missing field \"factor_depth\" (expected a number or [[number]])");
  const nlohmann::json* fd = &j.at("factor_depth");
  while (fd->is_array() && fd->size() == 1) fd = &(*fd)[0];
  Intrinsics k;
  k.fx = json_number(path, m[0][0], "intrinsic_matrix");
  k.cx = json_number(path, m[0][2], "intrinsic_matrix");
  k.fy = json_number(path, m[1][1], "intrinsic_matrix");
  k.cy = json_number(path, m[1][2], "intrinsic_matrix");
  k.depth_scale = json_number(path, *fd, "factor_depth");
  if (!(k.depth_scale > 0))
    fail(path, "field \"factor_depth\" is " + num(k.depth_scale) + " (expected > 0)");
  check_intrinsics(path, k);
  return k;
}

std::vector<std::uint8_t> read_label_image(const std::string& path, int width, int height) {
  const cv::Mat m = read_image(path);
  if (m.type() != CV_8UC1 || m.cols != width || m.rows != height)
    fail(path, "label image is " + mat_kind(m) + " " + size_str(m) +
                   " (expected 8-bit one-channel " + std::to_string(width) + "x" +
                   std::to_string(height) + ", the size of the frame)");
  std::vector<std::uint8_t> labels(static_cast<std::size_t>(width) * height);
  for (int r = 0; r < height; ++r)
    std::memcpy(labels.data() + static_cast<std::size_t>(r) * width, m.ptr<std::uint8_t>(r), width);
  return labels;
}

LabelImage read_label_png(const std::string& path) {
  const cv::Mat m = read_image(path);
  if (m.type() != CV_8UC1 && m.type() != CV_16UC1)
    fail(path, "label image is " + mat_kind(m) + " " + size_str(m) +
                   " (expected an 8- or 16-bit one-channel PNG)");
  // read_image takes JPEGs too: their lossy grey values are no labels.
  std::ifstream in(path, std::ios::binary);
  char signature[8] = {};
  in.read(signature, sizeof signature);
  if (!in || std::memcmp(signature, "\x89PNG\r\n\x1a\n", 8) != 0)
    fail(path, "label image is not a PNG (expected an 8- or 16-bit one-channel PNG)");
  LabelImage out;
  out.width = m.cols;
  out.height = m.rows;
  out.values.resize(static_cast<std::size_t>(m.cols) * m.rows);
  std::uint32_t* to = out.values.data();
  for (int r = 0; r < m.rows; ++r, to += m.cols) {
    if (m.depth() == CV_8U)
      std::copy_n(m.ptr<std::uint8_t>(r), m.cols, to);
    else
      std::copy_n(m.ptr<std::uint16_t>(r), m.cols, to);
  }
  return out;
}

Frame read_rgbd(const std::string& color_path, const std::string& depth_path, const Intrinsics& k) {
  check(k);
  const cv::Mat color = read_image(color_path);
  const cv::Mat depth = read_image(depth_path);
  if (color.depth() != CV_8U ||
      (color.channels() != 1 && color.channels() != 3 && color.channels() != 4))
    fail(color_path, "colour image is " + mat_kind(color) +
                         " (expected 8-bit grey, 3-channel colour or 4-channel colour+alpha)");
  if (depth.depth() != CV_16U || depth.channels() != 1)
    fail(depth_path, "depth image is " + mat_kind(depth) + " (expected 16-bit 1-channel)");
  if (color.size() != depth.size())
    fail(depth_path, "depth image is " + size_str(depth) + " but colour image " + color_path +
                         " is " + size_str(color) + " (expected the same size)");
  Frame frame;
  frame.width = color.cols;
  frame.height = color.rows;
  const cv::Mat dense = depth.isContinuous() ? depth : depth.clone();
  frame.xyz = back_project(dense.ptr<std::uint16_t>(0), depth.cols, depth.rows, k);
  frame.rgb.resize(frame.xyz.size());
  const int ch = color.channels();
  for (int v = 0; v < color.rows; ++v) {
    const auto* crow = color.ptr<std::uint8_t>(v);
    for (int u = 0; u < color.cols; ++u) {
      const std::uint8_t* c = crow + static_cast<std::size_t>(u) * ch;
      frame.rgb[static_cast<std::size_t>(v) * color.cols + u] =
          ch == 1 ? Rgb{c[0], c[0], c[0]} : Rgb{c[2], c[1], c[0]};  // BGR(A) -> RGB
    }
  }
  if (frame.valid_count() == 0)
    fail(depth_path, "has no valid depth (all pixels are 0; expected some depth > 0)");
  return frame;
}

namespace {

// The data of a binary_compressed PCD: compressed size, uncompressed size (uint32 each), then
// the LZF of the fields one after another (x of every point, then y, ..., then each extra field),
// the layout PCL defined: values of one field side by side compress far better than whole points.
// DATA binary_compressed after `header`: the compressed and uncompressed sizes, then the LZF of
// the fields one after another (x of every point, then y, ...). The buffers are not cleared
// before they are filled: on a one-frame process every fresh page costs a fault, and zeroing
// them touched each twice.
std::string compressed_pcd(std::string header, const Frame& frame,
                           const std::vector<PointField>& fields) {
  const std::size_t n = frame.xyz.size();
  const bool coloured = frame.coloured();
  const std::size_t field_count = 3 + (coloured ? 1 : 0) + fields.size();
  const std::size_t raw_size = 4 * n * field_count;
  if (raw_size > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("write_pcd: " + std::to_string(raw_size) +
                                " bytes of point data do not fit binary_compressed (at most "
                                "4 GiB; write DATA binary)");
  const std::unique_ptr<unsigned char[]> raw(new unsigned char[raw_size]);
  unsigned char* out = raw.get();
  for (int k = 0; k < 3; ++k)
    for (std::size_t i = 0; i < n; ++i, out += 4) std::memcpy(out, &frame.xyz[i][k], 4);
  if (coloured)
    for (std::size_t i = 0; i < n; ++i, out += 4) {
      const auto& c = frame.rgb[i];
      const std::uint32_t packed = (std::uint32_t{c[0]} << 16) | (std::uint32_t{c[1]} << 8) | c[2];
      std::memcpy(out, &packed, 4);
    }
  for (const auto& f : fields) {
    if (n > 0) std::memcpy(out, f.values.data(), 4 * n);
    out += 4 * n;
  }
  const std::unique_ptr<unsigned char[]> lzf(new unsigned char[detail::lzf_bound(raw_size)]);
  const std::size_t lzf_size = detail::lzf_compress(raw.get(), raw_size, lzf.get());
  if (lzf_size > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument(
        "write_pcd: compressed point data does not fit binary_compressed "
        "(at most 4 GiB; write DATA binary)");
  const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(lzf_size),
                                  static_cast<std::uint32_t>(raw_size)};
  header += "binary_compressed\n";
  std::string bytes;
  bytes.reserve(header.size() + sizeof sizes + lzf_size);
  bytes += header;
  bytes.append(reinterpret_cast<const char*>(sizes), sizeof sizes);
  bytes.append(reinterpret_cast<const char*>(lzf.get()), lzf_size);
  return bytes;
}

}  // namespace

std::string pcd_bytes(const Frame& frame, const std::vector<PointField>& fields, PcdData data) {
  const std::size_t n = frame.xyz.size();
  const bool coloured = frame.coloured();  // else x y z only: no made-up colour in the file
  if (coloured && frame.rgb.size() != n)
    throw std::invalid_argument("write_pcd: frame has " + std::to_string(n) + " points but " +
                                std::to_string(frame.rgb.size()) + " colours");
  if (frame.width < 0 || frame.height < 1 ||
      static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height) != n)
    throw std::invalid_argument("write_pcd: frame is " + std::to_string(frame.width) + "x" +
                                std::to_string(frame.height) + " but has " + std::to_string(n) +
                                " points");
  std::vector<std::string> names = {"x", "y", "z"};
  if (coloured) names.push_back("rgb");
  const std::size_t own = names.size();  // fields before the extra ones
  for (const auto& f : fields) {
    const bool ok_name =
        !f.name.empty() && std::all_of(f.name.begin(), f.name.end(),
                                       [](unsigned char c) { return std::isalnum(c) || c == '_'; });
    if (!ok_name)
      throw std::invalid_argument("write_pcd: field name '" + f.name +
                                  "' is not a PCD field name (letters, digits, _)");
    if (std::find(names.begin(), names.end(), f.name) != names.end())
      throw std::invalid_argument("write_pcd: field name '" + f.name + "' is used twice");
    // Even without colours: read_pcd would take such a field for the packed colour.
    if (f.name == "rgb" || f.name == "rgba")
      throw std::invalid_argument("write_pcd: field name '" + f.name + "' is the colour's");
    if (f.values.size() != n)
      throw std::invalid_argument("write_pcd: field '" + f.name + "' has " +
                                  std::to_string(f.values.size()) + " values for " +
                                  std::to_string(n) + " points");
    names.push_back(f.name);
  }
  std::string header = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS";
  for (const auto& nm : names) header += " " + nm;
  header += "\nSIZE";
  for (std::size_t i = 0; i < names.size(); ++i) header += " 4";
  header += "\nTYPE";
  for (std::size_t i = 0; i < names.size(); ++i) header += i < own ? " F" : " U";
  header += "\nCOUNT";
  for (std::size_t i = 0; i < names.size(); ++i) header += " 1";
  header += "\nWIDTH " + std::to_string(frame.width) + "\nHEIGHT " + std::to_string(frame.height) +
            "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(n) + "\nDATA ";
  if (data == PcdData::kBinaryCompressed) return compressed_pcd(std::move(header), frame, fields);
  header += "binary\n";
  const std::size_t point_size = 4 * names.size();
  std::string bytes = header;
  bytes.resize(header.size() + n * point_size);
  char* out = bytes.data() + header.size();
  for (std::size_t i = 0; i < n; ++i, out += point_size) {
    std::memcpy(out, frame.xyz[i].data(), 12);
    if (coloured) {
      const auto& c = frame.rgb[i];
      const std::uint32_t packed = (std::uint32_t{c[0]} << 16) | (std::uint32_t{c[1]} << 8) | c[2];
      std::memcpy(out + 12, &packed, 4);  // same bits as PCL's packed float rgb
    }
    for (std::size_t f = 0; f < fields.size(); ++f)
      std::memcpy(out + 4 * (own + f), &fields[f].values[i], 4);
  }
  return bytes;
}

void write_pcd(const std::string& path, const Frame& frame, const std::vector<PointField>& fields,
               PcdData data) {
  write_file_atomic(path, pcd_bytes(frame, fields, data));
}

namespace {

// The first half of an atomic write: bytes in a temporary file beside path, flushed to disk.
// Returns the temporary file's path; the caller renames it over path (or removes it).
fs::path write_beside(const std::string& path, const std::string& bytes) {
  const fs::path target(path);
  if (!target.has_filename())
    fail_file(path, "cannot write (the path names a directory, expected a file name)");
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    fail_file(path, "cannot write (directory " + dir.string() + " does not exist)");
  static std::atomic<unsigned> counter{0};
  const fs::path tmp = dir / ("." + target.filename().string() + ".tmp." +
                              std::to_string(::getpid()) + "." + std::to_string(counter++));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) fail_file(path, std::string("cannot write (") + std::strerror(errno) + ")");
  auto give_up = [&](const std::string& reason) {
    ::close(fd);
    std::error_code ignore;
    fs::remove(tmp, ignore);
    fail_file(path, "cannot write (" + reason + ")");
  };
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0) {
      if (errno == EINTR) continue;
      give_up(std::strerror(errno));
    }
    done += static_cast<std::size_t>(w);
  }
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) give_up(std::strerror(errno));
  if (::close(fd) != 0) {
    const std::string reason = std::strerror(errno);
    std::error_code ignore;
    fs::remove(tmp, ignore);
    fail_file(path, "cannot write (" + reason + ")");
  }
  return tmp;
}

}  // namespace

void write_file_atomic(const std::string& path, const std::string& bytes) {
  const fs::path tmp = write_beside(path, bytes);
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignore;
    fs::remove(tmp, ignore);
    fail_file(path, "cannot write (" + ec.message() + ")");
  }
}

void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files) {
  // A directory in the way would only show at its rename, after the others had replaced their
  // targets: refused before anything is written.
  for (const auto& [path, bytes] : files) {
    std::error_code ec;
    if (fs::is_directory(path, ec))
      fail_file(path, "cannot write (a directory of that name exists)");
  }
  std::vector<fs::path> temps;
  std::size_t renamed = 0;
  try {
    for (const auto& [path, bytes] : files) temps.push_back(write_beside(path, bytes));
    for (; renamed < files.size(); ++renamed) {
      std::error_code ec;
      fs::rename(temps[renamed], files[renamed].first, ec);
      if (ec) fail_file(files[renamed].first, "cannot write (" + ec.message() + ")");
    }
  } catch (...) {
    // Every file not yet in place goes, and so do the new ones already in place: never a set
    // of which some files are new and others missing.
    std::error_code ignore;
    for (std::size_t i = 0; i < temps.size(); ++i)
      fs::remove(i < renamed ? fs::path(files[i].first) : temps[i], ignore);
    throw;
  }
}

}  // namespace proxseg
