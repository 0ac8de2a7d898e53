// Seeded cluttered tabletop scenes (docs/clutter.md): the generator's entry points, its params'
// checks, the kinds of scene, the shading and the summary line. The layout is drawn in
// clutter/layout.cpp, its objects in clutter/objects.cpp, their textures in clutter/textures.cpp,
// their footprints in clutter/footprint.cpp and the camera and render in clutter/capture.cpp.
#include <proxseg/core/colour.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/clutter.hpp>

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "eval/clutter/layout.hpp"
#include "eval/clutter/random.hpp"
#include "eval/linemod_models.hpp"

namespace proxseg {

namespace {

// The name of an enum value from the names of its values in order; "?" for any other value.
template <typename Enum, std::size_t N>
const char* name_of(Enum value, const char* const (&names)[N]) {
  const auto i = static_cast<std::size_t>(value);
  return i < N ? names[i] : "?";
}

void check_params(const ClutterParams& p) {
  auto bad = [](const std::string& what) { throw InputError("clutter: " + what); };
  if (p.min_objects < 1 || p.max_objects < p.min_objects || p.max_objects > 40)
    bad("object count range must satisfy 1 <= min <= max <= 40");
  if (!(p.min_size > 0.005 && p.max_size >= p.min_size && p.max_size <= 0.6))
    bad("size range must satisfy 0.005 < min <= max <= 0.6 m");
  if (!(p.min_distance > 0.2 && p.max_distance >= p.min_distance))
    bad("camera distance range must satisfy 0.2 < min <= max");
  if (!(p.min_elevation_deg > 5 && p.max_elevation_deg >= p.min_elevation_deg &&
        p.max_elevation_deg <= 89))
    bad("camera elevation range must satisfy 5 < min <= max <= 89 degrees");
  if (!(p.min_table_width > 0.4 && p.max_table_width >= p.min_table_width &&
        p.min_table_depth > 0.4 && p.max_table_depth >= p.min_table_depth))
    bad("table ranges must be > 0.4 m and ordered");
  if (!(p.min_density > 0 && p.max_density >= p.min_density && p.max_density < 1))
    bad("density range must satisfy 0 < min <= max < 1");
  for (double q : {p.mesh_share, p.box_share, p.flat_share, p.p_touching, p.p_stacked, p.p_leaning,
                   p.p_lying, p.mesh_recolour, p.p_flush, p.p_front})
    if (!(q >= 0 && q <= 1)) bad("probabilities and shares must be in [0, 1]");
  if (!(p.depth_noise >= 0 && p.disparity_step >= 0 && p.colour_noise >= 0))
    bad("noise must be >= 0");
  if (!(p.min_front_gap >= 0 && p.max_front_gap >= p.min_front_gap && p.max_front_gap < 1))
    bad("front gaps must satisfy 0 <= min <= max < 1 m");
  if (p.min_visible_points < 0 || p.max_layouts < 1)
    bad("min_visible_points >= 0, max_layouts >= 1");
  if (!(p.catalogue_share >= 0 && p.catalogue_share <= 1))
    bad("probabilities and shares must be in [0, 1]");
  for (const CatalogueObject& e : p.catalogue)
    if (e.name.empty() || e.mesh.vertices.empty() || e.mesh.triangles.empty() ||
        e.mesh.colours.size() != e.mesh.vertices.size())
      bad("catalogue entry '" + e.name + "' needs a name and a mesh with one colour per vertex");
}

}  // namespace

const char* to_string(ClutterKind k) {
  return name_of(k, {"mesh", "box", "cylinder"});
}

const char* to_string(ClutterPose p) {
  return name_of(p, {"standing", "lying", "stacked", "leaning"});
}

void shade(Mesh& m, const Eigen::Vector3d& light, double ambient, double exposure,
           const Eigen::Vector3d* centre) {
  using Vec3 = Eigen::Vector3d;
  std::vector<Vec3> n(m.vertices.size(), Vec3::Zero());
  double orientation = 0;
  Vec3 mean = Vec3::Zero();
  for (const auto& v : m.vertices) mean += v.cast<double>();
  mean /= std::max<double>(1, static_cast<double>(m.vertices.size()));
  for (const auto& t : m.triangles) {
    const Vec3 a = m.vertices[t[0]].cast<double>(), b = m.vertices[t[1]].cast<double>(),
               c = m.vertices[t[2]].cast<double>();
    const Vec3 f = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) n[t[k]] += f;
    orientation += f.dot((a + b + c) / 3 - mean);
  }
  const double flip = orientation < 0 ? -1 : 1;  // meshes wound inwards
  for (std::size_t i = 0; i < n.size(); ++i) {
    Vec3 normal = n[i] * flip;
    const Vec3 v = m.vertices[i].cast<double>();
    if (centre) {
      if (normal.squaredNorm() == 0) normal = v - *centre;
      if (normal.dot(v - *centre) < 0) normal = -normal;
    }
    const double len = normal.norm();
    const double lambert = len > 0 ? std::max(0.0, normal.dot(light) / len) : 0.5;
    const double b = exposure * (ambient + (1 - ambient) * lambert);
    const Rgb c = m.colours[i];
    m.colours[i] = to_rgb8(Vec3(c[0], c[1], c[2]) * b);
  }
}

