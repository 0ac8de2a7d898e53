// PCD writing (pcd_bytes, write_pcd in cloud_io.hpp): the header of fields x y z, the packed
// colour and the extra unsigned fields, then the points as DATA binary or binary_compressed (the
// fields one after another, LZF-compressed, as PCL writes it).
#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>

#include "io/formats/lzf.hpp"

namespace proxseg {
namespace {

// The colour as PCL packs it: the bits of its float rgb, 0x00RRGGBB.
std::uint32_t pack_rgb(const Rgb& c) {
  return (std::uint32_t{c[0]} << 16) | (std::uint32_t{c[1]} << 8) | c[2];
}

// `header`, DATA binary_compressed and its data: compressed size, uncompressed size (uint32
// each), then the LZF of the fields one after another (x of every point, then y, ..., then each
// extra field), the layout PCL defined: values of one field side by side compress far better
// than whole points. The buffers are not cleared before they are filled: on a one-frame process
// every fresh page costs a fault, and zeroing them touched each twice.
std::string compressed_pcd(std::string header, const Frame& frame,
                           const std::vector<PointField>& fields) {
  const std::size_t n = frame.xyz.size();
  const bool coloured = frame.coloured();
  const std::size_t field_count = 3 + (coloured ? 1 : 0) + fields.size();
  const std::size_t raw_size = 4 * n * field_count;
  if (raw_size > std::numeric_limits<std::uint32_t>::max())
    throw InputError("write_pcd: " + std::to_string(raw_size) +
                     " bytes of point data do not fit binary_compressed (at most "
                     "4 GiB; write DATA binary)");
  const std::unique_ptr<unsigned char[]> raw(new unsigned char[raw_size]);
  unsigned char* out = raw.get();
  for (int k = 0; k < 3; ++k)
    for (std::size_t i = 0; i < n; ++i, out += 4) std::memcpy(out, &frame.xyz[i][k], 4);
  if (coloured)
    for (std::size_t i = 0; i < n; ++i, out += 4) {
      const std::uint32_t packed = pack_rgb(frame.rgb[i]);
      std::memcpy(out, &packed, 4);
    }
  for (const auto& f : fields) {
    if (n > 0) std::memcpy(out, f.values.data(), 4 * n);
    out += 4 * n;
  }
  const std::unique_ptr<unsigned char[]> lzf(new unsigned char[detail::lzf_bound(raw_size)]);
  const std::size_t lzf_size = detail::lzf_compress(raw.get(), raw_size, lzf.get());
  if (lzf_size > std::numeric_limits<std::uint32_t>::max())
    throw InputError(
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
    throw InputError("write_pcd: frame has " + std::to_string(n) + " points but " +
                     std::to_string(frame.rgb.size()) + " colours");
  if (frame.width < 0 || frame.height < 1 ||
      static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height) != n)
    throw InputError("write_pcd: frame is " + std::to_string(frame.width) + "x" +
                     std::to_string(frame.height) + " but has " + std::to_string(n) + " points");
  std::vector<std::string> names = {"x", "y", "z"};
  if (coloured) names.push_back("rgb");
  const std::size_t own = names.size();  // fields before the extra ones
  for (const auto& f : fields) {
    const bool ok_name =
        !f.name.empty() && std::all_of(f.name.begin(), f.name.end(),
                                       [](unsigned char c) { return std::isalnum(c) || c == '_'; });
    if (!ok_name)
      throw InputError("write_pcd: field name '" + f.name +
                       "' is not a PCD field name (letters, digits, _)");
    if (std::find(names.begin(), names.end(), f.name) != names.end())
      throw InputError("write_pcd: field name '" + f.name + "' is used twice");
    // Even without colours: read_pcd would take such a field for the packed colour.
    if (f.name == "rgb" || f.name == "rgba")
      throw InputError("write_pcd: field name '" + f.name + "' is the colour's");
    if (f.values.size() != n)
      throw InputError("write_pcd: field '" + f.name + "' has " + std::to_string(f.values.size()) +
                       " values for " + std::to_string(n) + " points");
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
      const std::uint32_t packed = pack_rgb(frame.rgb[i]);
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

}  // namespace proxseg
