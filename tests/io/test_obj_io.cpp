// Tests of the Wavefront OBJ + MTL + texture reader: the YCB textured models, hand-made files
// whose colours are known exactly, and malformed input.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/obj_io.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using proxseg::FileError;
using proxseg::InputError;
using proxseg::Mesh;
using proxseg::Rgb;

namespace {

const std::string kData = PROXSEG_DATA_DIR;

// The YCB model's OBJ; fails the test (not skips it) when the data is missing.
std::string ycb_obj(const std::string& object) {
  const std::string path = kData + "/ycb_textured/" + object + "/textured_simple_reoriented.obj";
  EXPECT_TRUE(fs::exists(path)) << path
                                << " is missing: the tests need the data (PROXSEG_DATA_DIR, "
                                   "make test DATA=/path/to/data)";
  return path;
}

// A fresh directory per test for hand-made files.
std::string tmp_dir(const std::string& name) {
  const fs::path d = fs::path(PROXSEG_TEST_TMP) / "obj_io" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

std::string write_text(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = (fs::path(dir) / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  return path;
}

// A 2x2 texture: top row red | blue, bottom row green | white (rows as stored, top first).
void write_texture(const std::string& path) {
  cv::Mat bgr(2, 2, CV_8UC3);
  bgr.at<cv::Vec3b>(0, 0) = {0, 0, 255};      // red
  bgr.at<cv::Vec3b>(0, 1) = {255, 0, 0};      // blue
  bgr.at<cv::Vec3b>(1, 0) = {0, 255, 0};      // green
  bgr.at<cv::Vec3b>(1, 1) = {255, 255, 255};  // white
  ASSERT_TRUE(cv::imwrite(path, bgr));
}

// The message of the InputError that f throws ("" and a test failure if it throws none).
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

struct Box {
  Eigen::Vector3f lo, hi;
};
Box bbox(const Mesh& m) {
  Box b{m.vertices[0], m.vertices[0]};
  for (const auto& v : m.vertices) {
    b.lo = b.lo.cwiseMin(v);
    b.hi = b.hi.cwiseMax(v);
  }
  return b;
}

double longest_edge(const Mesh& m) {
  double longest = 0;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k)
      longest = std::max(
          longest,
          (m.vertices[t[k]].cast<double>() - m.vertices[t[(k + 1) % 3]].cast<double>()).norm());
  return longest;
}

// Edges (by end positions, so that UV seams do not count) used by exactly one triangle: the
// holes of the surface.
std::size_t open_edges(const Mesh& m) {
  using P = std::array<float, 3>;
  auto key = [&](int i) { return P{m.vertices[i].x(), m.vertices[i].y(), m.vertices[i].z()}; };
  std::map<std::pair<P, P>, int> uses;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      P a = key(t[k]), b = key(t[(k + 1) % 3]);
      if (b < a) std::swap(a, b);
      ++uses[{a, b}];
    }
  std::size_t open = 0;
  for (const auto& [edge, n] : uses) open += n == 1;
  return open;
}

Eigen::Vector3d mean_colour(const std::vector<Rgb>& colours) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Rgb& c : colours) sum += Eigen::Vector3d(c[0], c[1], c[2]);
  return sum / static_cast<double>(colours.size());
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// The YCB textured models

