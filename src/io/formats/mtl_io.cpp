// The materials of Wavefront OBJ meshes (mtl_io.hpp): MTL files and their textures.
#include "io/formats/mtl_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string_view>
#include <utility>
#include <vector>

#include "io/formats/image_io.hpp"
#include "io/formats/obj_text.hpp"
#include "io/reader_errors.hpp"

namespace fs = std::filesystem;

namespace proxseg::detail::wavefront {
namespace {

// Textures larger than this are refused from their header, before anything is decoded (a
// 16384 x 16384 texture would take 0.8 GB); 8192 x 8192 is the limit of read_rgbd too.
constexpr std::uint64_t kMaxTexturePixels = std::uint64_t{8192} * 8192;

// map_Kd [options] file: the options' arguments are skipped (-s and -o kept), the rest of the
// line is the file name.
void parse_map_kd(const std::string& mtl, std::size_t line_no, std::string_view line,
                  const std::vector<std::string_view>& tok, Material& m) {
  // The other options and how many arguments each takes.
  constexpr std::pair<std::string_view, int> kOptions[] = {
      {"-blendu", 1}, {"-blendv", 1}, {"-boost", 1},   {"-mm", 2},   {"-texres", 1},
      {"-clamp", 1},  {"-bm", 1},     {"-imfchan", 1}, {"-type", 1}, {"-cc", 1}};
  std::size_t i = 1;
  while (i < tok.size()) {
    const std::string_view opt = tok[i];
    if (opt == "-s" || opt == "-o" || opt == "-t") {  // up to three numbers (u v w)
      double uvw[3] = {opt == "-s" ? 1.0 : 0.0, opt == "-s" ? 1.0 : 0.0, 0};
      std::size_t k = 0;
      while (k < 3 && i + 1 + k < tok.size() && parse_double(tok[i + 1 + k], uvw[k])) ++k;
      if (k == 0)
        fail_line(mtl, line_no,
                  "map_Kd " + std::string(opt) + " has no number (expected " + std::string(opt) +
                      " u [v [w]] before the file name)");
      if (opt == "-s") m.uv_scale = {uvw[0], uvw[1]};
      if (opt == "-o") m.uv_offset = {uvw[0], uvw[1]};
      i += 1 + k;
      continue;
    }
    const auto known = std::find_if(std::begin(kOptions), std::end(kOptions),
                                    [&](const auto& o) { return o.first == opt; });
    if (known == std::end(kOptions)) break;  // the file name (which may itself start with '-')
    i += 1 + static_cast<std::size_t>(known->second);
  }
  if (i >= tok.size())
    fail_line(mtl, line_no, "map_Kd has no file name (expected map_Kd [options] file)");
  m.texture = resolve(fs::path(mtl).parent_path(), rest_of_line(line, tok[i]));
  m.texture_named_by = where(mtl, line_no);
}

}  // namespace

void read_mtl(const std::string& mtl, const std::string& named_by, Materials& materials) {
  const std::string text = read_text(mtl, named_by);
  const std::string_view all(text);
  Material* current = nullptr;
  std::size_t pos = 0;
  for (std::size_t line_no = 1; pos < all.size(); ++line_no) {
    const std::string_view line = next_line(all, pos);
    const auto tok = split_ws(line);
    if (tok.empty()) continue;
    if (tok[0] == "newmtl") {
      if (tok.size() < 2) fail_line(mtl, line_no, "newmtl has no name (expected newmtl name)");
      current = &materials[rest_of_line(line, tok[1])];
      *current = Material{};
      continue;
    }
    if (tok[0] != "Kd" && tok[0] != "map_Kd") continue;
    if (!current)
      fail_line(mtl, line_no,
                std::string(tok[0]) + " before any newmtl (expected newmtl name first)");
    if (tok[0] == "map_Kd") {
      parse_map_kd(mtl, line_no, line, tok, *current);
      continue;
    }
    // Kd r [g b]: g and b default to r.
    double rgb[3];
    if (tok.size() != 2 && tok.size() != 4)
      fail_line(mtl, line_no, quote(line) + " is invalid (expected Kd r g b, numbers from 0 to 1)");
    for (std::size_t k = 0; k < 3; ++k) {
      const std::string_view t = tok[tok.size() == 2 ? 1 : 1 + k];
      if (!parse_double(t, rgb[k]))
        fail_line(mtl, line_no,
                  "Kd value " + quote(t) + " is not a number (expected Kd r g b, from 0 to 1)");
    }
    current->has_kd = true;
    for (int k = 0; k < 3; ++k)
      current->kd[k] = static_cast<float>(std::clamp(rgb[k], 0.0, 1.0) * 255.0);
  }
}

cv::Mat read_texture(const Material& m) {
  require_file(m.texture, m.texture_named_by);
  cv::Mat img;
  try {
    img = read_image_file(m.texture, kMaxTexturePixels);
  } catch (const std::runtime_error& e) {
    std::string why = e.what();
    std::replace(why.begin(), why.end(), '\n', ' ');
    fail(m.texture, why + " (expected a PNG or JPEG texture" + m.texture_named_by + ")");
  }
  if (img.depth() == CV_16U) img.convertTo(img, CV_8U, 1.0 / 257.0);
  if (img.channels() == 1) cv::cvtColor(img, img, cv::COLOR_GRAY2BGR);
  if (img.channels() == 4) cv::cvtColor(img, img, cv::COLOR_BGRA2BGR);
  if (img.type() != CV_8UC3 || img.empty())
    fail(m.texture, "unsupported image type (expected an 8- or 16-bit PNG or JPEG texture" +
                        m.texture_named_by + ")");
  return img;
}

Eigen::Vector3f sample(const cv::Mat& bgr, const Eigen::Vector2d& uv) {
  // Midpoints of UVs near the double range (or -s/-o products) can overflow: such a UV means
  // nothing, and 0 keeps the index arithmetic below defined.
  const double su = std::isfinite(uv.x()) ? uv.x() : 0.0, sv = std::isfinite(uv.y()) ? uv.y() : 0.0;
  const double u = su - std::floor(su), v = sv - std::floor(sv);
  const double x = u * bgr.cols - 0.5, y = (1.0 - v) * bgr.rows - 0.5;  // row 0 is v = 1
  const double fx = std::floor(x), fy = std::floor(y);
  const float ax = static_cast<float>(x - fx), ay = static_cast<float>(y - fy);
  auto wrap = [](double i, int n) {
    const int k = static_cast<int>(i) % n;
    return k < 0 ? k + n : k;
  };
  const int x0 = wrap(fx, bgr.cols), x1 = wrap(fx + 1, bgr.cols);
  const int y0 = wrap(fy, bgr.rows), y1 = wrap(fy + 1, bgr.rows);
  auto texel = [&](int r, int c) {
    const cv::Vec3b& p = bgr.at<cv::Vec3b>(r, c);
    return Eigen::Vector3f(p[2], p[1], p[0]);
  };
  return (1 - ay) * ((1 - ax) * texel(y0, x0) + ax * texel(y0, x1)) +
         ay * ((1 - ax) * texel(y1, x0) + ax * texel(y1, x1));
}

}  // namespace proxseg::detail::wavefront
