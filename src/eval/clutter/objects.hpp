// The objects of the cluttered scene generator (docs/clutter.md, "what a scene holds"): a
// prototype (box, cylinder, LINEMOD mesh or catalogue entry, its textured mesh in its own
// frame), its resting shape for a tilt (footprint and height), and the object as placed on the
// table or on a box. Private to the library.
#pragma once
#include <proxseg/core/mesh.hpp>
#include <proxseg/eval/clutter.hpp>

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "eval/clutter/footprint.hpp"
#include "eval/clutter/random.hpp"

namespace proxseg::clutter {

// The tessellation of every generated object, metres (textures are per vertex): the clutter
// generator's, the object set's and the scene benchmark's.
inline constexpr double kObjectCell = 0.004;

struct Proto {
  ClutterKind kind = ClutterKind::box;
  std::string name, texture;
  Vec3 size = Vec3::Zero();
  Mesh mesh;           // object frame, unshaded colours
  bool convex = true;  // box or cylinder: normals face away from the centre
  int catalogue = -1;  // ClutterParams::catalogue entry, -1 = drawn at random
};

Proto box_proto(Rng& r, const Vec3& size, const std::string& name);
Proto cylinder_proto(Rng& r, double radius, double height, const std::string& name);
// A LINEMOD mesh, rescaled by a factor in [1 - jitter, 1 + jitter], tinted with probability
// recolour.
Proto mesh_proto(Rng& r, const std::string& path, double jitter, double recolour);
// A catalogue entry exactly as given: no scale jitter, no recolouring.
Proto catalogue_proto(const std::vector<CatalogueObject>& catalogue, int index);

// What an object of the prototype is: its kind, name, catalogue entry, texture and size.
ClutterObject object_of(const Proto& p);

// Resting shape for a tilt R0: lowest point at z = 0, footprint (convex hull of the vertices'
// projection) centred on its vertex mean.
struct Rest {
  Eigen::Isometry3d rest_from_object = Eigen::Isometry3d::Identity();
  Poly hull;
  double height = 0;
  double radius = 0;  // of the hull around the origin
};

Rest make_rest(const Proto& p, const Eigen::Matrix3d& R0);

// One object as placed: world_from_rest = translate(t, z0) * yaw.
struct Placed {
  int proto = 0;
  Rest rest;
  ClutterPose pose = ClutterPose::standing;
  double yaw = 0, z0 = 0, z1 = 0;
  Vec2 t = Vec2::Zero();
  Poly foot;
  int on = -1, nb = -1;  // supporting object (-1 = table), neighbour (touching, leaning)
  double gap = 0, tilt_deg = 0;
  bool can_support = false;  // a box resting level: its top face is horizontal

  void place(double yaw_, const Vec2& t_, double z0_) {
    yaw = yaw_;
    t = t_;
    z0 = z0_;
    z1 = z0 + rest.height;
    const Eigen::Matrix2d R = rot2(yaw);
    foot.resize(rest.hull.size());
    for (std::size_t i = 0; i < foot.size(); ++i) foot[i] = R * rest.hull[i] + t;
  }
  Eigen::Isometry3d world_from_object() const {
    return Eigen::Translation3d(t.x(), t.y(), z0) * Eigen::AngleAxisd(yaw, Vec3::UnitZ()) *
           rest.rest_from_object;
  }
};

// The frame label of object i: 10 * (i + 2) (1 is the table).
inline std::uint32_t object_label(int i) {
  return static_cast<std::uint32_t>(10 * (i + 2));
}

// The object index of a frame label among `objects` objects, -1 for the table, no return or
// anything else.
inline int object_index(std::uint32_t label, std::size_t objects) {
  return label >= 20 && label % 10 == 0 && label / 10 - 2 < objects
             ? static_cast<int>(label / 10 - 2)
             : -1;
}

}  // namespace proxseg::clutter
