// The layout of a cluttered scene (docs/clutter.md, "poses", "layout area"): one draw of the
// stage, of the objects and of their relations, the placement by 2D footprints with collision
// checks, then the camera and the render (clutter/capture.cpp).
#include "eval/clutter/layout.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

#include "eval/clutter/capture.hpp"
#include "eval/clutter/footprint.hpp"
#include "eval/clutter/objects.hpp"
#include "eval/clutter/textures.hpp"
#include "util/angles.hpp"

namespace proxseg::clutter {

using detail::kPi;

namespace {

constexpr int kMaxCatalogueInstances = 2;  // of one catalogue entry per scene

// One layout draw (sub-stream `draw` of the seed): the stage, the objects' prototypes and
// relations, their placement (free, touching, stacked, leaning), then the capture.
class Layout {
 public:
  Layout(const ClutterParams& P, const std::vector<std::string>& models, int n, int draw)
      : P_(P),
        models_(models),
        n_(n),
        r_(stream(P.seed, 1 + static_cast<std::uint64_t>(draw))),
        catalogue_count_(P.catalogue.size(), 0) {
    unused_models_.resize(models.size());
    for (std::size_t i = 0; i < models.size(); ++i) unused_models_[i] = static_cast<int>(i);
  }

  bool run(ClutterScene& out);

 private:
  enum class Rel { free, touching, stacked, leaning };
  using Ground = std::pair<int, ClutterPose>;  // a prototype and its pose

  const ClutterParams& P_;
  const std::vector<std::string>& models_;
  int n_;
  Rng r_;
  std::vector<int> unused_models_;
  std::vector<int> catalogue_count_;  // instances of each catalogue entry drawn so far
  std::vector<Proto> protos_;
  std::vector<Placed> placed_;
  double table_hx_ = 0, table_hy_ = 0;
  Vec2 area_c_ = Vec2::Zero(), area_h_ = Vec2::Zero();
  double view_az_ = 0;  // with p_front: the camera's azimuth, drawn before the placement
  Stage stage_;

  double size_u(double lo, double hi) {
    return r_.u(std::max(lo, P_.min_size), std::min(hi, P_.max_size));
  }

  int add_proto(Proto p) {
    protos_.push_back(std::move(p));
    return static_cast<int>(protos_.size()) - 1;
  }