TEST(ObjReal, BananaIsYellowTexturedAndSplitToTwoMillimetres) {
  const std::string path = ycb_obj("banana");
  const Mesh whole = proxseg::read_obj(path, 1.0, 1.0);  // no edge is 1 m: not split
  const auto t0 = std::chrono::steady_clock::now();
  const Mesh m = proxseg::read_obj(path);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Box b = bbox(m);
  const Eigen::Vector3f size = b.hi - b.lo;
  std::cout << "banana: " << whole.vertices.size() << " vertices, " << whole.triangles.size()
            << " triangles as read; " << m.vertices.size() << " vertices, " << m.triangles.size()
            << " triangles split to 2 mm, read in " << seconds << " s; bbox " << b.lo.transpose()
            << " .. " << b.hi.transpose() << " (" << size.transpose() << " m)\n";
  // 7866 positions in the file; more vertices where UV seams split them.
  EXPECT_EQ(whole.triangles.size(), 15728u);
  EXPECT_GT(whole.vertices.size(), 7866u);
  EXPECT_LT(whole.vertices.size(), 3 * 15728u);
  EXPECT_GT(m.triangles.size(), 2 * whole.triangles.size());
  // Shared vertices, not three per triangle: about one vertex per two triangles on a surface.
  EXPECT_LT(m.vertices.size(), m.triangles.size());
  EXPECT_GT(size.maxCoeff(), 0.17f);
  EXPECT_LT(size.maxCoeff(), 0.21f);
  EXPECT_GT(size.minCoeff(), 0.02f);
  EXPECT_LE(longest_edge(m), 0.002);
  EXPECT_GT(longest_edge(whole), 0.002);
  // Splitting adds no hole: midpoints are shared across edges and seams split alike.
  const std::size_t open_before = open_edges(whole), open_after = open_edges(m);
  std::cout << "banana: " << open_before << " open edges as read, " << open_after << " split\n";
  if (open_before == 0) {
    EXPECT_EQ(open_after, 0u);
  }

  const Eigen::Vector3d mean = mean_colour(m.colours);
  std::set<Rgb> distinct(m.colours.begin(), m.colours.end());
  std::cout << "banana: mean colour " << mean.transpose() << ", " << distinct.size()
            << " distinct colours\n";
  EXPECT_GT(distinct.size(), 1000u);
  EXPECT_GT(mean.x(), mean.z() + 50);  // yellow: red and green well above blue
  EXPECT_GT(mean.y(), mean.z() + 50);
  EXPECT_LT(seconds, 10.0);

  // read_mesh takes .obj to read_obj.
  const Mesh same = proxseg::read_mesh(path, 1.0);
  EXPECT_EQ(same.vertices.size(), m.vertices.size());
  EXPECT_EQ(same.triangles.size(), m.triangles.size());
  EXPECT_EQ(same.colours, m.colours);
}

TEST(ObjReal, ScissorsLoadWithVariedColours) {
  const Mesh m = proxseg::read_obj(ycb_obj("scissors"));
  const Box b = bbox(m);
  const Eigen::Vector3f size = b.hi - b.lo;
  std::cout << "scissors: " << m.vertices.size() << " vertices, " << m.triangles.size()
            << " triangles; bbox " << size.transpose() << " m; mean colour "
            << mean_colour(m.colours).transpose() << "\n";
  EXPECT_GT(size.maxCoeff(), 0.15f);  // YCB 037_scissors: about 20 cm
  EXPECT_LT(size.maxCoeff(), 0.25f);
  EXPECT_LE(longest_edge(m), 0.002);
  std::set<Rgb> distinct(m.colours.begin(), m.colours.end());
  EXPECT_GT(distinct.size(), 1000u);
}

TEST(ObjReal, RenderedBananaViewShowsTheTexture) {
  const Mesh m = proxseg::read_obj(ycb_obj("banana"));
  proxseg::ViewSphereParams vp;
  vp.views = 1;
  const auto views = proxseg::render_views(m, vp);
  ASSERT_EQ(views.size(), 1u);
  const auto& rgb = views[0].points.rgb;
  ASSERT_GT(rgb.size(), 1000u);
  std::set<Rgb> distinct(rgb.begin(), rgb.end());
  const Eigen::Vector3d mean = mean_colour(rgb);
  std::cout << "banana view: " << rgb.size() << " points, " << distinct.size()
            << " distinct colours, mean " << mean.transpose() << "\n";
  EXPECT_GT(distinct.size(), 200u);
  EXPECT_GT(mean.x(), mean.z() + 50);
  EXPECT_GT(mean.y(), mean.z() + 50);
}

TEST(ObjReal, MillimetreScaleMistakeIsRefusedQuickly) {
  // The banana read as if it were in millimetres: 190 m long, billions of 2 mm triangles.
  const auto t0 = std::chrono::steady_clock::now();
  const std::string e = error_of([&] { proxseg::read_obj(ycb_obj("banana"), 1000.0); });
  EXPECT_NE(e.find("triangles"), std::string::npos) << e;
  EXPECT_NE(e.find("scale"), std::string::npos) << e;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
}

// ------------------------------------------------------------------------------------------------
// Hand-made files

