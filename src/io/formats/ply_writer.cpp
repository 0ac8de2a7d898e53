// PLY writing (ply_bytes, write_ply in cloud_io.hpp): a binary little-endian `vertex` element of
// x y z (float), red green blue (uchar) when the frame is coloured and the extra fields as `int`,
// the valid points only or every point (PlyPoints).
#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <limits>

namespace proxseg {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "PLY is written as little-endian memory");

// InputError unless the extra fields can be PLY properties beside x y z red green blue: names of
// letters, digits and _, each once, one value per point, values an `int` holds.
void check_fields(const std::vector<PointField>& fields, std::size_t n) {
  std::vector<std::string> names = {"x", "y", "z", "red", "green", "blue"};
  for (const auto& f : fields) {
    const bool ok_name =
        !f.name.empty() && std::all_of(f.name.begin(), f.name.end(),
                                       [](unsigned char c) { return std::isalnum(c) || c == '_'; });
    if (!ok_name)
      throw InputError("write_ply: field name '" + f.name +
                       "' is not a PLY property name (letters, digits, _)");
    if (std::find(names.begin(), names.end(), f.name) != names.end())
      throw InputError("write_ply: field name '" + f.name + "' is used twice (x y z red green " +
                       "blue are the points' own)");
    if (f.values.size() != n)
      throw InputError("write_ply: field '" + f.name + "' has " + std::to_string(f.values.size()) +
                       " values for " + std::to_string(n) + " points");
    const auto top = std::max_element(f.values.begin(), f.values.end());
    if (top != f.values.end() && *top > std::uint32_t{std::numeric_limits<std::int32_t>::max()})
      throw InputError("write_ply: field '" + f.name + "' holds " + std::to_string(*top) +
                       " (expected values up to 2^31 - 1, written as PLY int)");
    names.push_back(f.name);
  }
}

std::string ply_header(const Frame& frame, const std::vector<PointField>& fields,
                       std::size_t vertices) {
  std::string h = "ply\nformat binary_little_endian 1.0\ncomment written by proxseg";
  if (frame.organized())
    h += "\ncomment organized " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
         " frame (PLY keeps no grid)";
  h += "\nelement vertex " + std::to_string(vertices) +
       "\nproperty float x\nproperty float y\nproperty float z\n";
  if (frame.coloured()) h += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  for (const auto& f : fields) h += "property int " + f.name + "\n";
  return h + "end_header\n";
}

}  // namespace

std::string ply_bytes(const Frame& frame, const std::vector<PointField>& fields, PlyPoints points) {
  const std::size_t n = frame.xyz.size();
  if (frame.coloured() && frame.rgb.size() != n)
    throw InputError("write_ply: frame has " + std::to_string(n) + " points but " +
                     std::to_string(frame.rgb.size()) + " colours");
  check_fields(fields, n);
  const std::size_t written = points == PlyPoints::kAll ? n : frame.valid_count();
  if (written == 0)
    throw InputError(
        "write_ply: the frame has no valid points (expected at least one point "
        "with finite coordinates)");
  const std::string header = ply_header(frame, fields, written);
  const std::size_t vertex_size = 12 + (frame.coloured() ? 3 : 0) + 4 * fields.size();
  std::string bytes = header;
  bytes.resize(header.size() + written * vertex_size);
  char* out = bytes.data() + header.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (points == PlyPoints::kValid && !frame.valid(i)) continue;
    std::memcpy(out, frame.xyz[i].data(), 12);
    out += 12;
    if (frame.coloured()) {
      std::memcpy(out, frame.rgb[i].data(), 3);
      out += 3;
    }
    for (const auto& f : fields) {
      const std::int32_t v = static_cast<std::int32_t>(f.values[i]);
      std::memcpy(out, &v, 4);
      out += 4;
    }
  }
  return bytes;
}

void write_ply(const std::string& path, const Frame& frame, const std::vector<PointField>& fields,
               PlyPoints points) {
  write_file_atomic(path, ply_bytes(frame, fields, points));
}

}  // namespace proxseg
