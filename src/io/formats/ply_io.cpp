// PLY reading: the header, then ascii or binary vertices, colours and faces, and the point cloud
// of the vertices (ply_io.hpp).
#include "io/formats/ply_io.hpp"

#include "io/formats/text_fields.hpp"
#include "io/reader_errors.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string_view>

namespace proxseg::detail {
namespace {

[[noreturn]] void bad(const std::string& what) {
  throw std::runtime_error(what);
}

enum class Type { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

bool type_of(std::string_view name, Type& t) {
  static const std::pair<std::string_view, Type> kNames[] = {
      {"char", Type::kI8},    {"int8", Type::kI8},     {"uchar", Type::kU8},
      {"uint8", Type::kU8},   {"short", Type::kI16},   {"int16", Type::kI16},
      {"ushort", Type::kU16}, {"uint16", Type::kU16},  {"int", Type::kI32},
      {"int32", Type::kI32},  {"uint", Type::kU32},    {"uint32", Type::kU32},
      {"float", Type::kF32},  {"float32", Type::kF32}, {"double", Type::kF64},
      {"float64", Type::kF64}};
  for (const auto& [n, type] : kNames)
    if (n == name) return t = type, true;
  return false;
}

std::size_t size_of(Type t) {
  switch (t) {
    case Type::kI8:
    case Type::kU8:
      return 1;
    case Type::kI16:
    case Type::kU16:
      return 2;
    case Type::kI32:
    case Type::kU32:
    case Type::kF32:
      return 4;
    case Type::kF64:
      return 8;
  }
  return 1;
}

struct Property {
  std::string name;
  Type type = Type::kF32;  // the value's, or a list's items'
  bool list = false;
  Type count_type = Type::kU8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Format { kAscii, kLittle, kBig };

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "binary PLY is read on little-endian");

// Reads values one by one from the body, ascii tokens or binary numbers.
class Body {
 public:
  Body(const std::string& bytes, std::size_t at, Format format)
      : data_(bytes), pos_(at), format_(format) {}

  std::size_t left() const { return data_.size() - pos_; }

  double value(Type t, const std::string& where) {
    if (format_ == Format::kAscii) return token(where);
    const std::size_t n = size_of(t);
    if (left() < n)
      bad(where + ": the file ends inside it (expected " + std::to_string(n) + " more bytes)");
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, n);
    pos_ += n;
    if (format_ == Format::kBig) std::reverse(b, b + n);  // this machine is little-endian
    switch (t) {
      case Type::kI8:
        return static_cast<std::int8_t>(b[0]);
      case Type::kU8:
        return b[0];
      case Type::kI16:
        return load<std::int16_t>(b);
      case Type::kU16:
        return load<std::uint16_t>(b);
      case Type::kI32:
        return load<std::int32_t>(b);
      case Type::kU32:
        return load<std::uint32_t>(b);
      case Type::kF32:
        return load<float>(b);
      case Type::kF64:
        return load<double>(b);
    }
    return 0;
  }

 private:
  template <class T>
  static T load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof v);
    return v;
  }

  double token(const std::string& where) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    if (pos_ == data_.size()) bad(where + ": the file ends inside it (expected a number)");
    const char* first = data_.data() + pos_;
    const char* end = data_.data() + data_.size();
    double v = 0;
    const auto [ptr, ec] = std::from_chars(first, end, v);
    if (ec == std::errc::result_out_of_range) {
      // Beyond double's range: infinite or zero, as strtod gives it.
      v = std::strtod(std::string(first, static_cast<std::size_t>(ptr - first)).c_str(), nullptr);
    } else if (ec != std::errc() ||
               (ptr != end && !std::isspace(static_cast<unsigned char>(*ptr)))) {
      std::size_t len = 0;
      while (first + len != end && !std::isspace(static_cast<unsigned char>(first[len])) &&
             len < 40)
        ++len;
      bad(where + ": '" + std::string(first, len) + "' is not a number");
    }
    pos_ = static_cast<std::size_t>(ptr - data_.data());
    return v;
  }

  const std::string& data_;
  std::size_t pos_;
  Format format_;
};

