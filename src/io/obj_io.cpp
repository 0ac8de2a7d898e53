// Wavefront OBJ + MTL + texture reader. Parsed here rather than with Open3D's reader: that one
// keeps the texture as an image with UVs per triangle corner, while render() draws vertex
// colours, and our errors name the file and line.
#include <proxseg/io/obj_io.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "image_io.hpp"
#include "input_file.hpp"

namespace fs = std::filesystem;

namespace proxseg {
namespace {

// The split makes no more triangles: 4 million (2 m^2 of surface at 2 mm edges, the banana at
// 0.25 mm) take about 1 s and 0.3 GB; the banana at 2 mm has 34 thousand.
constexpr std::size_t kMaxTriangles = 4'000'000;
// Textures larger than this are refused from their header, before anything is decoded (a
// 16384 x 16384 texture would take 0.8 GB); 8192 x 8192 is the limit of read_rgbd too.
constexpr std::uint64_t kMaxTexturePixels = std::uint64_t{8192} * 8192;
// Mesh indices are ints.
constexpr std::size_t kMaxIndex = 2147483647;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw InputError(path + ": " + what);
}
[[noreturn]] void fail_file(const std::string& path, const std::string& what) {
  throw FileError(path + ": " + what);
}
// "path: line 12: what"
[[noreturn]] void fail_line(const std::string& path, std::size_t line, const std::string& what) {
  fail(path, "line " + std::to_string(line) + ": " + what);
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

// Checks that path names a regular file; `named_by` says where the name came from.
void require_file(const std::string& path, const std::string& named_by) {
  std::string why = detail::not_a_regular_file(path);
  if (why.empty()) return;
  if (!named_by.empty() && why.back() == ')') why.insert(why.size() - 1, named_by);
  fail_file(path, why);
}

std::string read_text(const std::string& path, const std::string& named_by) {
  require_file(path, named_by);
  return detail::read_input_file(path);
}

// The line of `all` that starts at pos (without its '\n' and anything from a '#' comment on);
// pos moves to the next line.
std::string_view next_line(std::string_view all, std::size_t& pos) {
  std::size_t end = all.find('\n', pos);
  if (end == std::string_view::npos) end = all.size();
  std::string_view line = all.substr(pos, end - pos);
  pos = end < all.size() ? end + 1 : end;
  const std::size_t hash = line.find('#');
  if (hash != std::string_view::npos) line = line.substr(0, hash);
  return line;
}

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

std::vector<std::string_view> split_ws(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t b = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

// The text of `line` from token `from` on, trimmed: a file or material name may hold spaces.
std::string rest_of_line(std::string_view line, std::string_view from) {
  std::string_view rest = line.substr(static_cast<std::size_t>(from.data() - line.data()));
  while (!rest.empty() && is_space(rest.back())) rest.remove_suffix(1);
  return std::string(rest);
}

bool parse_double(std::string_view s, double& v) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(v);
}

bool parse_i64(std::string_view s, std::int64_t& v) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

// The file a name in an OBJ or MTL refers to: relative names are relative to the directory of
// the file that holds them. Windows exporters write backslashes, taken as separators unless a
// file with the literal name exists.
std::string resolve(const fs::path& dir, const std::string& name) {
  const fs::path literal = dir / name;
  std::string slashed = name;
  std::replace(slashed.begin(), slashed.end(), '\\', '/');
  if (slashed == name || fs::exists(literal)) return literal.string();
  return (dir / slashed).string();
}

std::string where(const std::string& path, std::size_t line) {
  return " named by " + path + " line " + std::to_string(line);
}

// ---------------------------------------------------------------------------------------------
// Materials

struct Material {
  bool has_kd = false;
  Eigen::Vector3f kd = Eigen::Vector3f::Zero();     // 0..255
  std::string texture;                              // map_Kd, resolved; empty = none
  Eigen::Vector2d uv_scale{1, 1}, uv_offset{0, 0};  // map_Kd -s and -o
  std::string texture_named_by;                     // for messages: " named by MTL line N"
};

using Materials = std::map<std::string, Material, std::less<>>;

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

// Adds the materials of an MTL file (newmtl, Kd, map_Kd; everything else is not drawn).
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

// A texture as 8-bit BGR, whatever the file held (grey, alpha and 16-bit are converted).
cv::Mat read_texture(const Material& m) {
  require_file(m.texture, m.texture_named_by);
  cv::Mat img;
  try {
    img = detail::read_image_file(m.texture, kMaxTexturePixels);
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

// Bilinear texture colour (0..255 floats, r g b) at (u, v). Texel centres are at (i + 0.5) / size;
// UVs repeat, so the border texels blend with the opposite border as a GL_REPEAT sampler does.
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

// ---------------------------------------------------------------------------------------------
// OBJ

struct Corner {
  int v = 0;    // 0-based position index
  int vt = -1;  // 0-based UV index, -1 = none
};

struct ObjFace {
  std::array<Corner, 3> c;
  int material = -1;  // index into ObjData::used, -1 = none
};

struct ObjData {
  std::vector<Eigen::Vector3f> positions;         // metres
  std::vector<Eigen::Vector3f> position_colours;  // 0..255; x < 0 = the v line had none
  std::vector<Eigen::Vector2d> uvs;
  std::vector<ObjFace> faces;  // fan-triangulated
  Materials materials;
  bool has_mtllib = false;
  struct Use {
    std::string name;
    std::size_t line;
  };
  std::vector<Use> used;                               // usemtl names in order of first use
  std::map<std::string, int, std::less<>> used_index;  // name -> index into used
  std::vector<std::string> mtl_files;                  // read already
};

// One corner of an f line: v, v/vt, v/vt/vn or v//vn; indices 1-based or negative (from the end).
Corner parse_corner(const std::string& path, std::size_t line_no, std::string_view t,
                    const ObjData& d) {
  const std::size_t s1 = t.find('/');
  const std::size_t s2 = s1 == std::string_view::npos ? s1 : t.find('/', s1 + 1);
  if (s2 != std::string_view::npos && t.find('/', s2 + 1) != std::string_view::npos)
    fail_line(path, line_no,
              "face corner " + quote(t) + " is invalid (expected v, v/vt, v/vt/vn or v//vn)");
  auto index = [&](std::string_view s, std::size_t count, const char* what) {
    std::int64_t i = 0;
    if (!parse_i64(s, i) || i == 0)
      fail_line(path, line_no,
                std::string(what) + " index " + quote(s) + " in face corner " + quote(t) +
                    " is not an index (expected a non-zero integer: 1 is the first, -1 the last)");
    const std::int64_t n = static_cast<std::int64_t>(count);
    if (i > n || i < -n)
      fail_line(
          path, line_no,
          std::string(what) + " index " + std::to_string(i) + " is out of range (expected " +
              (n == 0 ? std::string("a ") + what + " line before the face"
                      : "1.." + std::to_string(n) + " or -" + std::to_string(n) + "..-1, the " +
                            std::to_string(n) + " " + what + " line(s) so far") +
              ")");
    return static_cast<int>(i > 0 ? i - 1 : n + i);
  };
  Corner c;
  c.v = index(t.substr(0, s1), d.positions.size(), "v");
  if (s1 != std::string_view::npos) {
    const std::string_view vt = t.substr(s1 + 1, s2 == std::string_view::npos ? s2 : s2 - s1 - 1);
    if (!vt.empty()) c.vt = index(vt, d.uvs.size(), "vt");
    // vn is not used (render() shades nothing), so its index is not checked.
  }
  return c;
}

void parse_obj(const std::string& path, double scale, ObjData& d) {
  const std::string text = read_text(path, "");
  const std::string_view all(text);
  const fs::path dir = fs::path(path).parent_path();
  int material = -1;
  std::vector<Corner> corners;
  std::size_t pos = 0;
  for (std::size_t line_no = 1; pos < all.size(); ++line_no) {
    const std::string_view line = next_line(all, pos);
    const auto tok = split_ws(line);
    if (tok.empty()) continue;
    const std::string_view key = tok[0];
    auto number = [&](std::size_t k, const char* expected) {
      double x = 0;
      if (!parse_double(tok[k], x))
        fail_line(path, line_no,
                  std::string(key) + " value " + quote(tok[k]) +
                      " is not a finite number (expected " + expected + ")");
      return x;
    };
    if (key == "v") {
      const char* expected = "v x y z, optionally followed by w or by r g b";
      if (tok.size() != 4 && tok.size() != 5 && tok.size() != 7 && tok.size() != 8)
        fail_line(path, line_no,
                  quote(line) + " has " + std::to_string(tok.size() - 1) + " values (expected " +
                      expected + ")");
      Eigen::Vector3f p;
      for (int k = 0; k < 3; ++k) p[k] = static_cast<float>(number(1 + k, expected) * scale);
      if (!p.allFinite())
        fail_line(path, line_no,
                  "vertex " + quote(line) + " is too large once scaled by " +
                      std::to_string(scale) + " (expected float coordinates)");
      Eigen::Vector3f colour(-1, -1, -1);
      if (tok.size() >= 7)  // r g b from 0 to 1 (MeshLab, Open3D); an 8th value (alpha) ignored
        for (int k = 0; k < 3; ++k)
          colour[k] = static_cast<float>(std::clamp(number(4 + k, expected), 0.0, 1.0) * 255.0);
      if (d.positions.size() >= kMaxIndex)
        fail_line(path, line_no, "too many vertices (expected fewer than 2^31)");
      d.positions.push_back(p);
      d.position_colours.push_back(colour);
    } else if (key == "vt") {
      const char* expected = "vt u [v [w]]";
      if (tok.size() < 2 || tok.size() > 4)
        fail_line(path, line_no,
                  quote(line) + " has " + std::to_string(tok.size() - 1) + " values (expected " +
                      expected + ")");
      if (d.uvs.size() >= kMaxIndex)
        fail_line(path, line_no, "too many texture coordinates (expected fewer than 2^31)");
      d.uvs.emplace_back(number(1, expected), tok.size() >= 3 ? number(2, expected) : 0.0);
    } else if (key == "f" || key == "fo") {
      if (tok.size() < 4)
        fail_line(path, line_no,
                  "face " + quote(line) + " has " + std::to_string(tok.size() - 1) +
                      " corner(s) (expected at least 3)");
      corners.clear();
      for (std::size_t k = 1; k < tok.size(); ++k)
        corners.push_back(parse_corner(path, line_no, tok[k], d));
      const bool uv = corners[0].vt >= 0;
      for (const Corner& c : corners)
        if ((c.vt >= 0) != uv)
          fail_line(path, line_no,
                    "face " + quote(line) +
                        " has texture coordinates at some corners only (expected all or none)");
      // Fan triangulation (exact for the convex polygons exporters write). Triangles that repeat
      // a vertex have no area and are dropped.
      for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        const ObjFace f{{corners[0], corners[k], corners[k + 1]}, material};
        if (f.c[0].v == f.c[1].v || f.c[1].v == f.c[2].v || f.c[0].v == f.c[2].v) continue;
        if (d.faces.size() >= kMaxIndex / 3)
          fail_line(path, line_no, "too many faces (expected fewer than 2^31 / 3)");
        d.faces.push_back(f);
      }
    } else if (key == "mtllib") {
      if (tok.size() < 2)
        fail_line(path, line_no, "mtllib has no file name (expected mtllib file)");
      // The spec separates several files by spaces, but exporters write names with spaces too:
      // the whole rest of the line is one name when such a file exists.
      const std::string whole = resolve(dir, rest_of_line(line, tok[1]));
      std::vector<std::string> files;
      if (tok.size() == 2 || fs::exists(whole)) {
        files.push_back(whole);
      } else {
        for (std::size_t k = 1; k < tok.size(); ++k)
          files.push_back(resolve(dir, std::string(tok[k])));
      }
      for (const std::string& mtl : files) {
        if (std::find(d.mtl_files.begin(), d.mtl_files.end(), mtl) != d.mtl_files.end()) continue;
        read_mtl(mtl, where(path, line_no), d.materials);
        d.mtl_files.push_back(mtl);
      }
      d.has_mtllib = true;
    } else if (key == "usemtl") {
      if (tok.size() < 2) fail_line(path, line_no, "usemtl has no name (expected usemtl name)");
      const std::string name = rest_of_line(line, tok[1]);
      const auto [it, added] = d.used_index.emplace(name, static_cast<int>(d.used.size()));
      if (added) d.used.push_back({name, line_no});
      material = it->second;
    }
    // vn, vp, o, g, s, l, p, usemap and free-form geometry draw nothing here: skipped.
  }
  if (d.positions.empty()) fail(path, "has no vertices (expected 'v x y z' lines and 'f' faces)");
  if (d.faces.empty())
    fail(path, "has no faces with an area (expected 'f' lines of 3 or more distinct vertices)");
}

// What a material of the OBJ draws: its texture (index into the loaded ones, -1 = none), else
// its flat Kd colour if it has one.
struct Look {
  int texture = -1;
  const Material* material = nullptr;  // null = no material (grey)
};

// Resolves the usemtl names and loads the textures that some face with UVs samples (a texture of
// an unused material is not needed, so not an error when missing).
std::vector<Look> resolve_looks(const std::string& path, const ObjData& d,
                                std::vector<cv::Mat>& textures) {
  std::vector<Look> looks(d.used.size());
  std::vector<char> sampled(d.used.size(), 0);
  for (const ObjFace& f : d.faces)
    if (f.material >= 0 && f.c[0].vt >= 0) sampled[f.material] = 1;
  std::map<std::string, int> loaded;
  for (std::size_t i = 0; i < d.used.size(); ++i) {
    const auto it = d.materials.find(d.used[i].name);
    if (it == d.materials.end()) {
      // Without any mtllib a usemtl name is only a label (some exporters write "usemtl default");
      // with one, an undefined name is a broken reference.
      if (d.has_mtllib)
        fail_line(path, d.used[i].line,
                  "usemtl " + quote(d.used[i].name) +
                      " names no material of the mtllib file(s) (expected a newmtl of that name)");
      continue;
    }
    looks[i].material = &it->second;
    if (!sampled[i] || it->second.texture.empty()) continue;
    const auto [at, added] = loaded.emplace(it->second.texture, static_cast<int>(textures.size()));
    if (added) textures.push_back(read_texture(it->second));
    looks[i].texture = at->second;
  }
  return looks;
}

// The mesh being built: per vertex its position, and either a texture and UV or a colour.
struct Vertices {
  std::vector<Eigen::Vector3f> p;
  std::vector<Eigen::Vector2d> uv;
  std::vector<int> texture;             // -1 = colour holds the vertex colour
  std::vector<Eigen::Vector3f> colour;  // 0..255

  int add(const Eigen::Vector3f& pos, const Eigen::Vector2d& t, int tex, const Eigen::Vector3f& c) {
    p.push_back(pos);
    uv.push_back(t);
    texture.push_back(tex);
    colour.push_back(c);
    return static_cast<int>(p.size() - 1);
  }
};

// The OBJ's corners as vertices, one per (position, material, UV if textured); triangles index
// them.
std::vector<Eigen::Vector3i> build_vertices(const ObjData& d, const std::vector<Look>& looks,
                                            Vertices& out) {
  struct KeyHash {
    std::size_t operator()(const std::array<int, 3>& k) const {
      std::uint64_t h = static_cast<std::uint32_t>(k[0]);
      h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(k[1]);
      h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(k[2]);
      return static_cast<std::size_t>(h ^ (h >> 29));
    }
  };
  std::unordered_map<std::array<int, 3>, int, KeyHash> index;
  index.reserve(d.positions.size() * 2);
  std::vector<Eigen::Vector3i> triangles;
  triangles.reserve(d.faces.size());
  for (const ObjFace& f : d.faces) {
    const Look look = f.material >= 0 ? looks[f.material] : Look{};
    // A textured vertex takes the texture alone. The MTL spec multiplies it by Kd, but exporters
    // write a default Kd beside map_Kd (Blender's 0.64 grey in the YCB models) that would only
    // darken it.
    const bool textured = look.texture >= 0 && f.c[0].vt >= 0;
    Eigen::Vector3i t;
    for (int k = 0; k < 3; ++k) {
      const Corner& c = f.c[k];
      const std::array<int, 3> key{c.v, f.material, textured ? c.vt : -1};
      const auto [it, added] = index.emplace(key, 0);
      if (added) {
        Eigen::Vector3f colour(128, 128, 128);
        if (d.position_colours[c.v].x() >= 0)
          colour = d.position_colours[c.v];
        else if (look.material && look.material->has_kd)
          colour = look.material->kd;
        Eigen::Vector2d uv(0, 0);
        if (textured)
          uv = d.uvs[c.vt].cwiseProduct(look.material->uv_scale) + look.material->uv_offset;
        it->second = out.add(d.positions[c.v], uv, textured ? look.texture : -1, colour);
      }
      t[k] = it->second;
    }
    triangles.push_back(t);
  }
  return triangles;
}

// The midpoint of an edge: the same float whichever end comes first, so that the triangles on
// both sides of an edge (and of a UV seam) get the same point; halved first so as not to overflow.
Eigen::Vector3f midpoint(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return 0.5f * a + 0.5f * b;
}

// Whether the split cuts edge a-b: it is longer than max_edge (limit2 = max_edge^2) and its
// midpoint is a new float point. The second test only fails far from the origin (beyond 16 km
// floats are more than 2 mm apart), where splitting would never end. Both depend only on the two
// positions, so the triangles on either side of an edge decide alike: no T-junction, no crack.
bool cuts(const Eigen::Vector3f& a, const Eigen::Vector3f& b, double limit2) {
  if ((a.cast<double>() - b.cast<double>()).squaredNorm() <= limit2) return false;
  const Eigen::Vector3f m = midpoint(a, b);
  return m != a && m != b;
}

// One step of the split of triangle t: its long edges are cut at their midpoints and its pieces
// pushed onto todo (true), or it has no long edge and is final (false). Corners are of type C:
// pos(c) is a corner's position, mid(a, b) the corner at the midpoint of edge a-b. Pieces keep the
// winding. Each step at least halves the long edges or shortens them to 0.87 of the longest (the
// diagonal of the two-edge case), so the split ends.
template <class C, class Pos, class Mid>
bool split_step(const std::array<C, 3>& t, double limit2, const Pos& pos, const Mid& mid,
                std::vector<std::array<C, 3>>& todo) {
  // cut[k]: the edge from corner k to corner k + 1.
  const std::array<bool, 3> cut{cuts(pos(t[0]), pos(t[1]), limit2),
                                cuts(pos(t[1]), pos(t[2]), limit2),
                                cuts(pos(t[2]), pos(t[0]), limit2)};
  const int n = cut[0] + cut[1] + cut[2];
  if (n == 0) return false;
  // The first corner: edge a-b is cut and, when two are, b-c is the other one.
  int r = 0;
  while (!(cut[r] && (n != 2 || cut[(r + 1) % 3]))) ++r;
  const C a = t[r], b = t[(r + 1) % 3], c = t[(r + 2) % 3];
  // Pushed last first, so that the pieces come off the stack in this order.
  if (n == 1) {
    const C m = mid(a, b);
    todo.push_back({m, b, c});
    todo.push_back({a, m, c});
  } else if (n == 2) {
    const C mab = mid(a, b), mbc = mid(b, c);
    // The quad a, mab, mbc, c is cut along its shorter diagonal.
    if ((pos(a) - pos(mbc)).squaredNorm() <= (pos(mab) - pos(c)).squaredNorm()) {
      todo.push_back({a, mbc, c});
      todo.push_back({a, mab, mbc});
    } else {
      todo.push_back({mab, mbc, c});
      todo.push_back({a, mab, c});
    }
    todo.push_back({mab, b, mbc});
  } else {
    const C mab = mid(a, b), mbc = mid(b, c), mca = mid(c, a);
    todo.push_back({mab, mbc, mca});
    todo.push_back({mca, mbc, c});
    todo.push_back({mab, b, mbc});
    todo.push_back({a, mab, mca});
  }
  return true;
}

// How many triangles the split makes, or cap + 1 as soon as it would make more: the same steps
// on positions alone, so that a mesh too large for max_edge (or given the wrong scale) is refused
// before anything is allocated. Depth first, so the stack stays short.
std::size_t split_count(const Vertices& v, const std::vector<Eigen::Vector3i>& triangles,
                        double limit2, std::size_t cap) {
  using P = Eigen::Vector3f;
  const auto pos = [](const P& p) -> const P& { return p; };
  std::vector<std::array<P, 3>> todo;
  std::size_t final = 0, steps = 0;
  for (const Eigen::Vector3i& t : triangles) {
    todo.push_back({v.p[t[0]], v.p[t[1]], v.p[t[2]]});
    while (!todo.empty()) {
      const std::array<P, 3> piece = todo.back();
      todo.pop_back();
      final += !split_step(piece, limit2, pos, midpoint, todo);
      // A step makes at least two pieces, so cap triangles take fewer than 2 cap steps.
      if (final > cap || ++steps > 2 * cap) return cap + 1;
    }
  }
  return final;
}

// Splits triangles at the midpoints of their edges longer than max_edge until none is (see
// split_step); a midpoint is made once per edge, with the UV and colour halfway. Each triangle is
// split completely before the next, so the result keeps the file's order.
std::vector<Eigen::Vector3i> subdivide(const std::string& path,
                                       const std::vector<Eigen::Vector3i>& triangles,
                                       double max_edge, Vertices& v) {
  const double limit2 = max_edge * max_edge;
  const std::size_t count = split_count(v, triangles, limit2, kMaxTriangles);
  if (count > kMaxTriangles) {
    std::ostringstream o;
    o << "splitting the textured mesh into edges of at most " << max_edge * 1000
      << " mm would make more than " << kMaxTriangles
      << " triangles (expected a smaller mesh: is it in metres with this scale?)";
    fail(path, o.str());
  }
  std::unordered_map<std::uint64_t, int> midpoints;
  midpoints.reserve(count);
  const auto pos = [&](int i) -> const Eigen::Vector3f& { return v.p[i]; };
  const auto mid = [&](int a, int b) {
    const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
                              static_cast<std::uint32_t>(std::max(a, b));
    const auto [it, added] = midpoints.emplace(key, 0);
    if (added)
      it->second = v.add(midpoint(v.p[a], v.p[b]), 0.5 * (v.uv[a] + v.uv[b]), v.texture[a],
                         0.5f * (v.colour[a] + v.colour[b]));
    return it->second;
  };
  std::vector<Eigen::Vector3i> done;
  done.reserve(count);
  std::vector<std::array<int, 3>> todo;
  for (const Eigen::Vector3i& t : triangles) {
    todo.push_back({t[0], t[1], t[2]});
    while (!todo.empty()) {
      const std::array<int, 3> piece = todo.back();
      todo.pop_back();
      if (!split_step(piece, limit2, pos, mid, todo))
        done.emplace_back(piece[0], piece[1], piece[2]);
    }
  }
  return done;
}

Rgb to_rgb(const Eigen::Vector3f& c) {
  Rgb out;
  for (int k = 0; k < 3; ++k)
    out[k] = static_cast<std::uint8_t>(std::clamp(std::lround(c[k]), 0L, 255L));
  return out;
}

}  // namespace

Mesh read_obj(const std::string& path, double scale, double max_edge) {
  if (!(scale > 0) || !std::isfinite(scale)) fail(path, "mesh scale must be a positive number");
  if (!(max_edge > 0) || !std::isfinite(max_edge))
    fail(path, "max_edge must be a positive number of metres");
  ObjData d;
  parse_obj(path, scale, d);
  std::vector<cv::Mat> textures;
  const std::vector<Look> looks = resolve_looks(path, d, textures);
  Vertices v;
  std::vector<Eigen::Vector3i> triangles = build_vertices(d, looks, v);
  if (!textures.empty()) triangles = subdivide(path, triangles, max_edge, v);

  Mesh mesh;
  mesh.vertices = std::move(v.p);
  mesh.triangles = std::move(triangles);
  mesh.colours.resize(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.colours.size(); ++i)
    mesh.colours[i] =
        to_rgb(v.texture[i] >= 0 ? sample(textures[v.texture[i]], v.uv[i]) : v.colour[i]);
  return mesh;
}

}  // namespace proxseg