// Texel centres of the 2x2 texture give its colours exactly: the v flip (v = 0.25 is the bottom
// row), wrapping, bilinear halves, the triangle fan, negative indices and vertex sharing.
TEST(ObjHandMade, TextureSampledAtUvsWithVFlip) {
  const std::string dir = tmp_dir("texture");
  write_texture(dir + "/tex.png");
  write_text(dir, "m.mtl", "newmtl tex\nKd 0.5 0.5 0.5\nmap_Kd tex.png\n");
  const std::string obj = write_text(dir, "m.obj",
                                     "mtllib m.mtl\n"
                                     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                     "vt 0.25 0.75\n"   // 1 top left: red
                                     "vt 0.75 0.75\n"   // 2 top right: blue
                                     "vt 0.25 0.25\n"   // 3 bottom left: green
                                     "vt 0.75 0.25\n"   // 4 bottom right: white
                                     "vt 1.25 -0.25\n"  // 5 wraps to 0.25 0.75: red
                                     "vt 0.5 0.75\n"    // 6 half red, half blue
                                     "vt 0.75 0.5\n"    // 7 half blue, half white
                                     "usemtl tex\n"
                                     "f 1/1 2/2 3/3 4/4\n"      // a quad: two triangles
                                     "f -4/-3/1 -2/-2 -1/-1\n"  // 1/5 3/6 4/7
                                     "f 1/1 3/3 4/4\n");        // shares vertices with the quad
  const Mesh m = proxseg::read_obj(obj, 1.0, 10.0);             // 10 m: not split
  ASSERT_EQ(m.triangles.size(), 4u);
  ASSERT_EQ(m.colours.size(), m.vertices.size());
  // (position, uv) pairs: 1/1 2/2 3/3 4/4 1/5 3/6 4/7; the last face reuses three of them.
  EXPECT_EQ(m.vertices.size(), 7u);
  auto colour = [&](int tri, int corner) { return m.colours[m.triangles[tri][corner]]; };
  const Rgb red{255, 0, 0}, blue{0, 0, 255}, green{0, 255, 0}, white{255, 255, 255};
  EXPECT_EQ(colour(0, 0), red);
  EXPECT_EQ(colour(0, 1), blue);
  EXPECT_EQ(colour(0, 2), green);
  EXPECT_EQ(colour(1, 0), red);  // the fan: 1 3 4
  EXPECT_EQ(colour(1, 1), green);
  EXPECT_EQ(colour(1, 2), white);
  EXPECT_EQ(colour(2, 0), red);                 // wrapped
  EXPECT_EQ(colour(2, 1), (Rgb{128, 0, 128}));  // 127.5 rounds up
  EXPECT_EQ(colour(2, 2), (Rgb{128, 128, 255}));
  EXPECT_EQ(m.triangles[3], m.triangles[1]);  // same corners, same vertices
  EXPECT_EQ(m.vertices[m.triangles[2][0]], Eigen::Vector3f(0, 0, 0));
  EXPECT_NE(m.triangles[2][0], m.triangles[0][0]);  // same position, other UV: another vertex
}

// Split vertices take the texture at their interpolated UV; midpoints on the shared edge of two
// triangles are shared.
TEST(ObjHandMade, SplitInterpolatesUvsAndSharesMidpoints) {
  const std::string dir = tmp_dir("split");
  write_texture(dir + "/tex.png");
  write_text(dir, "m.mtl", "newmtl tex\nmap_Kd tex.png\n");
  // A 1 cm square whose u runs from 0.25 (red) at x = 0 to 0.75 (blue) at x = 1 cm, in the top row.
  const std::string obj = write_text(dir, "m.obj",
                                     "mtllib m.mtl\nusemtl tex\n"
                                     "v 0 0 0\nv 0.01 0 0\nv 0.01 0.01 0\nv 0 0.01 0\n"
                                     "vt 0.25 0.75\nvt 0.75 0.75\nvt 0.75 0.75\nvt 0.25 0.75\n"
                                     "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  const double max_edge = 0.002;
  const Mesh m = proxseg::read_obj(obj, 1.0, max_edge);
  EXPECT_LE(longest_edge(m), max_edge);
  // Every edge is long for three rounds (10, 5, 2.5 mm sides; 14, 7, 3.5 mm diagonals): 4^3 each.
  EXPECT_EQ(m.triangles.size(), 2u * 64);
  std::set<std::array<float, 3>> positions;
  for (const auto& v : m.vertices) positions.insert({v.x(), v.y(), v.z()});
  EXPECT_EQ(positions.size(), m.vertices.size());  // no duplicate: every midpoint made once
  EXPECT_EQ(open_edges(m), 4u * 8);                // the square's outline only, 8 pieces a side
  double area = 0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3f a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
    const float z = (b - a).cross(c - a).z();
    EXPECT_GT(z, 0) << "winding kept";
    area += 0.5 * z;
  }
  EXPECT_NEAR(area, 1e-4, 1e-9);
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    const double t = m.vertices[i].x() / 0.01;  // 0 at red's texel centre, 1 at blue's
    const Rgb expected{static_cast<std::uint8_t>(std::lround(255 * (1 - t))), 0,
                       static_cast<std::uint8_t>(std::lround(255 * t))};
    for (int k : {0, 2}) EXPECT_NEAR(m.colours[i][k], expected[k], 1) << "vertex " << i;
    EXPECT_EQ(m.colours[i][1], 0);
  }
}