// The header: format, elements and their properties; `body` is where the data starts.
std::vector<Element> parse_header(const std::string& bytes, Format& format, std::size_t& body) {
  std::size_t pos = 0;
  auto next_line = [&](std::string_view& line) {
    if (pos >= bytes.size()) return false;
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) end = bytes.size();
    line = std::string_view(bytes).substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = end + 1;
    return true;
  };
  std::string_view line;
  if (!next_line(line) || line != "ply") bad("not a PLY file (expected the first line 'ply')");
  std::vector<Element> elements;
  bool have_format = false;
  for (int number = 2; next_line(line); ++number) {
    const std::string at = "header line " + std::to_string(number);
    const auto w = split_ws(line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      if (!have_format)
        bad("PLY header has no format line (expected 'format ascii 1.0' or binary)");
      body = std::min(pos, bytes.size());
      return elements;
    }
    if (w[0] == "format") {
      if (w.size() != 3 ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        bad(at + ": expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      format = w[1] == "ascii"                  ? Format::kAscii
               : w[1] == "binary_little_endian" ? Format::kLittle
                                                : Format::kBig;
      have_format = true;
    } else if (w[0] == "element") {
      std::uint64_t count = 0;
      const char* end = w.size() == 3 ? w[2].data() + w[2].size() : nullptr;
      if (w.size() != 3 || std::from_chars(w[2].data(), end, count).ptr != end)
        bad(at + ": expected 'element NAME COUNT' with a whole count");
      elements.push_back({std::string(w[1]), count, {}});
    } else if (w[0] == "property") {
      if (elements.empty()) bad(at + ": a property before any element");
      Property p;
      p.list = w.size() >= 2 && w[1] == "list";
      const bool ok = p.list ? w.size() == 5 && type_of(w[2], p.count_type) && type_of(w[3], p.type)
                             : w.size() == 3 && type_of(w[1], p.type);
      if (!ok)
        bad(at + ": expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME' " +
            "(types char uchar short ushort int uint float double)");
      p.name = std::string(w.back());
      elements.back().properties.push_back(p);
    } else {
      bad(at + ": unknown keyword '" + std::string(w[0].substr(0, 40)) + "'");
    }
    if (number > 100000) break;
  }
  bad("PLY header has no end_header line (expected a complete PLY header)");
}

int index_of(const Element& e, std::string_view name) {
  for (std::size_t i = 0; i < e.properties.size(); ++i)
    if (e.properties[i].name == name && !e.properties[i].list) return static_cast<int>(i);
  return -1;
}

// The index of the vertex property label_property (-1: none asked or none there); an error for
// a float or list property of that name.
int label_index(const Element& e, const std::string& label_property) {
  const int i = label_property.empty() ? -1 : index_of(e, label_property);
  if (i >= 0 && (e.properties[i].type == Type::kF32 || e.properties[i].type == Type::kF64))
    bad("PLY vertex property " + label_property +
        " is a float (expected an integer type for labels)");
  return i;
}

std::uint32_t label_value(double v, const std::string& where, const std::string& name) {
  if (!(v >= 0) || v > std::numeric_limits<std::uint32_t>::max() || v != std::floor(v))
    bad(where + ": " + name + " " +
        (std::fabs(v) < 1e15 && v == std::floor(v) ? std::to_string(static_cast<long long>(v))
                                                   : std::to_string(v)) +
        " (expected whole labels 0..2^32-1)");
  return static_cast<std::uint32_t>(v);
}

}  // namespace

PlyData parse_ply(const std::string& bytes, const std::string& label_property) {
  Format format = Format::kAscii;
  std::size_t start = 0;
  const std::vector<Element> elements = parse_header(bytes, format, start);
  Body body(bytes, start, format);
  PlyData out;
  bool have_vertex = false;
  for (const Element& e : elements) {
    // Every record takes at least a byte per property (binary: the fixed sizes; ascii: a digit
    // and a separator): a count beyond what is left is a broken header, refused before
    // anything of that size is allocated.
    std::uint64_t min_record = 0;
    for (const auto& p : e.properties)
      min_record += format == Format::kAscii ? 2 : size_of(p.list ? p.count_type : p.type);
    if (min_record > 0 && e.count > body.left() / min_record)
      bad("PLY header declares " + std::to_string(e.count) + " " + e.name +
          " records but the file has only " + std::to_string(body.left()) +
          " bytes of data (expected a complete file)");
    const bool vertex = e.name == "vertex" && !have_vertex;
    const bool face = e.name == "face" && out.triangles.empty();
    int x = -1, y = -1, z = -1, r = -1, g = -1, b = -1, l = -1, indices = -1;
    if (vertex) {
      have_vertex = true;
      x = index_of(e, "x"), y = index_of(e, "y"), z = index_of(e, "z");
      if (x < 0 || y < 0 || z < 0)
        bad("PLY vertex element has no x, y and z properties (expected all three)");
      r = index_of(e, "red"), g = index_of(e, "green"), b = index_of(e, "blue");
      out.vertices.resize(e.count);
      if (r >= 0 && g >= 0 && b >= 0) out.colours.resize(e.count);
      if ((l = label_index(e, label_property)) >= 0) out.labels.resize(e.count);
    }
    if (face)
      for (std::size_t i = 0; i < e.properties.size(); ++i)
        if (e.properties[i].list &&
            (e.properties[i].name == "vertex_indices" || e.properties[i].name == "vertex_index"))
          indices = static_cast<int>(i);
    std::vector<double> values(e.properties.size());
    std::vector<int> polygon;
    for (std::uint64_t n = 0; n < e.count; ++n) {
      const std::string where = e.name + " " + std::to_string(n);
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const Property& p = e.properties[i];
        if (!p.list) {
          values[i] = body.value(p.type, where);
          continue;
        }
        const double count = body.value(p.count_type, where);
        if (!(count >= 0) || count != std::floor(count) || count > 1e6)
          bad(where + ": list length " + std::to_string(count) + " (expected 0..10^6)");
        if (static_cast<int>(i) == indices) polygon.clear();
        for (int k = 0; k < static_cast<int>(count); ++k) {
          const double v = body.value(p.type, where);
          if (static_cast<int>(i) != indices) continue;
          if (!(v >= 0) || v > std::numeric_limits<int>::max() || v != std::floor(v))
            bad(where + ": vertex index " + std::to_string(v) + " (expected a whole number >= 0)");
          polygon.push_back(static_cast<int>(v));
        }
      }
      if (vertex) {
        out.vertices[n] = {values[x], values[y], values[z]};
        if (!out.colours.empty()) out.colours[n] = {values[r], values[g], values[b]};
        if (l >= 0) out.labels[n] = label_value(values[l], where, label_property);
      }
      if (face && indices >= 0)
        for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
          out.triangles.emplace_back(polygon[0], polygon[k], polygon[k + 1]);
    }
  }
  if (!have_vertex) bad("PLY has no vertex element (expected 'element vertex N')");
  return out;
}

// Colours as Open3D's reader gave them (the stored value / 255, then back to 0..255).
Frame ply_cloud(const std::string& path, const PlyData& ply) {
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
  frame.label = ply.labels;  // the label property asked for, if any
  if (frame.valid_count() == 0)
    fail(path, "has no valid points (all vertices have NaN or infinite coordinates)");
  return frame;
}

}  // namespace proxseg::detail
