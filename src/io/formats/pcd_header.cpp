// The PCD header (pcd_header.hpp): its lines read through a table of the keywords, then the field
// table built from FIELDS, SIZE, TYPE and COUNT and the point count checked against WIDTH and
// HEIGHT. Parsed here rather than by Open3D, whose reader drops WIDTH/HEIGHT and the label field.
#include "io/formats/pcd_header.hpp"

#include <algorithm>
#include <iterator>
#include <limits>

#include "io/formats/text_fields.hpp"
#include "io/formats/text_numbers.hpp"
#include "io/reader_errors.hpp"

namespace proxseg::detail {

std::string_view next_line(std::string_view all, std::size_t& pos) {
  std::size_t end = all.find('\n', pos);
  if (end == std::string_view::npos) end = all.size();
  const std::string_view line = all.substr(pos, end - pos);
  pos = end < all.size() ? end + 1 : end;
  return line;
}

namespace {

// The header as its lines give it: the values of FIELDS, SIZE, TYPE and COUNT (views into the
// file's text) until the field table is built from them, and the keywords seen so far.
struct HeaderLines {
  PcdHeader h;
  std::vector<std::string_view> names, sizes, types, counts;
  std::vector<std::string> seen;
  bool has(std::string_view key) const {
    return std::find(seen.begin(), seen.end(), key) != seen.end();
  }
};

// One header line: its keyword and values, where it is, and where the line after it starts.
struct HeaderLine {
  const std::string& path;
  std::string_view line;
  std::string key;
  std::vector<std::string_view> args;
  std::string where;  // "header line N "
  std::size_t line_no = 0, next = 0;