  // Any object for the table: mesh, box or cylinder, with its pose (standing or lying).
  std::pair<int, ClutterPose> generic(bool allow_mesh = true) {
    // A catalogue entry. Without a catalogue nothing is drawn here, so that the draws below, and
    // so every scene of the generator without one, stay as they were.
    if (!P_.catalogue.empty() && P_.catalogue_share > 0 && r_.p(P_.catalogue_share)) {
      std::vector<int> open;  // entries with fewer than 2 instances
      for (std::size_t k = 0; k < catalogue_count_.size(); ++k)
        if (catalogue_count_[k] < kMaxCatalogueInstances) open.push_back(static_cast<int>(k));
      if (!open.empty()) {
        const int k = open[static_cast<std::size_t>(r_.i(0, static_cast<int>(open.size()) - 1))];
        ++catalogue_count_[static_cast<std::size_t>(k)];
        const bool lying = P_.catalogue[static_cast<std::size_t>(k)].lies || r_.p(P_.p_lying);
        return {add_proto(catalogue_proto(P_.catalogue, k)),
                lying ? ClutterPose::lying : ClutterPose::standing};
      }
    }
    const double u = r_.u();
    const double mesh_share = (allow_mesh && !unused_models_.empty()) ? P_.mesh_share : 0;
    const bool lying = r_.p(P_.p_lying);
    if (u < mesh_share) {
      const int k = r_.i(0, static_cast<int>(unused_models_.size()) - 1);
      const int model = unused_models_[static_cast<std::size_t>(k)];
      unused_models_.erase(unused_models_.begin() + k);
      return {add_proto(mesh_proto(r_, models_[static_cast<std::size_t>(model)],
                                   P_.mesh_scale_jitter, P_.mesh_recolour)),
              lying ? ClutterPose::lying : ClutterPose::standing};
    }
    const double box_share = P_.box_share / std::max(1e-9, 1 - P_.mesh_share);
    const bool box = r_.u() < std::min(1.0, box_share);
    if (r_.p(P_.flat_share)) {  // small flat things, lying
      if (box) {
        if (r_.p(0.5))
          return {add_proto(box_proto(r_,
                                      Vec3(r_.u(0.03, 0.035), r_.u(0.11, 0.14),
                                           r_.u(std::max(P_.flat_min_thickness, 0.012), 0.02)),
                                      "marker")),
                  ClutterPose::lying};
        return {add_proto(box_proto(r_,
                                    Vec3(r_.u(0.05, 0.07), r_.u(0.08, 0.1),
                                         r_.u(std::max(P_.flat_min_thickness, 0.02), 0.03)),
                                    "soap bar")),
                ClutterPose::lying};
      }
      return {add_proto(cylinder_proto(r_, r_.u(0.011, 0.015), r_.u(0.11, 0.15), "marker")),
              ClutterPose::lying};
    }
    if (box) {
      // Largest extent a, then b <= a, c <= b; standing: a or b vertical, lying: c vertical.
      const double a = size_u(0.06, P_.max_size), b = size_u(0.03, a), c = size_u(0.03, b);
      Vec3 s;
      if (lying)
        s = Vec3(a, b, c);
      else if (r_.p(0.5))
        s = Vec3(b, c, a);
      else
        s = Vec3(a, c, b);
      if (r_.p(0.5)) std::swap(s.x(), s.y());
      return {add_proto(box_proto(r_, s, "box")),
              lying ? ClutterPose::lying : ClutterPose::standing};
    }
    const double rr = size_u(0.03, 0.12) / 2;  // diameter 3-12 cm
    const double h =
        lying ? size_u(std::max(2.2 * rr, 0.06), P_.max_size * 0.8) : size_u(0.04, P_.max_size);
    return {add_proto(cylinder_proto(r_, rr, h, "cylinder")),
            lying ? ClutterPose::lying : ClutterPose::standing};
  }

  Eigen::Matrix3d tilt_for(const Proto& p, ClutterPose pose) {
    // Random boxes are drawn with their lying extents already; a catalogue box is turned down
    // like a mesh (its longer horizontal axis: onto its largest face when z is its longest).
    if (pose != ClutterPose::lying || (p.kind == ClutterKind::box && p.catalogue < 0))
      return Eigen::Matrix3d::Identity();
    if (p.kind == ClutterKind::cylinder)
      return Eigen::AngleAxisd(kPi / 2, Vec3::UnitX()).toRotationMatrix();
    // On its side: turned about its longer horizontal axis (the flattest way down).
    const Vec3 axis = p.size.x() >= p.size.y() ? Vec3::UnitX() : Vec3::UnitY();
    return Eigen::AngleAxisd(r_.p(0.5) ? kPi / 2 : -kPi / 2, axis).toRotationMatrix();
  }

  // Collision-free against every placed object whose height range overlaps; on the table (if
  // resting on it) with a 2 cm margin.
  bool fits(const Placed& c) const {
    if (c.on < 0) {
      for (const Vec2& v : c.foot)
        if (std::abs(v.x()) > table_hx_ - 0.02 || std::abs(v.y()) > table_hy_ - 0.02) return false;
    }
    for (const Placed& o : placed_) {
      if (std::min(c.z1, o.z1) - std::max(c.z0, o.z0) <= 1e-4) continue;
      if ((c.t - o.t).norm() > c.rest.radius + o.rest.radius + 1e-6) continue;
      if (poly_gap(c.foot, o.foot) < 0) return false;
    }
    return true;
  }

