// proxseg.segment(): parameters as dicts laid out like the JSON config, results as numpy arrays
// and the CLI's report.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/parameters.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/io/view_page.hpp>

#include "bindings.hpp"
#include "segment.hpp"
#include "stop.hpp"

namespace proxseg::python {

SegmentParams segment_params(const py::handle& params) {
  SegmentParams p = params_from_json(python_to_json(params));
  validate(p);
  return p;
}

py::dict segmentation_dict(const Frame& frame, const SegmentParams& params, SegmentResult&& r) {
  py::dict out;
  out["report"] = json_to_python(segmentation_report(frame, params, r));
  out["labels"] = to_numpy(std::move(r.point_labels), point_shape(frame));
  out["labels_kmeans"] = to_numpy(std::move(r.point_labels_kmeans), point_shape(frame));
  out["instances"] = to_numpy(std::move(r.selection.instance), point_shape(frame));
  py::list points;
  for (Candidate& c : r.selection.components) {
    const auto n = static_cast<py::ssize_t>(c.points.size());
    points.append(to_numpy(std::move(c.points), {n}));
  }
  out["candidate_points"] = points;
  return out;
}

namespace {

// segment() and its parameters.
void bind_segment_calls(py::module_& m) {
  m.def(
      "_segment_params",
      [](const std::string& preset_name, const py::dict& overrides) {
        SegmentParams p = params_from_json(python_to_json(overrides), preset(preset_name));
        validate(p);
        return json_to_python(to_json(p));
      },
      py::arg("preset"), py::arg("overrides"),
      "The named preset with `overrides` (JSON layout) applied and checked, as a dict.");
  m.def(
      "_segment",
      [](const Frame& frame, const py::dict& params) {
        const SegmentParams p = segment_params(params);
        SegmentResult r = without_gil([&] { return segment(frame, p); });
        return segmentation_dict(frame, p, std::move(r));
      },
      py::arg("frame"), py::arg("params"));
  m.def(
      "_write_segmentation",
      [](const std::string& prefix, const Frame& frame, const py::array& labels,
         const py::array& instances, const py::dict& report, const std::string& outputs,
         int threads) {
        const auto values = [&](const py::array& a, const char* name) {
          const auto u =
              py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>::ensure(a);
          if (!u) throw InputError(std::string(name) + ": expected integer labels");
          return std::vector<std::uint32_t>(u.data(), u.data() + u.size());
        };
        const std::vector<std::uint32_t> l = values(labels, "labels"),
                                         i = values(instances, "instances");
        const nlohmann::json r = python_to_json(report);
        const OutputSet set = parse_outputs(outputs, "outputs");
        return without_gil([&] {
          write_segmentation(prefix, frame, l, i, r, set, threads);
          return output_files(prefix, set, false);
        });
      },
      py::arg("prefix"), py::arg("frame"), py::arg("labels"), py::arg("instances"),
      py::arg("report"), py::arg("outputs"), py::arg("threads"));
}

// What a segmentation writes.
void bind_segment_outputs(py::module_& m) {
  m.def(
      "_view_page",
      [](const Frame& frame, const py::list& fields, const py::dict& report,
         const std::string& title) {
        std::vector<ViewField> f;
        for (const py::handle& item : fields) {
          const auto pair = item.cast<std::pair<std::string, py::array>>();
          const auto u =
              py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>::ensure(
                  pair.second);
          if (!u) throw InputError(pair.first + ": expected integer ids");
          f.push_back({pair.first, std::vector<std::uint32_t>(u.data(), u.data() + u.size())});
        }
        const nlohmann::json r = python_to_json(report);
        return without_gil([&] {
          return view_page(frame, f, r, {ViewOptions{}.max_points, title});
        });
      },
      py::arg("frame"), py::arg("fields"), py::arg("report"), py::arg("title"),
      "The 3D page (io/view_page.hpp) of frame with its per-point fields [(name, ids)].");
  m.def(
      "_parameter_table",
      [](const std::string& which) {
        py::list rows;
        for (const Parameter& row :
             which == "segmentation" ? segment_parameters() : recognition_parameters()) {
          py::dict d;
          d["key"] = row.key();
          d["section"] = row.section;
          d["name"] = row.name;
          d["type"] = row.type_name();
          d["default"] = std::visit([](const auto& v) { return py::cast(v); }, row.default_value);
          d["range"] = row.range_text();
          d["unit"] = row.unit;
          d["help"] = row.help;
          d["paper"] = row.paper;
          d["flag"] = row.flag.empty() ? "" : "--" + row.flag;
          d["choices"] = row.choices;
          d["old_key"] = row.old_key;
          rows.append(d);
        }
        return rows;
      },
      py::arg("which"));
}

}  // namespace

void bind_segment(py::module_& m) {
  bind_segment_calls(m);
  bind_segment_outputs(m);
}

}  // namespace proxseg::python
