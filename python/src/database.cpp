// proxseg.Database: the model database [paper 3.4] on disk, opened once and shared by threads.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/mesh_units.hpp>
#include <proxseg/recognition/database_io.hpp>

#include <array>
#include <cmath>
#include <cstdio>

#include "bindings.hpp"
#include "database.hpp"
#include "stop.hpp"

namespace proxseg::python {
namespace {

// NaN or empty: the default.
DescriptorParams descriptor_params(double voxel_size, double normal_radius,
                                   const std::vector<double>& fpfh_radii) {
  DescriptorParams d;
  if (!std::isnan(voxel_size)) d.voxel_size = voxel_size;
  if (!std::isnan(normal_radius)) d.normal_radius = normal_radius;
  if (!fpfh_radii.empty()) d.fpfh_radii = fpfh_radii;
  return d;
}

// What Python is told about a view: copied out of the snapshot, turned into a dict with the GIL.
struct ViewInfo {
  std::string object, name, source;
  std::size_t points = 0;
  bool coloured = false;
};

ViewInfo view_info(const ModelView& v) {
  return {v.object, v.name, v.source, v.points, v.coloured};
}

py::dict view_dict(const ViewInfo& v) {
  return py::dict(py::arg("object") = v.object, py::arg("name") = v.name,
                  py::arg("source") = v.source, py::arg("points") = v.points,
                  py::arg("coloured") = v.coloured);
}

// The class, its constructor, what it holds and its size.
py::class_<SharedDatabase> database_class(py::module_& m) {
  return py::class_<SharedDatabase>(m, "_Database")
      .def(py::init([](const std::string& path, bool create, double voxel_size,
                       double normal_radius, const std::vector<double>& fpfh_radii) {
             return without_gil([&] {
               if (create) {
                 const bool given =
                     !std::isnan(voxel_size) || !std::isnan(normal_radius) || !fpfh_radii.empty();
                 return std::make_unique<SharedDatabase>(open_database(
                     path, descriptor_params(voxel_size, normal_radius, fpfh_radii), given));
               }
               return std::make_unique<SharedDatabase>(load_database(path));
             });
           }),
           py::arg("path"), py::arg("create"), py::arg("voxel_size"), py::arg("normal_radius"),
           py::arg("fpfh_radii"))
      .def_property_readonly("path", [](const SharedDatabase& d) { return d.snapshot()->dir; })
      .def_property_readonly("objects",
                             [](const SharedDatabase& d) { return d.snapshot()->objects(); })
      .def_property_readonly("damaged",
                             [](const SharedDatabase& d) { return d.snapshot()->damaged; })
      .def("__len__", [](const SharedDatabase& d) { return d.snapshot()->views.size(); });
}

// Reading the views, the summary and the check.
void add_database_reads(py::class_<SharedDatabase>& cls) {
  cls.def("view",
          [](const SharedDatabase& d, std::int64_t i) {
            const auto db = d.snapshot();
            if (i < 0 || i >= static_cast<std::int64_t>(db->views.size()))
              throw py::index_error("view " + std::to_string(i) + ": the database has " +
                                    std::to_string(db->views.size()) + " views");
            const ModelView& v = db->views[i];
            std::vector<float> xyz;
            without_gil([&] {  // a stored view's body is read here
              const Cloud& c = v.cloud();
              xyz.reserve(c.points.size() * 3);
              for (const auto& p : c.points)
                for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(p[k]));
            });
            py::dict out = view_dict(view_info(v));
            const auto n = static_cast<py::ssize_t>(xyz.size() / 3);
            out["xyz"] = to_numpy(std::move(xyz), {n, 3});
            return out;
          })
      .def("info",
           [](const SharedDatabase& d) { return json_to_python(database_info(*d.snapshot())); })
      .def("check", [](const SharedDatabase& d) {
        DatabaseCheck c;
        without_gil([&] { c = check_database(d.snapshot()->dir); });
        py::dict out;
        out["views"] = c.views;
        out["whole"] = c.whole;
        out["damaged"] = c.damaged;
        return out;
      });
}

// Changing the database: removing, renaming, adding objects.
void add_database_changes(py::class_<SharedDatabase>& cls) {
  cls.def(
         "remove",
         [](SharedDatabase& d, const std::string& object) {
           return without_gil(
               [&] { return d.change([&](Database& db) { return remove_object(db, object); }); });
         },
         py::arg("object"))
      .def(
          "rename",
          [](SharedDatabase& d, const std::string& from, const std::string& to) {
            return without_gil([&] {
              return d.change([&](Database& db) { return rename_object(db, from, to); });
            });
          },
          py::arg("object"), py::arg("to"))
      .def(
          "add_view",
          [](SharedDatabase& d, const std::string& object, const Frame& points,
             const std::array<double, 3>& sensor, const std::string& source) {
            const Eigen::Vector3d viewpoint(sensor[0], sensor[1], sensor[2]);
            ViewInfo added;
            without_gil([&] {
              if (points.valid_count() == 0) throw InputError("points: no valid points");
              added = d.change([&](Database& db) {
                return view_info(add_view(db, object, points, viewpoint, source));
              });
            });
            return view_dict(added);
          },
          py::arg("object"), py::arg("points"), py::arg("viewpoint"), py::arg("source"))
      .def(
          "render",
          [](SharedDatabase& d, const std::string& object, const std::string& mesh_path,
             double scale, int views, double distance, double depth_noise, std::uint32_t seed) {
            std::vector<ViewInfo> added;
            without_gil([&] {
              // The name is checked by add_view() too; here before the rendering's work.
              if (object.empty() || object == kUnknown)
                throw InputError("object name: expected a non-empty name other than \"unknown\"");
              if (views < 1 || views > 1000) throw InputError("views: expected 1 to 1000");
              if (!(distance >= 0) || !std::isfinite(distance))
                throw InputError("distance: expected metres >= 0");
              if (!(depth_noise >= 0 && depth_noise < 1))
                throw InputError("depth_noise: expected metres in [0, 1)");
              const Mesh mesh = read_mesh(mesh_path, scale);
              check_mesh_units(mesh, mesh_path, scale == 1.0 ? "m" : "mm", "units=");
              ViewSphereParams p;
              p.views = views;
              p.distance = distance;
              p.depth_noise = depth_noise;
              p.seed = seed;
              const auto rendered = render_views(mesh, p);
              for (std::size_t i = 0; i < rendered.size(); ++i) {
                if (rendered[i].points.size() < 10) continue;  // the camera sees almost nothing
                const auto& e = rendered[i].eye;
                char source[512];
                std::snprintf(source, sizeof source,
                              "%s view %zu/%d, camera at (%.3f, %.3f, %.3f) m", mesh_path.c_str(),
                              i + 1, views, e.x(), e.y(), e.z());
                added.push_back(d.change([&](Database& db) {
                  return view_info(add_view(db, object, rendered[i].points, e, source));
                }));
              }
            });
            py::list out;
            for (const ViewInfo& v : added) out.append(view_dict(v));
            return out;
          },
          py::arg("object"), py::arg("mesh"), py::arg("scale"), py::arg("views"),
          py::arg("distance"), py::arg("depth_noise"), py::arg("seed"));
}

}  // namespace

void bind_database(py::module_& m) {
  py::class_<SharedDatabase> cls = database_class(m);
  add_database_reads(cls);
  add_database_changes(cls);
}

}  // namespace proxseg::python