ClutterParams clutter_kind(const std::string& kind) {
  ClutterParams p;
  if (kind == "clutter") return p;
  if (kind == "piles") {
    // Boxes face to face, stacked and side by side: where geometry alone sees one surface.
    p.min_objects = 6, p.max_objects = 14;
    p.mesh_share = 0.1, p.box_share = 0.8, p.flat_share = 0.05;
    p.p_touching = 0.65, p.p_stacked = 0.25, p.p_leaning = 0.05, p.p_flush = 0.85;
    p.max_touch_gap = 0.002;
    p.p_lying = 0.3;
    p.min_density = 0.4, p.max_density = 0.6;
    return p;
  }
  if (kind == "occlusion") {
    // A low camera over a dense layout: objects hidden in part, often in two pieces.
    p.min_elevation_deg = 12, p.max_elevation_deg = 30;
    p.min_density = 0.3, p.max_density = 0.45;
    p.mesh_share = 0.3, p.box_share = 0.35;  // more cylinders: narrow occluders
    p.p_touching = 0.6, p.p_front = 0.6;
    return p;
  }
  throw InputError("clutter kind: expected \"clutter\", \"piles\" or \"occlusion\", got \"" + kind +
                   "\"");
}

ClutterScene clutter_layout_scene(const ClutterParams& params) {
  check_params(params);
  const std::vector<std::string> models = detail::list_models(params.models_dir);
  clutter::Rng count_rng = clutter::stream(params.seed, 0);
  const int n = count_rng.i(params.min_objects, params.max_objects);
  for (int draw = 0; draw < params.max_layouts; ++draw) {
    ClutterScene scene;
    if (!clutter::draw_layout(params, models, n, draw, scene)) continue;
    scene.layout = draw;
    return scene;
  }
  throw std::runtime_error("clutter: no valid layout of " + std::to_string(n) +
                           " objects for seed " + std::to_string(params.seed) + " in " +
                           std::to_string(params.max_layouts) + " draws");
}

Frame clutter_scene(const ClutterParams& params) {
  return clutter_layout_scene(params).frame;
}

std::string clutter_summary(const ClutterScene& s) {
  int meshes = 0, boxes = 0, stacked = 0, leaning = 0, lying = 0, touching = 0;
  for (const ClutterObject& o : s.objects) {
    meshes += o.kind == ClutterKind::mesh;
    boxes += o.kind == ClutterKind::box;
    stacked += o.pose == ClutterPose::stacked;
    leaning += o.pose == ClutterPose::leaning;
    lying += o.pose == ClutterPose::lying;
    touching += static_cast<int>(o.touching.size());
  }
  char line[320];
  std::snprintf(line, sizeof line,
                "%zu objects (%d meshes, %d boxes, %d cylinders; %d stacked, %d leaning, %d lying, "
                "%d touching pairs), %s table, %zu valid points, camera %.2f m at %.0f deg",
                s.objects.size(), meshes, boxes,
                static_cast<int>(s.objects.size()) - meshes - boxes, stacked, leaning, lying,
                touching / 2, s.table.c_str(), s.frame.valid_count(), (s.eye - s.target).norm(),
                s.elevation_deg);
  return line;
}

}  // namespace proxseg