  Placed start(int proto, ClutterPose pose, const Eigen::Matrix3d& R0) {
    Placed c;
    c.proto = proto;
    c.pose = pose;
    c.rest = make_rest(protos_[static_cast<std::size_t>(proto)], R0);
    // Stacking puts objects on the top face of the box's own extents: only a box that is not
    // turned (a lying catalogue box is) has it on top.
    c.can_support = protos_[static_cast<std::size_t>(proto)].kind == ClutterKind::box &&
                    pose != ClutterPose::leaning && R0 == Eigen::Matrix3d::Identity();
    return c;
  }

  bool place_free(Placed& c, int trials) {
    for (int k = 0; k < trials; ++k) {
      const Vec2 t(area_c_.x() + r_.u(-1, 1) * area_h_.x(),
                   area_c_.y() + r_.u(-1, 1) * area_h_.y());
      c.place(r_.u(0, 2 * kPi), t, 0);
      if (fits(c)) return true;
    }
    return false;
  }

  std::vector<int> table_level(bool boxes_only, double min_height) const {
    std::vector<int> out;
    for (std::size_t i = 0; i < placed_.size(); ++i) {
      const Placed& o = placed_[i];
      if (o.on >= 0 || o.pose == ClutterPose::leaning) continue;
      if (boxes_only && !o.can_support) continue;
      if (o.z1 < min_height) continue;
      out.push_back(static_cast<int>(i));
    }
    return out;
  }

  // Beside a placed object at a footprint gap in [0, max_touch_gap]: bisection along a random
  // direction from the neighbour's centre (the overlap set along a ray is an interval).
  bool is_box(const Placed& c) const {
    return protos_[static_cast<std::size_t>(c.proto)].kind == ClutterKind::box;
  }

  bool place_touching(Placed& c, int trials) {
    const std::vector<int> cand = table_level(false, 0);
    if (cand.empty()) return false;
    for (int k = 0; k < trials; ++k) {
      const int ni = cand[static_cast<std::size_t>(r_.i(0, static_cast<int>(cand.size()) - 1))];
      const Placed& nb = placed_[static_cast<std::size_t>(ni)];
      double yaw = r_.u(0, 2 * kPi), dir = r_.u(0, 2 * kPi);
      double gap = r_.u(0, P_.max_touch_gap);
      // In front: a few centimetres from the neighbour towards the camera, hiding part of it.
      if (P_.p_front > 0 && r_.p(P_.p_front)) {
        dir = view_az_ + r_.u(-1, 1) * kPi / 8;
        gap = r_.u(P_.min_front_gap, P_.max_front_gap);
      }
      Vec2 from = nb.t;
      // Flush: two boxes face to face, as in a pile (drawn only when asked for, so that scenes
      // without it stay bit-identical).
      if (P_.p_flush > 0 && is_box(c) && is_box(nb) && r_.p(P_.p_flush)) {
        yaw = nb.yaw + r_.i(0, 3) * kPi / 2 + detail::radians(r_.u(-1, 1));
        dir = nb.yaw + r_.i(0, 3) * kPi / 2;
        const Vec2 along(-std::sin(dir), std::cos(dir));
        from += r_.u(-0.5, 0.5) * std::min(c.rest.radius, nb.rest.radius) * along;
      }
      const Vec2 d(std::cos(dir), std::sin(dir));
      double lo = 0, hi = nb.rest.radius + c.rest.radius + gap + 0.01;
      for (int it = 0; it < 40; ++it) {
        const double mid = (lo + hi) / 2;
        c.place(yaw, from + mid * d, 0);
        (poly_gap(c.foot, nb.foot) >= gap ? hi : lo) = mid;
      }
      c.place(yaw, from + hi * d, 0);
      if ((c.t - area_c_).cwiseAbs().maxCoeff() > area_h_.maxCoeff() + 0.1) continue;  // stay near
      if (!fits(c)) continue;
      c.nb = ni;
      c.gap = poly_gap(c.foot, nb.foot);
      return true;
    }
    return false;
  }

