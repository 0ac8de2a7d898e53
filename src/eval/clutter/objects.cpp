// The objects of the cluttered scene generator: prototypes (boxes, cylinders, LINEMOD meshes,
// catalogue entries) and their resting shapes (clutter/objects.hpp).
#include "eval/clutter/objects.hpp"

#include <proxseg/core/colour.hpp>
#include <proxseg/core/render.hpp>

#include <algorithm>
#include <filesystem>
#include <tuple>

#include "eval/clutter/textures.hpp"
#include "eval/linemod_models.hpp"

namespace proxseg::clutter {

namespace {}  // namespace

Proto box_proto(Rng& r, const Vec3& size, const std::string& name) {
  Proto p;
  p.kind = ClutterKind::box;
  p.name = name;
  p.size = size;
  const ColourFn tex = box_texture(r, size, p.texture);
  p.mesh = make_box(Eigen::Isometry3d::Identity(), size, tex, kObjectCell);
  return p;
}

Proto cylinder_proto(Rng& r, double radius, double height, const std::string& name) {
  Proto p;
  p.kind = ClutterKind::cylinder;
  p.name = name;
  p.size = Vec3(2 * radius, 2 * radius, height);
  const ColourFn tex = cylinder_texture(r, radius, height, p.texture);
  p.mesh = make_cylinder(Eigen::Isometry3d::Identity(), radius, height, tex, kObjectCell);
  return p;
}

Proto mesh_proto(Rng& r, const std::string& path, double jitter, double recolour) {
  Proto p;
  p.kind = ClutterKind::mesh;
  p.name = std::filesystem::path(path).stem().string();
  p.texture = "scan";
  p.convex = false;
  p.mesh = *detail::cached_mesh(path);
  const double scale = r.u(1 - jitter, 1 + jitter);
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (auto& v : p.mesh.vertices) {
    v *= static_cast<float>(scale);
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
  p.size = hi - lo;
  if (r.p(recolour)) {
    const Col gain(r.u(0.6, 1.4), r.u(0.6, 1.4), r.u(0.6, 1.4));
    p.texture = "scan, tinted";
    for (auto& c : p.mesh.colours) c = to_rgb8(Col(c[0], c[1], c[2]).cwiseProduct(gain));
  }
  return p;
}

// A catalogue entry exactly as given: no scale jitter, no recolouring.
Proto catalogue_proto(const std::vector<CatalogueObject>& catalogue, int index) {
  const CatalogueObject& e = catalogue[static_cast<std::size_t>(index)];
  Proto p;
  p.kind = e.kind;
  p.name = e.name;
  p.texture = "catalogue";
  p.convex = e.convex;
  p.catalogue = index;
  p.mesh = e.mesh;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const auto& v : p.mesh.vertices) {
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
  p.size = hi - lo;
  return p;
}

ClutterObject object_of(const Proto& p) {
  ClutterObject o;
  std::tie(o.kind, o.name, o.catalogue, o.texture, o.size) =
      std::tie(p.kind, p.name, p.catalogue, p.texture, p.size);
  return o;
}

Rest make_rest(const Proto& p, const Eigen::Matrix3d& R0) {
  std::vector<Vec2> pts;
  double zmin = 1e300, zmax = -1e300;
  if (p.kind == ClutterKind::box) {  // the corners are exact
    for (int c = 0; c < 8; ++c) {
      const Vec3 v = R0 * Vec3((c & 1 ? 0.5 : -0.5) * p.size.x(), (c & 2 ? 0.5 : -0.5) * p.size.y(),
                               (c & 4 ? 0.5 : -0.5) * p.size.z());
      pts.emplace_back(v.x(), v.y());
    }
  } else {
    pts.reserve(p.mesh.vertices.size());
    for (const auto& vf : p.mesh.vertices) {
      const Vec3 v = R0 * vf.cast<double>();
      pts.emplace_back(v.x(), v.y());
    }
  }
  for (const auto& vf : p.mesh.vertices) {
    const double z = (R0 * vf.cast<double>()).z();
    zmin = std::min(zmin, z);
    zmax = std::max(zmax, z);
  }
  Rest r;
  r.hull = convex_hull(std::move(pts));
  Vec2 c = Vec2::Zero();
  for (const Vec2& v : r.hull) c += v;
  c /= static_cast<double>(r.hull.size());
  for (Vec2& v : r.hull) {
    v -= c;
    r.radius = std::max(r.radius, v.norm());
  }
  r.height = zmax - zmin;
  r.rest_from_object.linear() = R0;
  r.rest_from_object.translation() = Vec3(-c.x(), -c.y(), -zmin);
  return r;
}

}  // namespace proxseg::clutter
