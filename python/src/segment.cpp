// proxseg.segment(): parameters as dicts laid out like the JSON config, results as numpy arrays
// and the CLI's report.
#include <proxseg/core/pipeline.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>

#include "bindings.hpp"
#include "segment.hpp"

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

void bind_segment(py::module_& m) {
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
        SegmentResult r;
        {
          py::gil_scoped_release release;
          r = segment(frame, p);
        }
        return segmentation_dict(frame, p, std::move(r));
      },
      py::arg("frame"), py::arg("params"));
}

}  // namespace proxseg::python
