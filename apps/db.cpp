// `proxseg db add|render|info|check|remove|rename|upgrade`: build, inspect and keep a model
// database [paper 3.4] (docs/database.md).
#include <proxseg/core/database.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/mesh_units.hpp>
#include <proxseg/recognition/database_io.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>

#include "cli.hpp"

namespace cli {

using proxseg::InputError;

namespace {
// The --help headings of the db commands beside cli.hpp's.
constexpr const char* kObject = "Object";
constexpr const char* kRendering = "Rendering";
constexpr const char* kNewDatabase = "New database";
}  // namespace

void add_db(CLI::App& app, DbOptions& o) {
  auto* db = app.add_subcommand("db", tool_about("db"));
  db->require_subcommand(1);
  help_last(db);
  const auto descriptor = [&](CLI::App* cmd) {
    cmd->add_option("--voxel-size", o.voxel_size,
                    "New database only: voxel-grid filter of views and candidates, metres")
        ->group(kNewDatabase);
    cmd->add_option("--normal-radius", o.normal_radius, "New database only: normal radius, metres")
        ->group(kNewDatabase);
    cmd->add_option("--fpfh-radii", o.fpfh_radii, "New database only: FPFH radii, metres")
        ->delimiter(',')
        ->group(kNewDatabase);
    help_last(cmd);
  };
  // The object a command works on.
  const auto name = [&](CLI::App* cmd) {
    cmd->add_option("--name", o.name, "Object name")->required()->group(kObject);
  };
  o.add = db->add_subcommand("add", "Add views of an object: PCD files, or a plain xyz model");
  o.add->add_option("db", o.dir, "Database directory (created if missing)")->required();
  name(o.add);
  o.add->add_option("views", o.views,
                    "View clouds (.pcd or .ply), one view each; - for one from standard input");
  o.add
      ->add_flag("--accumulate", o.accumulate,
                 "Accumulate all given clouds into one view (several frames of one viewpoint)")
      ->group(group::kInput);
  o.add->add_option("--xyz", o.xyz, "A full model as plain 'x y z' lines in metres (YCB-Video)")
      ->group(group::kInput);
  descriptor(o.add);
  o.render = db->add_subcommand(
      "render", "Render partial views of a coloured mesh with a virtual depth camera and add them");
  o.render->add_option("db", o.dir, "Database directory (created if missing)")->required();
  name(o.render);
  o.render
      ->add_option("mesh", o.mesh,
                   "Mesh: .ply with vertex colours, or .obj with its .mtl and texture")
      ->required();
  o.render->add_option("--views", o.render_views, "Number of views (cameras on a sphere)")
      ->check(CLI::Range(1, 1000))
      ->group(kRendering);
  o.render
      ->add_option("--units", o.units,
                   "Units of the mesh coordinates: m or mm (a mesh far too large or small for "
                   "an object in these units is refused, with the other unit suggested)")
      ->check(CLI::IsMember({"mm", "m"}))
      ->capture_default_str()
      ->group(kRendering);
  o.render
      ->add_option("--distance", o.distance,
                   "Camera distance from the mesh centre, metres (0 = automatic)")
      ->group(kRendering);
  o.render->add_option("--noise", o.noise, "Depth noise std at 1 m, metres (0 = none)")
      ->group(kRendering);
  o.render->add_option("--seed", o.seed, "Seed of the depth noise")->group(kRendering);
  descriptor(o.render);
  o.info = db->add_subcommand("info", "List the objects and views of a database, with sizes");
  o.info->add_option("db", o.dir, "Database directory")->required();
  o.info->add_flag("--json", o.json, "Print JSON")->group(group::kOutput);
  help_last(o.info);
  o.check = db->add_subcommand(
      "check", "Read every record and verify its checksum; exit 1 when any is damaged");
  o.check->add_option("db", o.dir, "Database directory")->required();
  o.check->add_flag("--json", o.json, "Print JSON")->group(group::kOutput);
  help_last(o.check);
  o.remove = db->add_subcommand("remove", "Remove an object and all its views");
  o.remove->add_option("db", o.dir, "Database directory")->required();
  name(o.remove);
  help_last(o.remove);
  o.rename = db->add_subcommand("rename", "Rename an object (into another: the views join it)");
  o.rename->add_option("db", o.dir, "Database directory")->required();
  name(o.rename);
  o.rename->add_option("--to", o.new_name, "New name")->required()->group(kObject);
  help_last(o.rename);
  o.upgrade = db->add_subcommand(
      "upgrade", "Convert a version-1 folder database (index.json, views/) to the database file");
  o.upgrade->add_option("db", o.dir, "Database directory")->required();
  help_last(o.upgrade);
}

namespace {

proxseg::Database open_for_adding(const DbOptions& o) {
  proxseg::DescriptorParams d;
  if (o.voxel_size) d.voxel_size = *o.voxel_size;
  if (o.normal_radius) d.normal_radius = *o.normal_radius;
  if (!o.fpfh_radii.empty()) d.fpfh_radii = o.fpfh_radii;
  return proxseg::open_database(o.dir, d, o.voxel_size || o.normal_radius || !o.fpfh_radii.empty());
}

// input_coloured: whether the cloud the view was made from had colours (a view drops colours
// that are one placeholder colour throughout, docs/database.md).
void report(const proxseg::ModelView& v, bool input_coloured) {
  say() << "proxseg: added " << v.object << " view " << v.name << " (" << counted(v.points, "point")
        << (v.coloured       ? ""
            : input_coloured ? "; its colours are one placeholder colour throughout, not "
                               "the object's: recognised by shape alone"
                             : "; no colour: recognised by shape alone")
        << ") from " << v.source << "\n";
}

std::string megabytes(std::size_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f MB", bytes / 1e6);
  return buf;
}

int run_add(const DbOptions& o) {
  if (o.xyz.empty() == o.views.empty())
    throw CLI::ValidationError("give view clouds or --xyz FILE (not both)");
  if (!o.xyz.empty() && o.accumulate)
    throw CLI::ValidationError("--accumulate goes with view clouds, not --xyz");
  no_stdin(o.xyz, "--xyz", "- reads a PCD or PLY view, as VIEWS");
  if (std::count(o.views.begin(), o.views.end(), "-") > 1)
    throw CLI::ValidationError("- (standard input) holds one view: give it once");
  // Read everything before touching the database: bad input leaves it as it was.
  std::vector<std::pair<proxseg::Frame, std::string>> views;
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();  // the sensor of a captured view
  if (!o.xyz.empty()) {
    proxseg::Frame f;
    for (const auto& p : proxseg::read_xyz(o.xyz)) f.xyz.push_back(p.cast<float>());
    f.width = static_cast<int>(f.xyz.size());
    f.height = 1;
    views.emplace_back(std::move(f), o.xyz);
    viewpoint = Eigen::Vector3d::Constant(std::nan(""));  // a full model: seen from everywhere
  } else if (o.accumulate) {
    proxseg::Frame all;
    std::string source;
    // The union has colours only if every view has: one XYZ-only view makes it XYZ-only (a
    // colour per point, or none).
    bool coloured = true;
    for (const auto& file : o.views) {
      const proxseg::Frame f = read_cloud(file);
      coloured = coloured && f.coloured();
      for (std::size_t i = 0; i < f.size(); ++i)
        if (f.valid(i)) {
          all.xyz.push_back(f.xyz[i]);
          if (coloured) all.rgb.push_back(f.rgb[i]);
        }
      source += (source.empty() ? "" : " + ") + cloud_name(file);
    }
    if (!coloured) all.rgb.clear();
    all.width = static_cast<int>(all.xyz.size());
    all.height = 1;
    views.emplace_back(std::move(all), source);
  } else {
    for (const auto& file : o.views) views.emplace_back(read_cloud(file), cloud_name(file));
  }
  proxseg::Database db = open_for_adding(o);
  for (const auto& [frame, source] : views)
    report(proxseg::add_view(db, o.name, frame, viewpoint, source), frame.coloured());
  std::cout << o.dir << ": " << counted(db.objects().size(), "object") << ", "
            << counted(db.views.size(), "view") << "\n";
  return 0;
}

int run_render(const DbOptions& o) {
  no_stdin(o.mesh, "MESH",
           "a mesh is read by its name (an OBJ's material and texture lie beside it)");
  if (!(o.distance >= 0) || !std::isfinite(o.distance))
    throw InputError("--distance: expected metres >= 0");
  if (!(o.noise >= 0 && o.noise < 1)) throw InputError("--noise: expected metres in [0, 1)");
  const proxseg::Mesh mesh = proxseg::read_mesh(o.mesh, o.units == "mm" ? 0.001 : 1.0);
  proxseg::check_mesh_units(mesh, o.mesh, o.units, "--units");
  proxseg::ViewSphereParams p;
  p.views = o.render_views;
  p.distance = o.distance;
  p.depth_noise = o.noise;
  p.seed = o.seed;
  const auto rendered = proxseg::render_views(mesh, p);
  proxseg::Database db = open_for_adding(o);
  for (std::size_t i = 0; i < rendered.size(); ++i) {
    const auto& e = rendered[i].eye;
    char source[256];
    std::snprintf(source, sizeof source, "%s view %zu/%d, camera at (%.3f, %.3f, %.3f) m",
                  o.mesh.c_str(), i + 1, o.render_views, e.x(), e.y(), e.z());
    if (rendered[i].points.size() < 10) {
      std::cerr << "proxseg: warning: " << source << " sees almost nothing; skipped\n";
      continue;
    }
    report(proxseg::add_view(db, o.name, rendered[i].points, e, source),
           rendered[i].points.coloured());
  }
  std::cout << o.dir << ": " << counted(db.objects().size(), "object") << ", "
            << counted(db.views.size(), "view") << "\n";
  return 0;
}

int run_info(const DbOptions& o) {
  const proxseg::Database db = proxseg::load_database(o.dir);
  const nlohmann::json info = proxseg::database_info(db);
  if (o.json) {
    std::cout << info.dump(2) << "\n";
    return 0;
  }
  std::cout << o.dir << ": " << counted(db.objects().size(), "object") << ", "
            << counted(db.views.size(), "view") << ", "
            << megabytes(info["file_bytes"].get<std::size_t>()) << ", voxel "
            << db.descriptor.voxel_size << " m, FPFH radii";
  for (double r : db.descriptor.fpfh_radii) std::cout << " " << r;
  std::cout << " m\n";
  for (const auto& obj : info["objects"])
    std::cout << "  " << obj["name"].get<std::string>() << ": "
              << counted(obj["views"].get<std::size_t>(), "view") << ", "
              << counted(obj["points"].get<std::size_t>(), "point") << ", "
              << megabytes(obj["bytes"].get<std::size_t>()) << "\n";
  for (const std::string& d : db.damaged) std::cout << "  damaged: " << d << "\n";
  return 0;
}

int run_check(const DbOptions& o) {
  const proxseg::DatabaseCheck check = proxseg::check_database(o.dir);
  if (o.json) {
    std::cout << nlohmann::json{{"db", o.dir},
                                {"views", check.views},
                                {"whole", check.whole},
                                {"damaged", check.damaged}}
                     .dump(2)
              << "\n";
  } else {
    for (const std::string& d : check.damaged) std::cout << "damaged: " << d << "\n";
    std::cout << o.dir << ": " << check.whole << " of " << counted(check.views, "view") << " whole"
              << (check.damaged.empty() ? ""
                                        : ", " + std::to_string(check.damaged.size()) +
                                              " damaged records or structures")
              << "\n";
  }
  return check.damaged.empty() ? 0 : 1;
}

int run_remove(const DbOptions& o) {
  proxseg::Database db = proxseg::load_database(o.dir);
  const int n = proxseg::remove_object(db, o.name);
  std::cout << o.dir << ": removed " << o.name << " (" << counted(n, "view") << "); "
            << counted(db.objects().size(), "object") << ", " << counted(db.views.size(), "view")
            << "\n";
  return 0;
}

int run_rename(const DbOptions& o) {
  proxseg::Database db = proxseg::load_database(o.dir);
  const int n = proxseg::rename_object(db, o.name, o.new_name);
  std::cout << o.dir << ": renamed " << o.name << " to " << o.new_name << " (" << counted(n, "view")
            << ")\n";
  return 0;
}

int run_upgrade(const DbOptions& o) {
  const int n = proxseg::upgrade_database(o.dir);
  std::cout << o.dir << ": upgraded " << counted(n, "view") << " into " << o.dir << "/"
            << proxseg::kDatabaseFile << " (index.json and views/ are no longer read)\n";
  return 0;
}

}  // namespace

int run_db(const DbOptions& o) {
  if (o.add->parsed()) return run_add(o);
  if (o.render->parsed()) return run_render(o);
  if (o.check->parsed()) return run_check(o);
  if (o.remove->parsed()) return run_remove(o);
  if (o.rename->parsed()) return run_rename(o);
  if (o.upgrade->parsed()) return run_upgrade(o);
  return run_info(o);
}

}  // namespace cli