  // A small object (box, cylinder or mesh) on the top face of a placed box.
  bool place_stacked(int& proto, Placed& c) {
    std::vector<int> cand;
    for (std::size_t i = 0; i < placed_.size(); ++i) {
      const Placed& o = placed_[i];
      if (!o.can_support) continue;
      const Vec3 s = protos_[static_cast<std::size_t>(o.proto)].size;
      if (std::min(s.x(), s.y()) >= 0.05) cand.push_back(static_cast<int>(i));
    }
    if (cand.empty()) return false;
    const int bi = cand[static_cast<std::size_t>(r_.i(0, static_cast<int>(cand.size()) - 1))];
    const Placed& base = placed_[static_cast<std::size_t>(bi)];
    const Vec3 bs = protos_[static_cast<std::size_t>(base.proto)].size;
    const double room = std::min(bs.x(), bs.y()) - 0.008, room2 = std::max(bs.x(), bs.y()) - 0.008;
    // The object: a mesh that fits, or a box or a standing cylinder smaller than the top.
    const double u = r_.u();
    if (u < P_.mesh_share && !unused_models_.empty()) {
      const int k = r_.i(0, static_cast<int>(unused_models_.size()) - 1);
      const std::string& path =
          models_[static_cast<std::size_t>(unused_models_[static_cast<std::size_t>(k)])];
      Proto p = mesh_proto(r_, path, P_.mesh_scale_jitter, P_.mesh_recolour);
      if (std::max(p.size.x(), p.size.y()) < room) {
        unused_models_.erase(unused_models_.begin() + k);
        proto = add_proto(std::move(p));
      }
    }
    bool aligned = false;  // a box goes roughly along the box below (as stacked boxes do)
    if (proto < 0) {
      if (r_.p(0.7) || room < 0.035) {
        const double a = r_.u(std::min(0.03, room), std::min(0.9 * room2, 0.2));
        const double b = r_.u(std::min(0.03, room), std::min(0.9 * room, a));
        const double h = r_.u(std::max(P_.flat_min_thickness, 0.015), 0.12);
        proto = add_proto(box_proto(r_, Vec3(a, b, h), "box"));
        aligned = true;
      } else {
        const double rr = r_.u(0.015, std::max(0.016, std::min(0.05, room / 2)));
        proto = add_proto(cylinder_proto(r_, rr, r_.u(0.04, 0.15), "cylinder"));
      }
    }
    c = start(proto, ClutterPose::stacked, Eigen::Matrix3d::Identity());
    for (int k = 0; k < 30; ++k) {
      // A point of the base's top face, then the footprint must lie 3 mm inside it.
      const Eigen::Matrix2d R = rot2(base.yaw);
      const Vec2 local(r_.u(-0.5, 0.5) * (bs.x() - 0.006), r_.u(-0.5, 0.5) * (bs.y() - 0.006));
      const Vec2 centre = base.t + R * local;  // the base is a box centred on its footprint
      const double yaw = aligned ? base.yaw + (bs.x() >= bs.y() ? 0 : kPi / 2) + r_.u(-0.25, 0.25)
                                 : r_.u(0, 2 * kPi);
      c.place(yaw, centre, base.z1);
      if (!inside(c.foot, base.foot, 0.003)) continue;
      if (!fits(c)) continue;
      c.on = bi;
      return true;
    }
    return false;
  }

