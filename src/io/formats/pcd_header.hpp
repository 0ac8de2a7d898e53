// The header of a PCD file (PCL's Point Cloud Data format, v0.7): its keywords, the table of
// fields it declares (name, type, size, count, where each sits in a point) and where the data
// begins. Private to the library.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace proxseg::detail {

struct PcdField {
  std::string name;
  char type = 0;                // 'F', 'U', 'I'
  int size = 0;                 // bytes per element: 1, 2, 4, 8
  std::size_t count = 1;        // elements
  std::size_t offset = 0;       // byte offset of the field within a point
  std::size_t value_index = 0;  // index of the field's first value on an ascii line
};

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

// The header at the start of text (the file's first bytes, read from path): every keyword once,
// FIELDS, SIZE, TYPE, WIDTH and HEIGHT before DATA, one SIZE, TYPE (and COUNT) per field, POINTS
// = WIDTH * HEIGHT < 2^31. InputError naming path, the header line and what was expected.
PcdHeader parse_pcd_header(const std::string& path, const std::string& text);

// The line of `all` that starts at pos (without its '\n'); pos moves to the next line.
std::string_view next_line(std::string_view all, std::size_t& pos);

}  // namespace proxseg::detail
