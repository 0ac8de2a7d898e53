// The points of the 3D page (view_page.hpp) as the page's script reads them: planes of bytes,
// deflated (zlib) and written as base64 text. Planes of alike bytes (the high bytes of position
// steps, runs of one id) deflate to almost nothing: about 5 bytes a point in the page, 0.7-1.4 MB
// for a 640x480 frame (docs/results.md, "Viewing").
#include "io/page/view_points.hpp"

#include <zlib.h>

#include <cmath>
#include <stdexcept>

namespace proxseg::detail {
namespace {

// Appends values as two planes, low bytes then high bytes; returns [offset, count].
nlohmann::json append_planes16(std::string& blob, const std::vector<std::uint16_t>& values) {
  const std::size_t offset = blob.size(), n = values.size();
  blob.resize(offset + 2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    blob[offset + i] = static_cast<char>(values[i] & 0xff);
    blob[offset + n + i] = static_cast<char>(values[i] >> 8);
  }
  return {offset, n};
}

std::string deflated(const std::string& bytes) {
  uLongf size = compressBound(bytes.size());
  std::string out(size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(out.data()), &size,
                reinterpret_cast<const Bytef*>(bytes.data()), bytes.size(), 6) != Z_OK)
    throw std::runtime_error("view page: zlib could not deflate the points");
  out.resize(size);
  return out;
}

std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 3; ++k)
      v = (v << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? digits[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

// Per axis: the coordinate quantised to 16 bits over the points' extent, stored as the step from
// the previous point (mod 2^16): neighbouring points of a scan differ little.
nlohmann::json append_positions(std::string& blob, const Frame& frame,
                                const std::vector<int>& points, nlohmann::json& bounds) {
  nlohmann::json arrays = nlohmann::json::array();
  for (int a = 0; a < 3; ++a) {
    float lo = INFINITY, hi = -INFINITY;
    for (int p : points) lo = std::min(lo, frame.xyz[p][a]), hi = std::max(hi, frame.xyz[p][a]);
    const double step = hi > lo ? (double(hi) - lo) / 65535.0 : 1.0;
    std::vector<std::uint16_t> steps(points.size());
    std::uint16_t previous = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const auto q = static_cast<std::uint16_t>(std::lround((frame.xyz[points[i]][a] - lo) / step));
      steps[i] = static_cast<std::uint16_t>(q - previous);
      previous = q;
    }
    bounds["min"].push_back(lo);
    bounds["step"].push_back(step);
    arrays.push_back(append_planes16(blob, steps));
  }
  return arrays;
}

// The scene's colours as three planes (r, g, b); a frame without colours, grey.
nlohmann::json append_colours(std::string& blob, const Frame& frame,
                              const std::vector<int>& points) {
  const std::size_t offset = blob.size(), n = points.size();
  blob.resize(offset + 3 * n, static_cast<char>(160));
  if (!frame.rgb.empty())
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        blob[offset + c * n + i] = static_cast<char>(frame.rgb[points[i]][c]);
  return {offset, n};
}

}  // namespace

ViewPoints encode_view_points(const Frame& frame, const std::vector<int>& points,
                              const std::vector<ViewField>& fields) {
  std::string blob;
  ViewPoints out;
  out.arrays["position"] = append_positions(blob, frame, points, out.bounds);
  out.arrays["colour"] = append_colours(blob, frame, points);
  for (const ViewField& field : fields) {
    std::vector<std::uint16_t> ids(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
      ids[i] = static_cast<std::uint16_t>(std::min<std::uint32_t>(field.ids[points[i]], 65535));
    out.arrays[field.name] = append_planes16(blob, ids);
  }
  out.base64 = base64(deflated(blob));
  return out;
}

}  // namespace proxseg::detail