  // A board (thin box) or a cylinder tilted 10-30 degrees, its top resting against a vertical
  // face of a placed standing box, its lowest edge on the table.
  bool place_leaning(int& proto, Placed& c) {
    const std::vector<int> cand = table_level(true, 0.08);
    if (cand.empty()) return false;
    const int ni = cand[static_cast<std::size_t>(r_.i(0, static_cast<int>(cand.size()) - 1))];
    const Placed& nb = placed_[static_cast<std::size_t>(ni)];
    const Poly& f = nb.foot;
    std::vector<int> edges;
    for (std::size_t i = 0; i < f.size(); ++i)
      if ((f[(i + 1) % f.size()] - f[i]).norm() >= 0.05) edges.push_back(static_cast<int>(i));
    if (edges.empty()) return false;
    const auto e = static_cast<std::size_t>(
        edges[static_cast<std::size_t>(r_.i(0, static_cast<int>(edges.size()) - 1))]);
    const Vec2 a = f[e], b = f[(e + 1) % f.size()];
    const double len = (b - a).norm();
    const Vec2 tangent = (b - a) / len, normal(tangent.y(), -tangent.x());  // outward (CCW hull)
    const double theta = detail::radians(r_.u(P_.min_lean_deg, P_.max_lean_deg));
    const double contact = nb.z1 * r_.u(0.55, 0.9);  // height of the top edge on the face
    const double H = std::clamp(contact / std::cos(theta), P_.min_size, P_.max_size);
    if (r_.p(0.6)) {
      const double w = std::min(r_.u(0.06, 0.2), std::max(P_.min_size, len));
      proto = add_proto(
          box_proto(r_, Vec3(r_.u(std::max(P_.flat_min_thickness, 0.012), 0.035), w, H), "board"));
    } else {
      proto = add_proto(cylinder_proto(r_, r_.u(0.015, 0.04), H, "cylinder"));
    }
    // Tilt about y so that the top moves towards -x; then -x is turned towards the face.
    c = start(proto, ClutterPose::leaning,
              Eigen::AngleAxisd(-theta, Vec3::UnitY()).toRotationMatrix());
    c.can_support = false;
    double minx = 1e300;
    for (const Vec2& v : c.rest.hull) minx = std::min(minx, v.x());
    // The contact vertex must touch the face below its top edge.
    double zc = -1;
    const Proto& p = protos_[static_cast<std::size_t>(proto)];
    for (const auto& vf : p.mesh.vertices) {
      const Vec3 v = c.rest.rest_from_object * vf.cast<double>();
      if (v.x() < minx + 1e-4) zc = std::max(zc, v.z());
    }
    if (!(zc > 0.01 && zc < nb.z1 - 0.004)) return false;
    const double yaw = std::atan2(normal.y(), normal.x());
    for (int k = 0; k < 20; ++k) {
      const double gap = r_.u(0.1, 1.0) * P_.max_lean_gap;
      const double s = r_.u(-1, 1) * std::max(0.0, len / 2 - 0.015);
      const Vec2 t = (a + b) / 2 + s * tangent + normal * (gap - minx);
      c.place(yaw, t, 0);
      if (!fits(c)) continue;
      c.nb = ni;
      c.gap = poly_gap(c.foot, nb.foot);
      c.tilt_deg = detail::degrees(theta);
      return true;
    }
    return false;
  }

  // ---- The phases of run(), in the order of their random draws.

  // The table (kind by the seed: a third of any run of seeds each, size, texture) and the light.
  void draw_stage(ClutterScene& out) {
    const int table_kind = static_cast<int>(P_.seed % 3);
    out.table = table_kind == 0 ? "wood" : table_kind == 1 ? "cloth" : "plain";
    stage_.table_w = r_.u(P_.min_table_width, P_.max_table_width);
    stage_.table_d = r_.u(P_.min_table_depth, P_.max_table_depth);
    table_hx_ = stage_.table_w / 2;
    table_hy_ = stage_.table_d / 2;
    stage_.table_colour = table_texture(r_, out.table);
    if (P_.p_front > 0) view_az_ = r_.u(0, 2 * kPi);  // drawn only then: other scenes unchanged
    const double light_el =
        detail::radians(r_.u(P_.min_light_elevation_deg, P_.max_light_elevation_deg));
    const double light_az = r_.u(0, 2 * kPi);
    stage_.light = Vec3(std::cos(light_el) * std::cos(light_az),
                        std::cos(light_el) * std::sin(light_az), std::sin(light_el));
    stage_.ambient = r_.u(P_.min_ambient, P_.max_ambient);
    stage_.exposure = r_.u(0.9, 1.05) / (stage_.ambient + (1 - stage_.ambient) * stage_.light.z());
    out.light = stage_.light;
  }

