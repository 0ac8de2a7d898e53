// The 3D page (view_page.hpp): the points (view_points.cpp), the layers and legends read from
// the report, the objects' boxes, and the page's HTML, style and script (src/io/page/assets/,
// compiled in as view_assets.cpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/core/selection.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/view_page.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

#include "io/json_file.hpp"
#include "io/page/page_text.hpp"
#include "io/page/view_assets.hpp"
#include "io/page/view_points.hpp"
#include "io/page/view_report.hpp"
#include "io/report/pictures.hpp"
#include "util/shown_names.hpp"

namespace proxseg {
namespace {

using nlohmann::json;

bool is_recognition(const json& report) {
  return report.contains("database");
}

json rgb_json(const Rgb& c) {
  return {c[0], c[1], c[2]};
}

// The valid points, every k-th when there are more than max_points (the notes say so).
std::vector<int> kept_points(const Frame& frame, std::size_t max_points,
                             std::vector<std::string>& notes) {
  std::vector<int> valid;
  for (std::size_t i = 0; i < frame.xyz.size(); ++i)
    if (frame.xyz[i].allFinite()) valid.push_back(static_cast<int>(i));
  if (valid.size() <= max_points || max_points == 0) return valid;
  const std::size_t every = (valid.size() + max_points - 1) / max_points;
  std::vector<int> kept;
  for (std::size_t i = 0; i < valid.size(); i += every) kept.push_back(valid[i]);
  notes.push_back("Every " + std::to_string(every) + "th of the " + std::to_string(valid.size()) +
                  " points is shown.");
  return kept;
}

// A recognition report's objects as legend entries, in report order, with their colour in
// PREFIX.png.
json object_legend(const json& report) {
  json legend = json::array();
  for (const json& c : report.value("candidates", json::array())) {
    json e = {{"id", c.at("id")},
              {"colour", c.value("colour", json{200, 200, 200})},
              {"name", c.value("name", "")},
              {"points", c.value("points", 0)}};
    for (const char* k : {"score", "fitness", "coverage", "pose"})
      if (c.contains(k)) e[k] = c[k];
    if (!c.contains("score") && c.contains("best") && c["best"].is_object())
      e["score"] = c["best"].value("score", 0.0);
    legend.push_back(e);
  }
  return legend;
}

// A segmentation report's instances: its candidates and background planes.
json instance_legend(const json& report) {
  std::map<std::uint32_t, json> by_id;  // in id order
  for (const char* kind : {"candidates", "background"})
    for (const json& c : report.value(kind, json::array())) {
      const std::uint32_t id = c.at("id");
      by_id[id] = {{"id", id},
                   {"colour", rgb_json(detail::label_rgb(id))},
                   {"name", std::string(kind) == "background" ? "background" : "candidate"},
                   {"points", c.value("points", 0)}};
    }
  json legend = json::array();
  for (auto& [id, e] : by_id) legend.push_back(std::move(e));
  return legend;
}

// Every id a field holds, coloured as the pictures colour labels.
json id_legend(const std::vector<std::uint32_t>& ids, const std::string& name) {
  std::map<std::uint32_t, std::size_t> count;
  for (std::uint32_t id : ids)
    if (id) ++count[id];
  json legend = json::array();
  for (const auto& [id, n] : count)
    legend.push_back({{"id", id},
                      {"colour", rgb_json(detail::label_rgb(id))},
                      {"name", name + " " + std::to_string(id)},
                      {"points", n}});
  return legend;
}

// A layer's title: the labels are the paper's (after the MRF, or k-means' when it is off) or,
// where the default's image-grid selection did not need them, its surfaces.
std::string layer_title(const std::string& field, const json& report) {
  if (field == "label") {
    if (!report.value("paper_labels", true)) return "Surfaces";
    return report.value("mrf", json::object()).value("enabled", true) ? "MRF labels"
                                                                      : "k-means labels";
  }
  static const std::map<std::string, std::string> titles = {{"label_kmeans", "k-means labels"},
                                                            {"instance", "Instances"},
                                                            {"object", "Recognised objects"}};
  const auto title = titles.find(field);
  return title == titles.end() ? field : title->second;
}

json layer_of(const ViewField& field, const json& report) {
  json layer = {{"key", field.name}, {"title", layer_title(field.name, report)}};
  if (field.name == "object" && is_recognition(report))
    layer["legend"] = object_legend(report);
  else if (field.name == "instance" && !is_recognition(report))
    layer["legend"] = instance_legend(report);
  else
    layer["legend"] = id_legend(field.ids, field.name == "instance" ? "instance" : "label");
  return layer;
}

// The box of a recognised object's points: along its pose's axes when it has one (the box at
// the estimated pose), else their principal axes.
json object_box(const Frame& frame, const std::vector<int>& points, const json& pose) {
  OrientedBox box = oriented_box(frame, points);
  if (pose.is_array() && pose.size() == 4) {  // 4x4 (check_view_report)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) box.axes(r, c) = pose[r][c].get<double>();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
    for (int p : points) {
      const Eigen::Vector3d q = box.axes.transpose() * frame.xyz[p].cast<double>();
      lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    }
    box.centre = box.axes * ((lo + hi) / 2);
    box.extent = hi - lo;
  }
  json axes = json::array();
  for (int a = 0; a < 3; ++a) axes.push_back({box.axes(0, a), box.axes(1, a), box.axes(2, a)});
  return {{"centre", {box.centre.x(), box.centre.y(), box.centre.z()}},
          {"axes", axes},
          {"extent", {box.extent.x(), box.extent.y(), box.extent.z()}}};
}

// The boxes drawn: a recognition's named objects (at their poses), or a segmentation's
// candidates (their boxes in the report).
json view_objects(const Frame& frame, const std::vector<ViewField>& fields, const json& report) {
  json objects = json::array();
  if (!is_recognition(report)) {
    for (const json& c : report.value("candidates", json::array()))
      if (c.contains("box"))
        objects.push_back(
            {{"id", c.at("id")},
             {"box", c["box"]},
             {"colour", rgb_json(detail::label_rgb(c.at("id").get<std::uint32_t>()))}});
    return objects;
  }
  const auto field = std::find_if(fields.begin(), fields.end(),
                                  [](const ViewField& f) { return f.name == "object"; });
  if (field == fields.end()) return objects;
  std::map<std::uint32_t, std::vector<int>> members;
  for (std::size_t i = 0; i < field->ids.size(); ++i)
    if (field->ids[i]) members[field->ids[i]].push_back(static_cast<int>(i));
  for (const json& e : object_legend(report)) {
    const std::uint32_t id = e.at("id");
    if (e.value("name", "") == kUnknown || members[id].size() < 3) continue;
    json o = {{"id", id},
              {"colour", e["colour"]},
              {"name", e["name"]},
              {"box", object_box(frame, members[id], e.value("pose", json()))}};
    if (e.contains("pose")) o["pose"] = e["pose"];
    objects.push_back(o);
  }
  return objects;
}

// Seen from the sensor, at the middle of the kept points.
json home_view(const Frame& frame, const std::vector<int>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int p : points) sum += frame.xyz[p].cast<double>();
  const Eigen::Vector3d target = points.empty() ? Eigen::Vector3d(0, 0, 1) : sum / points.size();
  return {{"target", {target.x(), target.y(), target.z()}},
          {"distance", std::max(0.1, target.norm())}};
}

}  // namespace