TEST(ObjHandMade, FlatColoursFromKdVertexColoursOrGreyAndNoSplit) {
  const std::string dir = tmp_dir("flat");
  write_text(dir, "m.mtl", "# materials\nnewmtl orange\nKd 1 0.5 0\nnewmtl plain\nNs 10\n");
  const std::string obj = write_text(dir, "m.obj",
                                     "mtllib m.mtl\n"
                                     "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                     "v 0 0 1 0 1 0\n"  // a vertex colour: green
                                     "vt 0 0\n"
                                     "f 1 2 3\n"  // before any usemtl: grey
                                     "usemtl orange\nf 1//1 2//1 3//1\n"
                                     "usemtl plain\nf 1/1/1 2/1/1 3/1/1\n"
                                     "usemtl orange\nf 1 2 4\n");
  const Mesh m = proxseg::read_obj(obj);  // 1 m edges, but nothing to sample: not split
  ASSERT_EQ(m.triangles.size(), 4u);
  const Rgb grey{128, 128, 128}, orange{255, 128, 0}, green{0, 255, 0};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(m.colours[m.triangles[0][k]], grey);
    EXPECT_EQ(m.colours[m.triangles[1][k]], orange);
    EXPECT_EQ(m.colours[m.triangles[2][k]], grey);  // a material without Kd
  }
  EXPECT_EQ(m.colours[m.triangles[3][2]], green);
  EXPECT_EQ(m.triangles[3][0], m.triangles[1][0]);  // same position and material: shared
}

TEST(ObjHandMade, ScaleAndNoMtllibUsemtlIsALabel) {
  const std::string dir = tmp_dir("scale");
  const std::string obj = write_text(dir, "m.obj",
                                     "o thing\ng part\ns 1\nusemtl default\n"
                                     "v 10 20 30\nv 11 20 30\nv 10 21 30\nvn 0 0 1\n"
                                     "f 1//1 2//1 3//1\n");
  const Mesh m = proxseg::read_mesh(obj, 0.001);
  ASSERT_EQ(m.vertices.size(), 3u);
  EXPECT_TRUE(m.vertices[0].isApprox(Eigen::Vector3f(0.010f, 0.020f, 0.030f)));
  EXPECT_EQ(m.colours[0], (Rgb{128, 128, 128}));
}

TEST(ObjHandMade, ReadMeshNamesTheMeshExtensions) {
  const std::string stl = write_text(tmp_dir("ext"), "m.stl", "solid m\n");
  const std::string e = error_of([&] { proxseg::read_mesh(stl); });
  EXPECT_NE(e.find("unknown mesh extension '.stl' (expected .ply or .obj)"), std::string::npos)
      << e;
}

// ------------------------------------------------------------------------------------------------
// Malformed input: an InputError naming the file, the line and what was expected

