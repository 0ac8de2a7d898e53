// Batch work (proxseg/io/batch.hpp) for the Python runners (proxseg.dask): frames as plain dicts
// (picklable, so that they travel to Dask workers), one frame's job with the GIL released, and the
// JSON-lines summary the CLI writes too.
#include <proxseg/io/batch.hpp>
#include <proxseg/io/batch_start.hpp>
#include <proxseg/io/memory.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/recognize_frame.hpp>

#include <set>

#include "bindings.hpp"
#include "database.hpp"
#include "stop.hpp"

namespace proxseg::python {
namespace {

py::dict to_dict(const FrameSource& f) {
  py::dict d;
  d["id"] = f.id;
  d["cloud"] = f.cloud;
  d["color"] = f.colour;
  d["depth"] = f.depth;
  d["camera"] = f.camera;
  if (!f.unreadable.empty()) {
    d["unreadable"] = f.unreadable;
    d["problem"] = f.problem;
  }
  return d;
}

FrameSource from_dict(const py::handle& h) {
  if (!py::isinstance<py::dict>(h))
    throw py::type_error(
        "a frame is a dict with id, cloud, color, depth, camera (and unreadable, problem)");
  const auto d = py::reinterpret_borrow<py::dict>(h);
  FrameSource f;
  auto get = [&](const char* key, std::string& out) {
    if (d.contains(key)) out = py::cast<std::string>(d[key]);
  };
  get("id", f.id);
  get("cloud", f.cloud);
  get("color", f.colour);
  get("depth", f.depth);
  get("camera", f.camera);
  get("unreadable", f.unreadable);
  get("problem", f.problem);
  if (f.id.empty()) throw py::value_error("a frame needs an \"id\"");
  return f;
}

std::vector<FrameSource> from_list(const py::iterable& frames) {
  std::vector<FrameSource> out;
  for (const auto& f : frames) out.push_back(from_dict(f));
  return out;
}

py::list to_list(const std::vector<FrameSource>& frames) {
  py::list out;
  for (const auto& f : frames) out.append(to_dict(f));
  return out;
}

// The frames of a batch: found, segmented, recognised.
void bind_batch_frames(py::module_& m) {
  m.def(
      "_discover_frames",
      [](const std::vector<std::string>& sources, const std::string& colour,
         const std::string& depth, const std::string& meta, const std::string& intrinsics) {
        std::vector<FrameSource> frames;
        without_gil([&] {
          frames = discover_frames(sources, RgbdNaming{colour, depth, meta, intrinsics});
        });
        return to_list(frames);
      },
      py::arg("sources"), py::arg("color"), py::arg("depth"), py::arg("meta"),
      py::arg("intrinsics"));
  m.def(
      "_start_batch",
      [](const std::vector<std::string>& sources, const std::string& colour,
         const std::string& depth, const std::string& meta, const std::string& intrinsics,
         const std::string& out_dir, const py::handle& header, bool resume) {
        BatchPlan plan;
        plan.sources = sources;
        plan.naming = RgbdNaming{colour, depth, meta, intrinsics};
        plan.resume = resume;
        plan.runner = "dask";
        const nlohmann::json h = python_to_json(header);
        BatchStart b;
        without_gil([&] { b = start_batch(plan, out_dir, h); });
        py::dict out;
        out["frames"] = b.frames.size();
        out["todo"] = to_list(b.todo);
        out["damaged"] = b.damaged;
        out["redone"] = b.redone;
        out["changed"] = b.changed;
        out["unproven"] = b.unproven;
        out["log"] = py::cast(std::move(b.log));
        return out;
      },
      py::arg("sources"), py::arg("color"), py::arg("depth"), py::arg("meta"),
      py::arg("intrinsics"), py::arg("out_dir"), py::arg("header"), py::arg("resume"));
  m.def(
      "_segment_frame",
      [](const py::handle& frame, const std::string& out_dir, const std::string& outputs,
         const py::handle& params) {
        const SegmentJob job{out_dir, parse_outputs(outputs),
                             params_from_json(python_to_json(params))};
        const FrameSource source = from_dict(frame);
        nlohmann::json row;
        without_gil([&] { row = segment_frame(source, job); });
        return json_to_python(row);
      },
      py::arg("frame"), py::arg("out_dir"), py::arg("outputs"), py::arg("params"));
  m.def(
      "_recognize_frame",
      [](const py::handle& frame, const std::string& out_dir, const std::string& outputs,
         const py::handle& segmentation, const py::handle& recognition, const SharedDatabase& db,
         const std::string& db_dir, double load_ms) {
        const RecognizeJob job{out_dir,
                               parse_outputs(outputs),
                               params_from_json(python_to_json(segmentation)),
                               recognition_params_from_json(python_to_json(recognition)),
                               db_dir,
                               load_ms};
        const FrameSource source = from_dict(frame);
        nlohmann::json row;
        without_gil([&] { row = recognize_frame(source, job, *db.snapshot()); });
        return json_to_python(row);
      },
      py::arg("frame"), py::arg("out_dir"), py::arg("outputs"), py::arg("segmentation"),
      py::arg("recognition"), py::arg("db"), py::arg("db_dir"), py::arg("load_ms"));
}

// The logs of a batch, its outputs and the resident set.
void bind_batch_logs(py::module_& m) {
  m.def(
      "_canonical_outputs",
      [](const std::string& outputs) { return to_string(parse_outputs(outputs)); },
      py::arg("outputs"));
  m.def(
      "_remove_stale_temporaries",
      [](const std::string& out_dir, const py::iterable& frames) {
        const auto list = from_list(frames);
        return without_gil([&] { return remove_stale_temporaries(out_dir, list); });
      },
      py::arg("out_dir"), py::arg("frames"));
  m.def(
      "_summarize",
      [](const std::vector<std::string>& logs, bool whole_batch) {
        return json_to_python(summarize(logs, whole_batch));
      },
      py::arg("logs"), py::arg("whole_batch"));
  m.def("_summary_logs", &summary_logs, py::arg("out_dir"));
  m.def(
      "_frame_rows",
      [](const std::string& out_dir) {
        nlohmann::json rows;
        without_gil([&] { rows = frame_rows(out_dir); });
        return json_to_python(rows);
      },
      py::arg("out_dir"));
  m.def("_peak_resident_mib", &peak_resident_mib);
  m.def("_resident_mib", &resident_mib);

  py::class_<SummaryLog>(m, "_SummaryLog")
      .def(py::init([](const std::string& out_dir, const std::string& name,
                       const py::handle& header, bool resume) {
             return std::make_unique<SummaryLog>(out_dir, name, python_to_json(header), resume);
           }),
           py::arg("out_dir"), py::arg("name"), py::arg("header"), py::arg("resume"))
      .def(
          "append", [](SummaryLog& log, const py::handle& row) { log.append(python_to_json(row)); },
          py::arg("row"))
      .def("close", &SummaryLog::close, py::arg("interrupted"), py::arg("peak_rss_mib"))
      .def_property_readonly("path", &SummaryLog::path);
}

}  // namespace

void bind_batch(py::module_& m) {
  bind_batch_frames(m);
  bind_batch_logs(m);
}

}  // namespace proxseg::python