  // The relation each object is placed with (the first is free).
  std::vector<Rel> draw_relations() {
    std::vector<Rel> rel(static_cast<std::size_t>(n_), Rel::free);
    for (int i = 1; i < n_; ++i) {
      const double u = r_.u();
      rel[static_cast<std::size_t>(i)] = u < P_.p_stacked                  ? Rel::stacked
                                         : u < P_.p_stacked + P_.p_leaning ? Rel::leaning
                                         : u < P_.p_stacked + P_.p_leaning + P_.p_touching
                                             ? Rel::touching
                                             : Rel::free;
    }
    return rel;
  }

  // The objects that go on the table on their own (free and touching ones), drawn before the
  // placement for the layout area; returns the sum of their footprints' areas.
  double draw_ground(const std::vector<Rel>& rel, std::vector<Ground>& ground) {
    double footprint_area = 0;
    for (int i = 0; i < n_; ++i) {
      if (rel[static_cast<std::size_t>(i)] == Rel::stacked ||
          rel[static_cast<std::size_t>(i)] == Rel::leaning)
        continue;
      ground[static_cast<std::size_t>(i)] = generic();
      const Proto& p = protos_[static_cast<std::size_t>(ground[static_cast<std::size_t>(i)].first)];
      footprint_area +=
          poly_area(make_rest(p, tilt_for(p, ground[static_cast<std::size_t>(i)].second)).hull);
    }
    return footprint_area;
  }

  // The layout area: the footprints over a drawn density, a drawn aspect, within the caps.
  void draw_area(double footprint_area) {
    const double density = r_.u(P_.min_density, P_.max_density), aspect = r_.u(1.0, 1.5);
    const double area = std::max(footprint_area / density, 0.04);
    const double cap_x = std::min(P_.max_area_half_extent, table_hx_ - 0.15);
    const double cap_y = std::min(P_.max_area_half_extent, table_hy_ - 0.15);
    area_h_ = Vec2(std::min(std::sqrt(area * aspect) / 2, cap_x),
                   std::min(std::sqrt(area / aspect) / 2, cap_y));
    if (r_.p(0.5)) std::swap(area_h_.x(), area_h_.y());
    area_h_ = area_h_.cwiseMin(Vec2(cap_x, cap_y));
    area_c_ = Vec2(r_.u(-0.03, 0.03), r_.u(-0.03, 0.03));
  }

  // Placement, in order; a stacked or leaning object without a partner is placed touching.
  // False if some object finds no place.
  bool place_all(const std::vector<Rel>& rel, std::vector<Ground>& ground) {
    for (int i = 0; i < n_; ++i) {
      Rel want = rel[static_cast<std::size_t>(i)];
      Placed c;
      bool ok = false;
      if (want == Rel::stacked || want == Rel::leaning) {
        int proto = -1;
        ok = want == Rel::stacked ? place_stacked(proto, c) : place_leaning(proto, c);
        if (!ok) {
          if (proto >= 0) protos_.pop_back();  // its prototype was not placed
          want = Rel::touching;
          ground[static_cast<std::size_t>(i)] = generic();
        }
      }
      if (!ok) {
        const auto [proto, pose] = ground[static_cast<std::size_t>(i)];
        c = start(proto, pose, tilt_for(protos_[static_cast<std::size_t>(proto)], pose));
        ok = want == Rel::touching ? place_touching(c, 40) || place_free(c, 60)
                                   : place_free(c, 80) || place_touching(c, 40);
      }
      if (!ok) return false;
      placed_.push_back(std::move(c));
    }
    return true;
  }