  [[noreturn]] void bad(const std::string& expected) const {
    fail(path, where + quote(line) + " is invalid (expected " + expected + ")");
  }
  // The one value of WIDTH, HEIGHT or POINTS: an integer small enough for an int.
  std::uint64_t one_uint(const char* what) const {
    std::uint64_t v = 0;
    if (args.size() != 1 || !parse_u64(args[0], v)) bad(std::string(what));
    if (v > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
      fail(path, where + key + " " + std::string(args[0]) +
                     " is too large (expected at most 2147483647, 2^31 - 1)");
    return v;
  }
};

// The header keywords and what each one's line holds.
struct Keyword {
  const char* name;
  void (*read)(const HeaderLine& line, HeaderLines& header);
};
const Keyword kKeywords[] = {
    {"VERSION",
     [](const HeaderLine& l, HeaderLines&) {
       if (l.args.size() != 1) l.bad("VERSION <number>");
     }},
    {"FIELDS",
     [](const HeaderLine& l, HeaderLines& r) {
       if (l.args.empty()) l.bad("FIELDS <name>...");
       r.names = l.args;
     }},
    {"SIZE", [](const HeaderLine& l, HeaderLines& r) { r.sizes = l.args; }},
    {"TYPE", [](const HeaderLine& l, HeaderLines& r) { r.types = l.args; }},
    {"COUNT", [](const HeaderLine& l, HeaderLines& r) { r.counts = l.args; }},
    {"WIDTH", [](const HeaderLine& l,
                 HeaderLines& r) { r.h.width = l.one_uint("WIDTH <non-negative integer>"); }},
    {"HEIGHT",
     [](const HeaderLine& l, HeaderLines& r) {
       r.h.height = l.one_uint("HEIGHT <positive integer>");
       if (r.h.height == 0) l.bad("HEIGHT <positive integer>");
     }},
    {"VIEWPOINT",
     [](const HeaderLine& l, HeaderLines&) {
       double d;
       if (l.args.size() != 7 ||
           !std::all_of(l.args.begin(), l.args.end(),
                        [&](std::string_view a) { return parse_number(a, d); }))
         l.bad("VIEWPOINT with 7 numbers");
     }},
    {"POINTS",
     [](const HeaderLine& l, HeaderLines& r) {
       r.h.points = l.one_uint("POINTS <non-negative integer>");
       r.h.has_points = true;
     }},
    {"DATA",
     [](const HeaderLine& l, HeaderLines& r) {
       if (l.args.size() != 1) l.bad("DATA ascii, binary or binary_compressed");
       r.h.data = std::string(l.args[0]);
       if (r.h.data != "ascii" && r.h.data != "binary" && r.h.data != "binary_compressed")
         fail(l.path, l.where + "has unknown DATA type " + quote(l.args[0]) +
                          " (expected ascii, binary or binary_compressed)");
       r.h.data_start = l.next;
       r.h.data_line = l.line_no;
     }},
};

// The header's lines up to DATA, the last one, each keyword once; line_no counts them.
HeaderLines read_header_lines(const std::string& path, const std::string& text,
                              std::size_t& line_no) {
  HeaderLines r;
  std::size_t pos = 0;
  const std::string_view all(text);
  while (pos < all.size() && !r.has("DATA")) {
    const std::string_view line = next_line(all, pos);
    ++line_no;
    const auto tok = split_ws(line);
    if (tok.empty() || tok[0][0] == '#') continue;
    const HeaderLine l{path,
                       line,
                       std::string(tok[0]),
                       {tok.begin() + 1, tok.end()},
                       "header line " + std::to_string(line_no) + " ",
                       line_no,
                       pos};
    if (r.has(l.key))
      fail(path, l.where + "repeats " + l.key + " (expected each header keyword once)");
    r.seen.push_back(l.key);
    const auto keyword = std::find_if(std::begin(kKeywords), std::end(kKeywords),
                                      [&](const Keyword& k) { return l.key == k.name; });
    if (keyword == std::end(kKeywords))
      l.bad(
          "a PCD header keyword: VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, "
          "POINTS or DATA");
    keyword->read(l, r);
  }
  return r;
}

// What a header must have had by its DATA line: the keywords the data needs, one SIZE, TYPE and
// COUNT value per field.
void check_complete(const std::string& path, const HeaderLines& r, std::size_t line_no) {
  if (!r.has("DATA")) {
    if (line_no == 0) fail(path, "empty file (expected a PCD header)");
    fail(path, "header has no DATA line (expected DATA ascii, binary or binary_compressed)");
  }
  const char* missing = !r.has("FIELDS")   ? "FIELDS"
                        : !r.has("SIZE")   ? "SIZE"
                        : !r.has("TYPE")   ? "TYPE"
                        : !r.has("WIDTH")  ? "WIDTH"
                        : !r.has("HEIGHT") ? "HEIGHT"
                                           : nullptr;
  if (missing)
    fail(path, std::string("header has no ") + missing + " line (expected it before DATA)");
  const std::size_t n = r.names.size();
  auto check_len = [&](const char* key, std::size_t len) {
    if (len != n)
      fail(path, std::string("header ") + key + " has " + std::to_string(len) +
                     " values but FIELDS has " + std::to_string(n) +
                     " names (expected one per field)");
  };
  check_len("SIZE", r.sizes.size());
  check_len("TYPE", r.types.size());
  if (r.has("COUNT")) check_len("COUNT", r.counts.size());
}

// The field table: each field's type, size and count, and where it sits in a binary point and
// on an ascii line.
void build_fields(const std::string& path, HeaderLines& r) {
  const bool have_count = r.has("COUNT");
  std::size_t offset = 0, value_index = 0;
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    PcdField f;
    f.name = std::string(r.names[i]);
    std::uint64_t v = 0;
    if (!parse_u64(r.sizes[i], v) || (v != 1 && v != 2 && v != 4 && v != 8))
      fail(path, "field " + f.name + " has SIZE " + quote(r.sizes[i]) + " (expected 1, 2, 4 or 8)");
    f.size = static_cast<int>(v);
    if (r.types[i] != "F" && r.types[i] != "U" && r.types[i] != "I")
      fail(path, "field " + f.name + " has TYPE " + quote(r.types[i]) + " (expected F, U or I)");
    f.type = r.types[i][0];
    if (f.type == 'F' && f.size != 4 && f.size != 8)
      fail(path, "field " + f.name + " is TYPE F with SIZE " + std::to_string(f.size) +
                     " (expected SIZE 4 or 8 for F)");
    if (have_count) {
      // A bound far above any real descriptor (FPFH 33, VFH 308) keeps a point's size finite.
      constexpr std::uint64_t kMaxCount = std::uint64_t{1} << 20;
      const std::string_view count = r.counts[i];
      const bool digits = !count.empty() && std::all_of(count.begin(), count.end(), [](char c) {
        return c >= '0' && c <= '9';
      });
      const bool parsed = parse_u64(count, v);
      if (!digits || (parsed && v == 0))
        fail(path, "field " + f.name + " has COUNT " + quote(r.counts[i]) +
                       " (expected a positive integer)");
      if (!parsed || v > kMaxCount)  // digits beyond 2^64 too
        fail(path, "field " + f.name + " has COUNT " + quote(r.counts[i]) + " (expected at most " +
                       std::to_string(kMaxCount) + " values per field)");
      f.count = static_cast<std::size_t>(v);
    }
    f.offset = offset;
    f.value_index = value_index;
    offset += f.count * static_cast<std::size_t>(f.size);
    value_index += f.count;
    r.h.fields.push_back(f);
  }
  r.h.point_size = offset;
  r.h.values_per_line = value_index;
}

}  // namespace

PcdHeader parse_pcd_header(const std::string& path, const std::string& text) {
  std::size_t line_no = 0;
  HeaderLines r = read_header_lines(path, text, line_no);
  check_complete(path, r, line_no);
  build_fields(path, r);
  PcdHeader& h = r.h;
  const std::uint64_t wh = h.width * h.height;  // both <= INT_MAX: no overflow
  if (!h.has_points) h.points = wh;
  if (h.points != wh)
    fail(path, "POINTS " + std::to_string(h.points) + " but WIDTH*HEIGHT = " +
                   std::to_string(h.width) + "*" + std::to_string(h.height) + " = " +
                   std::to_string(wh) + " (expected POINTS = WIDTH*HEIGHT)");
  if (wh > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
    fail(path, "WIDTH*HEIGHT = " + std::to_string(wh) + " is too large (expected < 2^31 points)");
  return std::move(h);
}

}  // namespace proxseg::detail