TEST(ObjErrors, MalformedLinesAreNamed) {
  const std::string dir = tmp_dir("errors");
  write_text(dir, "ok.mtl", "newmtl a\nKd 1 0 0\n");
  const std::string head = "mtllib ok.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n";
  struct Case {
    std::string body;   // after the 5 lines of head
    std::string words;  // expected in the message, after "line N"
  };
  const std::vector<Case> cases = {
      {"f 1 2 4\n", "v index 4 is out of range (expected 1..3"},
      {"f 1 2 -4\n", "v index -4 is out of range"},
      {"f 1 2 0\n", "index '0' in face corner '0' is not an index"},
      {"f 1/2 2/1 3/1\n", "vt index 2 is out of range (expected 1..1"},
      {"f 1 2 x\n", "is not an index"},
      {"f 1 2\n", "has 2 corner(s) (expected at least 3)"},
      {"f 1/1 2 3\n", "texture coordinates at some corners only"},
      {"f 1/1/1/1 2 3\n", "is invalid (expected v, v/vt, v/vt/vn or v//vn)"},
      {"v 1 2 x\n", "value 'x' is not a finite number (expected v x y z"},
      {"v 1 2 nan\n", "value 'nan' is not a finite number"},
      {"v 1 2\n", "has 2 values (expected v x y z"},
      {"vt 0.5 1e999\n", "is not a finite number (expected vt u [v [w]])"},
      {"usemtl b\nf 1 2 3\n", "usemtl 'b' names no material"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string obj =
        write_text(dir, "bad" + std::to_string(i) + ".obj", head + cases[i].body);
    const std::string e = error_of([&] { proxseg::read_obj(obj); });
    EXPECT_EQ(e.rfind(obj + ": line 6: ", 0), 0u) << e;
    EXPECT_NE(e.find(cases[i].words), std::string::npos) << e;
  }
  // A bad Kd is named in the MTL.
  write_text(dir, "badkd.mtl", "newmtl a\nKd 1 zero 0\n");
  const std::string kd = write_text(dir, "kd.obj", "mtllib badkd.mtl\n");
  const std::string e = error_of([&] { proxseg::read_obj(kd); });
  EXPECT_NE(e.find("badkd.mtl: line 2: Kd value 'zero' is not a number"), std::string::npos) << e;
}

TEST(ObjErrors, MissingFilesAreNamed) {
  const std::string dir = tmp_dir("missing");
  try {
    proxseg::read_obj(dir + "/none.obj");
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("none.obj: file not found"), std::string::npos);
  }
  const std::string no_mtl = write_text(dir, "a.obj", "mtllib gone.mtl\nv 0 0 0\n");
  try {
    proxseg::read_obj(no_mtl);
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(dir + "/gone.mtl: file not found"), std::string::npos) << m;
    EXPECT_NE(m.find("a.obj line 1"), std::string::npos) << m;
  }
  write_text(dir, "t.mtl", "newmtl t\nmap_Kd -s 1 1 1 -clamp on textures/gone.png\n");
  const std::string no_png =
      write_text(dir, "b.obj",
                 "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl t\n"
                 "f 1/1 2/1 3/1\n");
  try {
    proxseg::read_obj(no_png);
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(dir + "/textures/gone.png: file not found"), std::string::npos) << m;
    EXPECT_NE(m.find("t.mtl line 2"), std::string::npos) << m;
  }
  // The texture of a material no face samples is not needed: no error.
  const std::string unused = write_text(dir, "c.obj",
                                        "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                        "usemtl t\nf 1 2 3\n");
  EXPECT_EQ(proxseg::read_obj(unused).triangles.size(), 1u);
  // Not an image.
  write_text(dir, "fake.png", "not a png");
  write_text(dir, "f.mtl", "newmtl f\nmap_Kd fake.png\n");
  const std::string fake = write_text(dir, "d.obj",
                                      "mtllib f.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl f\n"
                                      "f 1/1 2/1 3/1\n");
  const std::string e = error_of([&] { proxseg::read_obj(fake); });
  EXPECT_NE(e.find("fake.png: "), std::string::npos) << e;
  EXPECT_NE(e.find("f.mtl line 2"), std::string::npos) << e;
}

TEST(ObjErrors, EmptyMeshesAndBadParameters) {
  const std::string dir = tmp_dir("empty");
  const std::string empty = write_text(dir, "empty.obj", "# nothing\n\n");
  EXPECT_NE(error_of([&] { proxseg::read_obj(empty); }).find("has no vertices"), std::string::npos);
  const std::string points = write_text(dir, "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n");
  EXPECT_NE(error_of([&] { proxseg::read_obj(points); }).find("has no faces"), std::string::npos);
  const std::string flat = write_text(dir, "flat.obj", "v 0 0 0\nv 1 0 0\nf 1 2 1\n");
  EXPECT_NE(error_of([&] { proxseg::read_obj(flat); }).find("has no faces"), std::string::npos);
  const std::string ok = write_text(dir, "ok.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NE(error_of([&] { proxseg::read_obj(ok, 0.0); }).find("scale"), std::string::npos);
  EXPECT_NE(error_of([&] { proxseg::read_obj(ok, 1.0, -1); }).find("max_edge"), std::string::npos);
  // A textured sliver 1e30 m long would need 1e33 triangles: refused before splitting.
  write_texture(dir + "/tex.png");
  write_text(dir, "t.mtl", "newmtl t\nmap_Kd tex.png\n");
  const std::string sliver = write_text(dir, "sliver.obj",
                                        "mtllib t.mtl\nusemtl t\nv 0 0 0\nv 1e30 0 0\nv 2e30 0 0\n"
                                        "vt 0 0\nf 1/1 2/1 3/1\n");
  const std::string e = error_of([&] { proxseg::read_obj(sliver); });
  EXPECT_NE(e.find("would make more than"), std::string::npos) << e;
  // Binary junk: an error, not a crash.
  std::string junk(4096, '\0');
  for (std::size_t i = 0; i < junk.size(); ++i) junk[i] = static_cast<char>((i * 131 + 7) % 256);
  const std::string bin = write_text(dir, "junk.obj", junk);
  EXPECT_FALSE(error_of([&] { proxseg::read_obj(bin); }).empty());
}