  // The layout decision of placed object i: what it is (its prototype), then where (its
  // placement). Its z range is set with its world mesh.
  ClutterObject describe(std::size_t i) const {
    const Placed& c = placed_[i];
    ClutterObject o = object_of(protos_[static_cast<std::size_t>(c.proto)]);
    o.label = object_label(static_cast<int>(i));
    o.pose = c.pose;
    o.world_from_object = c.world_from_object();
    o.support = c.on < 0 ? 1 : object_label(c.on);
    o.neighbour = c.nb < 0 ? 0 : object_label(c.nb);
    o.gap = c.gap;
    o.tilt_deg = c.tilt_deg;
    o.footprint = c.foot;
    return o;
  }

  // World meshes, shaded (the light is fixed in the world, so they do not depend on the
  // camera); out.objects takes the objects' layout decisions.
  std::vector<Mesh> world_meshes(ClutterScene& out) const {
    std::vector<Mesh> meshes;
    meshes.reserve(placed_.size() + 1);
    out.objects.clear();
    for (std::size_t i = 0; i < placed_.size(); ++i) {
      const Proto& p = protos_[static_cast<std::size_t>(placed_[i].proto)];
      ClutterObject o = describe(i);
      Mesh m = p.mesh;
      o.z_min = 1e300;
      o.z_max = -1e300;
      for (auto& v : m.vertices) {
        v = (o.world_from_object * v.cast<double>()).cast<float>();
        o.z_min = std::min(o.z_min, static_cast<double>(v.z()));
        o.z_max = std::max(o.z_max, static_cast<double>(v.z()));
      }
      const Vec3 centre = o.world_from_object.translation();
      shade(m, stage_.light, stage_.ambient, stage_.exposure, p.convex ? &centre : nullptr);
      m.label = o.label;
      meshes.push_back(std::move(m));
      out.objects.push_back(std::move(o));
    }
    return meshes;
  }

  // Lateral contacts: footprints within max_touch_gap at overlapping heights.
  void find_contacts(ClutterScene& out) const {
    for (std::size_t i = 0; i < placed_.size(); ++i)
      for (std::size_t j = i + 1; j < placed_.size(); ++j) {
        const Placed &a = placed_[i], &b = placed_[j];
        if (std::min(a.z1, b.z1) - std::max(a.z0, b.z0) <= 1e-3) continue;
        if ((a.t - b.t).norm() > a.rest.radius + b.rest.radius + P_.max_touch_gap) continue;
        if (poly_gap(a.foot, b.foot) <= P_.max_touch_gap + 1e-9) {
          out.objects[i].touching.push_back(out.objects[j].label);
          out.objects[j].touching.push_back(out.objects[i].label);
        }
      }
  }

  // What the camera must see: points of every footprint (about 12 per object) at its low and
  // high z.
  std::vector<Vec3> corners() const {
    std::vector<Vec3> corners;
    for (const Placed& c : placed_)
      for (std::size_t k = 0; k < c.foot.size(); k += std::max<std::size_t>(1, c.foot.size() / 12))
        for (double z : {c.z0, c.z1}) corners.emplace_back(c.foot[k].x(), c.foot[k].y(), z);
    return corners;
  }
};

// The stage, the objects and their places, then the camera and the render. Every draw comes
// from r_ in this order: a scene is a pure function of the seed and the params.
bool Layout::run(ClutterScene& out) {
  draw_stage(out);
  const std::vector<Rel> rel = draw_relations();
  std::vector<Ground> ground(static_cast<std::size_t>(n_), {-1, ClutterPose::standing});
  const double footprint_area = draw_ground(rel, ground);
  draw_area(footprint_area);
  if (!place_all(rel, ground)) return false;
  std::vector<Mesh> meshes = world_meshes(out);
  find_contacts(out);
  if (!choose_camera(r_, P_, meshes, corners(), area_c_, view_az_, out)) return false;
  return capture(r_, P_, stage_, meshes, out);
}

}  // namespace

bool draw_layout(const ClutterParams& P, const std::vector<std::string>& models, int n, int draw,
                 ClutterScene& out) {
  Layout layout(P, models, n, draw);
  return layout.run(out);
}

}  // namespace proxseg::clutter
