// The object-varied development set for recognition (object_set.hpp): the pool, the folds and
// the database capture.
#include <proxseg/core/colour.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/clutter.hpp>
#include <proxseg/eval/object_set.hpp>
#include <proxseg/eval/point_mesh.hpp>
#include <proxseg/eval/ycb_frames.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/recognition/model_view.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "eval/clutter/objects.hpp"
#include "linemod_models.hpp"
#include "util/angles.hpp"
#include "util/splitmix.hpp"
#include "util/value_noise.hpp"

namespace proxseg {

namespace {

using detail::kPi;

using Col = Eigen::Vector3d;  // 0..255 per channel
using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

Rgb rgb(const Col& c) {
  return to_rgb8(c);
}

PoolObject pool_object(const std::string& name, ClutterKind kind, Mesh mesh, bool convex,
                       const std::string& family, const std::string& group, int half,
                       bool lies = false) {
  PoolObject o;
  o.entry.name = name;
  o.entry.kind = kind;
  o.entry.mesh = std::move(mesh);
  o.entry.convex = convex;
  o.entry.lies = lies;
  o.family = family;
  o.group = group;
  o.half = half;
  return o;
}

// ---- generated shapes, each a surface of revolution (make_lathe) or a box

// A closed ellipsoid-like fruit: radius r, height h, a dimple at the stem.
std::vector<Vec2> fruit_profile(double r, double h) {
  std::vector<Vec2> p;
  const int n = 24;
  for (int i = 0; i <= n; ++i) {
    const double t = kPi * i / n;  // 0 at the bottom pole, pi at the top
    const double dimple = 0.08 * h * std::exp(-std::pow((kPi - t) / 0.35, 2));
    p.emplace_back(r * std::sin(t), -h / 2 * std::cos(t) - dimple);
  }
  p.front().x() = 0, p.back().x() = 0;
  return p;
}

// An open cup or bowl: outer wall from the foot up to the rim, the rim, inner wall down to the
// inner bottom. `flare` widens the top (bowls).
std::vector<Vec2> vessel_profile(double r_bottom, double r_top, double h, double wall) {
  return {{0, 0}, {r_bottom, 0}, {r_top, h}, {r_top - wall, h}, {r_bottom - wall, wall}, {0, wall}};
}

// A pen or marker along z, centred: a body, a conical tip at -z and a flat cap at +z.
std::vector<Vec2> pen_profile(double r, double length, double tip) {
  return {{0, -length / 2},
          {r * 0.3, -length / 2 + 0.2 * tip},
          {r, -length / 2 + tip},
          {r, length / 2},
          {0, length / 2}};
}

// A fruit's skin: two colours blended by a smooth field plus speckles, so that the colour varies
// over the surface (red on one side, yellow-green on the other) as real fruit does.
ColourFn fruit_skin(const Col& a, const Col& b, double patch, std::uint64_t salt) {
  return [=](const Vec3& p) {
    const double side = 0.5 + 0.5 * std::tanh((p.x() + 0.4 * p.y()) / patch);
    const double field = vnoise(p / 0.02, salt);
    const double w = std::clamp(0.7 * side + 0.6 * (field - 0.5), 0.0, 1.0);
    const double speck = vnoise(p / 0.003, salt + 1) > 0.82 ? 0.85 : 1.0;
    return rgb((a * (1 - w) + b * w) * speck);
  };
}

// A pen: body colour, a light band (the label), the cap's end in the body colour darkened.
ColourFn pen_paint(const Col& body, double length) {
  return [=](const Vec3& p) {
    if (std::abs(p.z() - 0.1 * length) < 0.12 * length) return rgb(Col(230, 228, 220));
    if (p.z() > 0.42 * length) return rgb(body * 0.6);
    return rgb(body);
  };
}

// A vessel: outside in `outside`, inside and rim in `inside`, a band near the top outside.
ColourFn vessel_paint(const Col& outside, const Col& inside, double r_bottom, double r_top,
                      double h, double wall) {
  return [=](const Vec3& p) {
    const double r = std::hypot(p.x(), p.y());
    const double outer = r_bottom + (r_top - r_bottom) * std::clamp(p.z() / h, 0.0, 1.0);
    const bool inner = p.z() > wall * 0.5 && r < outer - 0.5 * wall;
    if (inner || p.z() > h - 1e-6) return rgb(inside);
    if (p.z() > 0.7 * h && p.z() < 0.8 * h) return rgb(inside * 0.5 + outside * 0.5);
    return rgb(outside);
  };
}

// A box: body colour, a printed panel of `panel` on the two largest sides, a lid band.
ColourFn box_paint(const Col& body, const Col& panel, const Vec3& size) {
  return [=](const Vec3& p) {
    if (p.z() > size.z() / 2 - 1e-6) return rgb(panel);
    const bool front = std::abs(std::abs(p.y()) - size.y() / 2) < 1e-6;
    if (front && std::abs(p.x()) < 0.3 * size.x() && std::abs(p.z()) < 0.25 * size.z())
      return rgb(panel);
    return rgb(body);
  };
}

// A can: a label of two colours around it (a band of `b` in `a`), metal lids.
ColourFn can_paint(const Col& a, const Col& b, double h) {
  return [=](const Vec3& p) {
    if (std::abs(p.z()) > h / 2 - 1e-6) return rgb(Col(175, 175, 180));
    if (std::abs(p.z()) < 0.15 * h) return rgb(b);
    return rgb(a);
  };
}

Mesh lathe(const std::vector<Vec2>& profile, const ColourFn& colour) {
  return make_lathe(Eigen::Isometry3d::Identity(), profile, colour, clutter::kObjectCell);
}

// The generated objects: the kinds that fail (round objects with colour patches, thin pens and
// markers, open cups and bowls, boxes of several sizes) and look-alike groups (same shape in
// another colour; same colour in another shape).
void add_generated(std::vector<PoolObject>& pool) {
  const auto add = [&](const std::string& name, ClutterKind kind, Mesh mesh, bool convex,
                       const std::string& group, int half, bool lies = false) {
    pool.push_back(
        pool_object(name, kind, std::move(mesh), convex, "generated", group, half, lies));
  };
  // Fruit: the apple and the peach are one shape in other colours.
  add("apple", ClutterKind::mesh,
      lathe(fruit_profile(0.038, 0.072), fruit_skin({190, 30, 35}, {170, 190, 60}, 0.02, 11)),
      false, "fruit", 0);
  add("peach", ClutterKind::mesh,
      lathe(fruit_profile(0.038, 0.072), fruit_skin({230, 120, 60}, {235, 200, 90}, 0.02, 12)),
      false, "fruit", 0);
  add("orange", ClutterKind::mesh,
      lathe(fruit_profile(0.040, 0.076), fruit_skin({240, 140, 20}, {225, 120, 15}, 0.03, 13)),
      false, "", 1);
  add("plum", ClutterKind::mesh,
      lathe(fruit_profile(0.026, 0.05), fruit_skin({90, 30, 70}, {60, 25, 60}, 0.015, 14)), false,
      "", 1);
  // Thin objects, lying: three pens of one shape, a marker.
  const double pen_l = 0.145, marker_l = 0.125;
  const auto pen = [&](const std::string& name, const Col& body, double r, double length,
                       double tip, const std::string& group, int half) {
    add(name, ClutterKind::cylinder, lathe(pen_profile(r, length, tip), pen_paint(body, length)),
        false, group, half, true);
  };
  pen("pen-blue", {30, 60, 170}, 0.0055, pen_l, 0.02, "pen", 1);
  pen("pen-red", {190, 30, 30}, 0.0055, pen_l, 0.02, "pen", 1);
  pen("pen-black", {28, 28, 32}, 0.0055, pen_l, 0.02, "pen", 1);
  pen("marker-green", {40, 150, 60}, 0.0095, marker_l, 0.015, "", 0);
  // Open vessels: three cups of one shape (one black), a beaker and two bowls.
  const auto vessel = [&](const std::string& name, const Col& outside, const Col& inside,
                          double r_bottom, double r_top, double h, double wall,
                          const std::string& group, int half) {
    add(name, ClutterKind::mesh,
        lathe(vessel_profile(r_bottom, r_top, h, wall),
              vessel_paint(outside, inside, r_bottom, r_top, h, wall)),
        false, group, half);
  };
  vessel("cup-white", {230, 230, 225}, {215, 215, 210}, 0.03, 0.04, 0.09, 0.004, "cup", 0);
  vessel("cup-red", {180, 35, 40}, {225, 220, 215}, 0.03, 0.04, 0.09, 0.004, "cup", 0);
  vessel("mug-black", {30, 30, 34}, {60, 60, 64}, 0.03, 0.04, 0.09, 0.004, "cup", 0);
  vessel("beaker", {60, 90, 150}, {200, 205, 215}, 0.035, 0.035, 0.11, 0.003, "", 1);
  vessel("bowl-green", {50, 140, 80}, {225, 225, 215}, 0.035, 0.075, 0.055, 0.004, "bowl", 1);
  vessel("bowl-yellow", {225, 190, 50}, {225, 225, 215}, 0.035, 0.075, 0.055, 0.004, "bowl", 1);
  // Boxes: one shape in two colours; one colour in two shapes; a black one; a flat one.
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  const Vec3 tall(0.07, 0.07, 0.15), slim(0.09, 0.05, 0.15), flat(0.12, 0.08, 0.035);
  const auto box = [&](const std::string& name, const Vec3& size, const Col& face, const Col& print,
                       const std::string& group, int half) {
    add(name, ClutterKind::box,
        make_box(I, size, box_paint(face, print, size), clutter::kObjectCell), true, group, half);
  };
  box("box-blue", tall, {40, 70, 170}, {235, 235, 230}, "box-tall", 0);
  box("box-green", tall, {40, 140, 70}, {235, 235, 230}, "box-tall", 0);
  box("box-orange", slim, {230, 120, 30}, {60, 40, 30}, "orange-things", 1);
  add("can-orange", ClutterKind::cylinder,
      make_cylinder(I, 0.033, 0.12, can_paint({230, 120, 30}, {60, 40, 30}, 0.12),
                    clutter::kObjectCell),
      true, "orange-things", 1);
  const Vec3 long_box(0.16, 0.045, 0.06);
  box("box-black", long_box, {35, 35, 38}, {90, 90, 95}, "", 1);
  box("box-flat", flat, {200, 200, 60}, {150, 40, 120}, "", 0);
}

// ---- LINEMOD

void add_linemod(std::vector<PoolObject>& pool, const std::string& dir) {
  const auto mesh = [&](const char* id) {
    return detail::linemod_mesh(dir, id, "the object pool");
  };
  const auto add = [&](const std::string& name, Mesh m, const std::string& group, int half) {
    pool.push_back(
        pool_object(name, ClutterKind::mesh, std::move(m), false, "linemod", group, half));
  };
  const Mesh ape = mesh("obj_000001"), duck = mesh("obj_000009");
  add("ape", ape, "ape", 0);
  add("ape-green", hue_turned(ape, 0.33), "ape", 0);
  add("can", mesh("obj_000005"), "", 0);
  add("cat", mesh("obj_000006"), "", 1);
  add("glue", mesh("obj_000011"), "", 0);
  add("duck", duck, "duck", 1);
  add("duck-blue", hue_turned(duck, 0.62), "duck", 1);
  add("driller", mesh("obj_000008"), "", 1);
  add("eggbox", mesh("obj_000010"), "", 0);
  add("holepuncher", mesh("obj_000012"), "", 1);
}

// ---- scanned textured meshes

void add_textured(std::vector<PoolObject>& pool, const std::string& dir) {
  namespace fs = std::filesystem;
  int half = 0;
  for (const char* name : {"banana", "scissors"}) {
    const fs::path path = fs::path(dir) / name / "textured_simple_reoriented.obj";
    if (!fs::is_regular_file(path))
      throw InputError(path.string() + ": missing (the object pool needs the textured mesh)");
    pool.push_back(
        pool_object(name, ClutterKind::mesh, read_mesh(path.string()), false, "scan", "", half));
    half = 1 - half;
  }
}

// ---- YCB-Video shapes (points only) with generated paint

// A generated paint for a shape without colour, seeded by its name: a base colour and one of a
// band, a label, two tones or blotches, as printed packaging and plastic are.
ColourFn generated_paint(const std::string& name, const Eigen::AlignedBox3d& box) {
  std::uint64_t h = 1469598103934665603ull;
  for (char c : name) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  SplitMix rng{h};
  const auto colour = [&] {
    const double hue = rng.uniform(), sat = rng.uniform(0.35, 0.9), val = rng.uniform(0.3, 0.95);
    return Col(hsv_to_rgb(Eigen::Vector3d(hue, sat, val)));
  };
  const Col base = colour(), second = rng.uniform() < 0.3 ? Col(230, 228, 220) : colour();
  const int pattern = static_cast<int>(rng.next() % 4);
  const double z0 = box.min().z(), height = std::max(1e-6, box.sizes().z());
  const std::uint64_t salt = rng.next();
  return [=](const Vec3& p) {
    const double t = (p.z() - z0) / height;
    switch (pattern) {
      case 0:  // a band around the middle
        return rgb(t > 0.35 && t < 0.65 ? second : base);
      case 1:  // a label on one side
        return rgb(p.x() > box.center().x() && t > 0.2 && t < 0.8 ? second : base);
      case 2:  // two tones, top and bottom
        return rgb(t > 0.6 ? second : base);
      default:  // blotches
        return rgb(vnoise(p / 0.025, salt) > 0.55 ? second : base);
    }
  };
}

void add_ycb(std::vector<PoolObject>& pool, const std::string& dir) {
  namespace fs = std::filesystem;
  const std::vector<std::string> classes = read_lines((fs::path(dir) / "classes.txt").string());
  // Look-alike groups stay in one half: the small boxes, the big boxes, two cans, the clamps.
  const std::map<std::string, std::pair<std::string, int>> grouped = {
      {"008_pudding_box", {"ycb-small-box", 0}}, {"009_gelatin_box", {"ycb-small-box", 0}},
      {"003_cracker_box", {"ycb-big-box", 1}},   {"004_sugar_box", {"ycb-big-box", 1}},
      {"005_tomato_soup_can", {"ycb-can", 0}},   {"010_potted_meat_can", {"ycb-can", 0}},
      {"051_large_clamp", {"clamp", 1}},         {"052_extra_large_clamp", {"clamp", 1}}};
  int next_half = 1;
  for (const std::string& c : classes) {
    if (c == "011_banana" || c == "037_scissors") continue;  // the scans have them, textured
    const fs::path path = fs::path(dir) / "models" / c / "points.xyz";
    if (!fs::is_regular_file(path))
      throw InputError(path.string() + ": missing (the object pool needs the YCB-Video model)");
    Mesh mesh = mesh_from_points(read_xyz(path.string()));
    Eigen::AlignedBox3d box;
    for (const auto& v : mesh.vertices) box.extend(v.cast<double>());
    const ColourFn paint = generated_paint(c, box);
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
      mesh.colours[i] = paint(mesh.vertices[i].cast<double>());
    const auto g = grouped.find(c);
    int half = 0;
    std::string group;
    if (g != grouped.end()) {
      group = g->second.first, half = g->second.second;
    } else {
      half = next_half, next_half = 1 - next_half;
    }
    pool.push_back(pool_object(c, ClutterKind::mesh, std::move(mesh), false, "ycb", group, half));
  }
}

}  // namespace

Mesh hue_turned(Mesh m, double hue) {
  double sx = 0, sy = 0;
  for (const Rgb& c : m.colours) {
    const Eigen::Vector3d hsv = rgb_to_hsv(c);
    sx += hsv[1] * hsv[2] * std::cos(2 * kPi * hsv[0]);
    sy += hsv[1] * hsv[2] * std::sin(2 * kPi * hsv[0]);
  }
  const double mean = std::atan2(sy, sx) / (2 * kPi);
  for (Rgb& c : m.colours) {
    Eigen::Vector3d hsv = rgb_to_hsv(c);
    hsv[0] += hue - mean;
    c = to_rgb8(hsv_to_rgb(hsv));
  }
  return m;
}

std::vector<PoolObject> object_pool(const ObjectPoolParams& params) {
  std::vector<PoolObject> pool;
  if (!params.linemod_dir.empty()) add_linemod(pool, params.linemod_dir);
  if (!params.textured_dir.empty()) add_textured(pool, params.textured_dir);
  if (!params.ycbv_dir.empty()) add_ycb(pool, params.ycbv_dir);
  if (params.generated) add_generated(pool);
  return pool;
}

std::vector<ObjectFold> object_folds(const std::vector<PoolObject>& pool,
                                     const ObjectFoldParams& params) {
  if (params.known < 1 || params.unknown < 1)
    throw InputError("object folds: known and unknown must be >= 1");
  std::vector<ObjectFold> folds;
  for (int half = 0; half < 2; ++half) {
    std::vector<int> members;
    for (std::size_t i = 0; i < pool.size(); ++i)
      if (pool[i].half == half) members.push_back(static_cast<int>(i));
    const int n = static_cast<int>(members.size());
    if (n == 0) continue;
    if (n < params.known + params.unknown)
      throw InputError("object folds: half " + std::string(1, char('A' + half)) + " has " +
                       std::to_string(n) + " objects, fewer than known + unknown (" +
                       std::to_string(params.known + params.unknown) + ")");
    const int count = (n + params.unknown - 1) / params.unknown;
    for (int k = 0; k < count; ++k) {
      ObjectFold f;
      f.half = half;
      f.name = std::string(1, char('A' + half)) + std::to_string(k + 1);
      const int first = k * params.unknown;
      for (int j = 0; j < params.unknown; ++j) f.unknown.push_back(members[(first + j) % n]);
      for (int j = 0; j < params.known; ++j)
        f.known.push_back(members[(first + params.unknown + j) % n]);
      folds.push_back(std::move(f));
    }
  }
  return folds;
}

SceneCatalogue fold_catalogue(const std::vector<PoolObject>& pool, const ObjectFold& fold) {
  std::vector<CatalogueObject> entries;
  std::vector<char> known;
  for (int i : fold.known) entries.push_back(pool.at(i).entry), known.push_back(1);
  for (int i : fold.unknown) entries.push_back(pool.at(i).entry), known.push_back(0);
  return make_catalogue(std::move(entries), std::move(known));
}

Database captured_database(const SceneCatalogue& catalogue, const CaptureParams& capture,
                           const DescriptorParams& descriptor) {
  if (capture.views < 1) throw InputError("database capture: views must be >= 1");
  Database db;
  db.descriptor = descriptor;
  const std::vector<Vec3> directions = view_sphere(capture.views);
  for (std::size_t e = 0; e < catalogue.entries.size(); ++e) {
    if (!catalogue.known[e]) continue;
    const CatalogueObject& object = catalogue.entries[e];
    // Per object: another camera's white balance.
    SplitMix rng{mix64(capture.seed ^ (e * 0x9e3779b97f4a7c15ull))};
    Vec3 gain;
    for (int c = 0; c < 3; ++c)
      gain[c] = rng.uniform(1 - capture.white_balance, 1 + capture.white_balance);
    Eigen::AlignedBox3d box;
    for (const auto& v : object.mesh.vertices) box.extend(v.cast<double>());
    const Vec3 centre = box.center();
    for (int i = 0; i < capture.views; ++i) {
      const Vec3 eye = centre + capture.distance * directions[i];
      RenderParams rp;
      rp.camera_from_world = look_at(eye, centre);
      rp.depth_noise = capture.depth_noise;
      rp.disparity_step = capture.disparity_step;
      rp.seed = capture.seed + static_cast<std::uint32_t>(1000 * e + i);
      // The light beside the camera: up and to the left of it, seen from the object.
      const Eigen::Isometry3d world_from_camera = rp.camera_from_world.inverse();
      const Vec3 light =
          (world_from_camera.linear() * Vec3(-0.5, -0.6, -1.0)).normalized();  // camera: y down
      Mesh lit = object.mesh;
      shade(lit, light, capture.ambient, 1.0 / (capture.ambient + (1 - capture.ambient) * 0.8),
            object.convex ? &centre : nullptr);
      for (Rgb& c : lit.colours) c = to_rgb8(Col(c[0] * gain[0], c[1] * gain[1], c[2] * gain[2]));
      const Frame image = render({lit}, rp);
      std::vector<Vec3> points;
      std::vector<Rgb> colours;
      for (std::size_t k = 0; k < image.size(); ++k) {
        if (!image.valid(k)) continue;
        points.push_back(world_from_camera * image.xyz[k].cast<double>());
        colours.push_back(image.rgb[k]);
      }
      db.views.push_back(make_model_view(
          object.name, describe(points, eye, descriptor, &colours),
          object.name + " view " + std::to_string(i + 1) + "/" + std::to_string(capture.views),
          object.name + "-" + std::to_string(i)));
    }
  }
  return db;
}

}  // namespace proxseg