std::string view_page(const Frame& frame, const std::vector<ViewField>& fields, const json& report,
                      const ViewOptions& options) {
  detail::check_view_report(report, "view page: report");
  for (const ViewField& f : fields)
    if (f.ids.size() != frame.xyz.size())
      throw InputError("view page: field " + f.name + " has " + std::to_string(f.ids.size()) +
                       " ids for " + std::to_string(frame.xyz.size()) + " points");
  std::vector<std::string> notes;
  const std::vector<int> points = kept_points(frame, options.max_points, notes);
  const detail::ViewPoints encoded = detail::encode_view_points(frame, points, fields);
  json meta = {{"title", options.title.empty() ? std::string("proxseg") : options.title},
               {"points", points.size()},
               {"arrays", encoded.arrays},
               {"bounds", encoded.bounds},
               {"notes", notes},
               {"view", home_view(frame, points)},
               {"objects", view_objects(frame, fields, report)}};
  meta["layers"] = json::array({{{"key", "colour"}, {"title", "Scene colours"}}});
  for (const ViewField& f : fields) meta["layers"].push_back(layer_of(f, report));
  meta["default_layer"] = fields.empty() ? "colour" : fields.back().name;
  return detail::page_text(detail::kViewerHtml, detail::kViewerCss,
                           {{"@META@", detail::script_safe(dump_shown(meta))},
                            {"@JS@", detail::kViewerJs},
                            {"@POINTS@", encoded.base64}});
}

std::string view_page_of(const std::string& prefix, const ViewOptions& options) {
  const std::string report_path = prefix + ".json", pcd_path = prefix + ".pcd";
  const json report = detail::read_json_file(report_path);
  detail::check_view_report(report, report_path);
  std::vector<ViewField> fields;
  Frame frame;
  for (const char* name : is_recognition(report) ? std::vector<const char*>{"object"}
                                                 : std::vector<const char*>{"label", "instance"}) {
    frame = read_pcd(pcd_path, name);
    if (frame.label.empty())
      throw InputError(pcd_path + ": no field " + name + " (expected proxseg's labelled cloud)");
    fields.push_back({name, std::move(frame.label)});
  }
  ViewOptions o = options;
  if (o.title.empty()) o.title = prefix.substr(prefix.find_last_of('/') + 1);
  return view_page(frame, fields, report, o);
}

}  // namespace proxseg
