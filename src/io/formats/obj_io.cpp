// Wavefront OBJ reader (read_obj in obj_io.hpp). Parsed here rather than with Open3D's reader:
// that one keeps the texture as an image with UVs per triangle corner, while render() draws
// vertex colours, and our errors name the file and line. The materials and textures are read by
// mtl_io.hpp, the textured triangles split by edge_split.hpp.
#include <proxseg/io/obj_io.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "io/formats/edge_split.hpp"
#include "io/formats/mtl_io.hpp"
#include "io/formats/obj_text.hpp"
#include "io/reader_errors.hpp"

namespace fs = std::filesystem;

namespace proxseg {
namespace {

using detail::fail;
using detail::parse_number;
using detail::quote;
using detail::Vertices;
using namespace detail::wavefront;

// Mesh indices are ints.
constexpr std::size_t kMaxIndex = 2147483647;

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
    if (!parse_number(s, i) || i == 0)
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

// One line of the OBJ being parsed, for the readers of its keywords.
struct ObjLine {
  const std::string& path;
  std::size_t line_no;
  std::string_view line;
  const std::vector<std::string_view>& tok;

  // Value k as a finite number; InputError naming the line and what was expected otherwise.
  double number(std::size_t k, const char* expected) const {
    double x = 0;
    if (!parse_double(tok[k], x))
      fail_line(path, line_no,
                std::string(tok[0]) + " value " + quote(tok[k]) +
                    " is not a finite number (expected " + expected + ")");
    return x;
  }
  // "'v 1 2' has 2 values (expected ...)"
  [[noreturn]] void bad_count(const char* expected) const {
    fail_line(path, line_no,
              quote(line) + " has " + std::to_string(tok.size() - 1) + " values (expected " +
                  expected + ")");
  }
};

// v x y z [w | r g b [a]]: a position, scaled to metres, and its colour if the line has one.
void parse_vertex(const ObjLine& l, double scale, ObjData& d) {
  const char* expected = "v x y z, optionally followed by w or by r g b";
  const std::size_t n = l.tok.size();
  if (n != 4 && n != 5 && n != 7 && n != 8) l.bad_count(expected);
  Eigen::Vector3f p;
  for (int k = 0; k < 3; ++k) p[k] = static_cast<float>(l.number(1 + k, expected) * scale);
  if (!p.allFinite())
    fail_line(l.path, l.line_no,
              "vertex " + quote(l.line) + " is too large once scaled by " + std::to_string(scale) +
                  " (expected float coordinates)");
  Eigen::Vector3f colour(-1, -1, -1);
  if (n >= 7)  // r g b from 0 to 1 (MeshLab, Open3D); an 8th value (alpha) ignored
    for (int k = 0; k < 3; ++k)
      colour[k] = static_cast<float>(std::clamp(l.number(4 + k, expected), 0.0, 1.0) * 255.0);
  if (d.positions.size() >= kMaxIndex)
    fail_line(l.path, l.line_no, "too many vertices (expected fewer than 2^31)");
  d.positions.push_back(p);
  d.position_colours.push_back(colour);
}

// vt u [v [w]]
void parse_uv(const ObjLine& l, ObjData& d) {
  const char* expected = "vt u [v [w]]";
  if (l.tok.size() < 2 || l.tok.size() > 4) l.bad_count(expected);
  if (d.uvs.size() >= kMaxIndex)
    fail_line(l.path, l.line_no, "too many texture coordinates (expected fewer than 2^31)");
  d.uvs.emplace_back(l.number(1, expected), l.tok.size() >= 3 ? l.number(2, expected) : 0.0);
}

// f (or fo) with 3 or more corners, in the current material; corners is the caller's buffer.
void parse_face(const ObjLine& l, int material, std::vector<Corner>& corners, ObjData& d) {
  if (l.tok.size() < 4)
    fail_line(l.path, l.line_no,
              "face " + quote(l.line) + " has " + std::to_string(l.tok.size() - 1) +
                  " corner(s) (expected at least 3)");
  corners.clear();
  for (std::size_t k = 1; k < l.tok.size(); ++k)
    corners.push_back(parse_corner(l.path, l.line_no, l.tok[k], d));
  const bool uv = corners[0].vt >= 0;
  for (const Corner& c : corners)
    if ((c.vt >= 0) != uv)
      fail_line(l.path, l.line_no,
                "face " + quote(l.line) +
                    " has texture coordinates at some corners only (expected all or none)");
  // Fan triangulation (exact for the convex polygons exporters write). Triangles that repeat
  // a vertex have no area and are dropped.
  for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
    const ObjFace f{{corners[0], corners[k], corners[k + 1]}, material};
    if (f.c[0].v == f.c[1].v || f.c[1].v == f.c[2].v || f.c[0].v == f.c[2].v) continue;
    if (d.faces.size() >= kMaxIndex / 3)
      fail_line(l.path, l.line_no, "too many faces (expected fewer than 2^31 / 3)");
    d.faces.push_back(f);
  }
}

// mtllib file...: reads the MTL files not read yet.
void parse_mtllib(const ObjLine& l, const fs::path& dir, ObjData& d) {
  if (l.tok.size() < 2)
    fail_line(l.path, l.line_no, "mtllib has no file name (expected mtllib file)");
  // The spec separates several files by spaces, but exporters write names with spaces too:
  // the whole rest of the line is one name when such a file exists.
  const std::string whole = resolve(dir, rest_of_line(l.line, l.tok[1]));
  std::vector<std::string> files;
  if (l.tok.size() == 2 || fs::exists(whole)) {
    files.push_back(whole);
  } else {
    for (std::size_t k = 1; k < l.tok.size(); ++k)
      files.push_back(resolve(dir, std::string(l.tok[k])));
  }
  for (const std::string& mtl : files) {
    if (std::find(d.mtl_files.begin(), d.mtl_files.end(), mtl) != d.mtl_files.end()) continue;
    read_mtl(mtl, where(l.path, l.line_no), d.materials);
    d.mtl_files.push_back(mtl);
  }
  d.has_mtllib = true;
}

// usemtl name: the material of the faces that follow (its index into ObjData::used).
int parse_usemtl(const ObjLine& l, ObjData& d) {
  if (l.tok.size() < 2) fail_line(l.path, l.line_no, "usemtl has no name (expected usemtl name)");
  const std::string name = rest_of_line(l.line, l.tok[1]);
  const auto [it, added] = d.used_index.emplace(name, static_cast<int>(d.used.size()));
  if (added) d.used.push_back({name, l.line_no});
  return it->second;
}

// The OBJ at path, line by line (v, vt, f, mtllib, usemtl), into d.
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
    const ObjLine l{path, line_no, line, tok};
    if (key == "v")
      parse_vertex(l, scale, d);
    else if (key == "vt")
      parse_uv(l, d);
    else if (key == "f" || key == "fo")
      parse_face(l, material, corners, d);
    else if (key == "mtllib")
      parse_mtllib(l, dir, d);
    else if (key == "usemtl")
      material = parse_usemtl(l, d);
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
  if (!textures.empty()) triangles = detail::subdivide(path, triangles, max_edge, v);

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
