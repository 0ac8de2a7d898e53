// The models and views the recognition tests build databases from: the real data, the LINEMOD
// meshes rendered into views, clouds of bare points, and a view seen by a camera with its colours
// repainted.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/registration.hpp>

#include <Eigen/Geometry>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace proxseg::test {

inline const std::string kData = PROXSEG_DATA_DIR;

inline std::vector<Eigen::Vector3d> points_of(const Frame& f, const std::vector<int>& idx) {
  std::vector<Eigen::Vector3d> out;
  for (int i : idx) out.push_back(f.xyz[i].cast<double>());
  return out;
}

inline Frame frame_of(const std::vector<Eigen::Vector3d>& pts) {
  Frame f;
  for (const auto& p : pts) f.xyz.push_back(p.cast<float>());
  f.width = static_cast<int>(pts.size());
  f.height = 1;
  return f;
}

inline const std::map<std::string, std::string> kLinemod = {
    {"01", "ape"},  {"05", "can"},    {"06", "cat"},  {"08", "driller"},
    {"09", "duck"}, {"10", "eggbox"}, {"11", "glue"}, {"12", "holepuncher"}};

inline void add_linemod(Database& db, int views) {
  for (const auto& [id, name] : kLinemod) {
    const Mesh mesh = read_mesh(kData + "/lmo/models/obj_0000" + id + ".ply", 0.001);
    ViewSphereParams p;
    p.views = views;
    for (const auto& v : render_views(mesh, p)) add_view(db, name, v.points, v.eye, "render");
  }
}

// A rendered view of a LINEMOD mesh (model frame) and the same view seen by a camera, with its
// colours passed through `paint`.
struct SeenView {
  Cloud view, candidate;
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();  // camera <- model
};
inline SeenView seen_view(const Mesh& mesh, const std::function<Rgb(const Rgb&)>& paint) {
  ViewSphereParams p;
  p.views = 4;
  const auto views = render_views(mesh, p);
  const Frame& f = views[1].points;
  std::vector<Eigen::Vector3d> model, seen;
  std::vector<Rgb> painted;
  SeenView s;
  s.truth.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 1).normalized()).matrix();
  s.truth.translation() = Eigen::Vector3d(0.02, 0.05, 0.9);
  for (std::size_t i = 0; i < f.size(); ++i) {
    model.push_back(f.xyz[i].cast<double>());
    seen.push_back(s.truth * model.back());
    painted.push_back(paint(f.rgb[i]));
  }
  s.view = describe(model, views[1].eye, DescriptorParams{}, &f.rgb);
  s.candidate = describe(seen, s.truth * views[1].eye, DescriptorParams{}, &painted);
  return s;
}

// Paints for seen_view(): half as bright, and red and blue swapped.
inline Rgb dim(const Rgb& c) {
  return {static_cast<std::uint8_t>(c[0] * 0.5), static_cast<std::uint8_t>(c[1] * 0.5),
          static_cast<std::uint8_t>(c[2] * 0.5)};
}
inline Rgb blue(const Rgb& c) {
  return {c[2], c[1], c[0]};
}

}  // namespace proxseg::test
