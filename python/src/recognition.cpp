// proxseg.recognize() and recognize_object() [paper 3.4]: objects with names, scores and poses,
// the per-point object ids, and for a scene the segmentation it started from.
#include <proxseg/core/errors.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/io/view_page.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <chrono>

#include "bindings.hpp"
#include "database.hpp"
#include "segment.hpp"
#include "stop.hpp"

namespace proxseg::python {
namespace {

RecognitionParams recognition_params(const py::handle& params) {
  RecognitionParams p = recognition_params_from_json(python_to_json(params));
  validate(p);
  return p;
}

std::shared_ptr<const Database> non_empty(const SharedDatabase& d) {
  auto db = d.snapshot();
  if (db->views.empty()) throw InputError(db->dir + ": the database has no views");
  return db;
}

// Per object: "report" (its entry of the CLI's report: name, scores, pose, view, runner-up,
// times, colour in the picture) and "points" (numpy int32 frame point indices).
py::list objects_list(std::vector<SceneObject>& objects, const Database& db) {
  const nlohmann::json reports = recognition_candidates_json(objects, db);
  py::list out;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    py::dict o;
    o["report"] = json_to_python(reports[i]);
    const auto n = static_cast<py::ssize_t>(objects[i].points.size());
    o["points"] = to_numpy(std::move(objects[i].points), {n});
    out.append(o);
  }
  return out;
}

// What RecognitionResult.save writes from: the objects and the report as the CLI would make them,
// and the database snapshot whose views the picture draws.
struct RecognitionOutput {
  std::vector<SceneObject> objects;
  nlohmann::json report;
  std::shared_ptr<const Database> db;
  bool scene = true;
};

std::shared_ptr<RecognitionOutput> recognition_output(const std::vector<SceneObject>& objects,
                                                      const std::shared_ptr<const Database>& db,
                                                      const std::string& input,
                                                      const RecognitionParams& rec,
                                                      const SegmentParams* seg,
                                                      nlohmann::json times) {
  auto out = std::make_shared<RecognitionOutput>();
  out->objects = objects;
  out->db = db;
  out->scene = seg != nullptr;
  out->report = recognition_report(input, db->dir, *db, rec, seg, objects);
  out->report["times_ms"] = std::move(times);
  return out;
}

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// The recognition outputs and their writing.
void bind_recognition_outputs(py::module_& m) {
  py::class_<RecognitionOutput, std::shared_ptr<RecognitionOutput>>(
      m, "_RecognitionOutput", "What RecognitionResult.save writes from (not picklable).");
  m.def(
      "_write_recognition",
      [](const std::string& prefix, const Frame& frame, const RecognitionOutput& out,
         const std::string& outputs) {
        const OutputSet set = parse_outputs(outputs, "outputs");
        without_gil([&] {
          write_recognition(prefix, frame, out.objects, *out.db, out.report, out.scene, set);
        });
        std::vector<std::string> files;
        for (const std::string& f : output_files(prefix, set, true))
          if (out.scene || f == prefix + ".json" || f == prefix + ".png") files.push_back(f);
        return files;
      },
      py::arg("prefix"), py::arg("frame"), py::arg("output"), py::arg("outputs"));
  m.def(
      "_recognition_view_page",
      [](const Frame& frame, const RecognitionOutput& out, const std::string& title) {
        return without_gil([&] {
          return view_page(frame, {{"object", recognition_labels(frame, out.objects)}}, out.report,
                           {ViewOptions{}.max_points, title});
        });
      },
      py::arg("frame"), py::arg("output"), py::arg("title"),
      "The 3D page (io/view_page.hpp) of a recognised scene.");
  m.def(
      "_recognition_params",
      [](const py::dict& overrides) {
        RecognitionParams p = recognition_params_from_json(python_to_json(overrides));
        validate(p);
        return json_to_python(to_json(p));
      },
      py::arg("overrides"),
      "The default recognition parameters with `overrides` (JSON layout) applied and checked.");
}

// recognize() and recognize_scene().
void bind_recognition_calls(py::module_& m) {
  m.def(
      "_recognize_scene",
      [](const Frame& frame, const SharedDatabase& d, const py::dict& segment_params_dict,
         const py::dict& params, const std::string& input) {
        const SegmentParams seg = segment_params(segment_params_dict);
        const RecognitionParams rec = recognition_params(params);
        SegmentResult segmentation;
        std::vector<SceneObject> objects;
        std::vector<std::uint32_t> ids;
        double segment_ms = 0, recognize_ms = 0;
        const std::shared_ptr<const Database> snapshot = non_empty(d);
        const Database& db = *snapshot;
        without_gil([&] {
          auto t = std::chrono::steady_clock::now();
          segmentation = segment(frame, seg);
          segment_ms = ms_since(t);
          t = std::chrono::steady_clock::now();
          objects = recognize_scene(frame, segmentation.selection, db, rec);
          recognize_ms = ms_since(t);
          ids = recognition_labels(frame, objects);
        });
        py::dict out;
        out["output"] = recognition_output(objects, snapshot, input, rec, &seg,
                                           {{"segment", segment_ms},
                                            {"recognize", recognize_ms},
                                            {"total", segment_ms + recognize_ms}});
        out["objects"] = objects_list(objects, db);
        out["object_ids"] = to_numpy(std::move(ids), point_shape(frame));
        out["segmentation"] = segmentation_dict(frame, seg, std::move(segmentation));
        py::dict times;
        times["segment"] = segment_ms;
        times["recognize"] = recognize_ms;
        out["times_ms"] = times;
        return out;
      },
      py::arg("frame"), py::arg("db"), py::arg("segment_params"), py::arg("params"),
      py::arg("input"));
  m.def(
      "_recognize_object",
      [](const Frame& cloud, const SharedDatabase& d, const py::dict& params,
         const std::string& input) {
        const RecognitionParams rec = recognition_params(params);
        std::vector<SceneObject> objects;
        double recognize_ms = 0;
        const std::shared_ptr<const Database> db = non_empty(d);
        without_gil([&] {
          const auto t = std::chrono::steady_clock::now();
          objects.push_back(recognize_object(cloud, *db, rec));
          recognize_ms = ms_since(t);
        });
        py::dict out;
        out["output"] = recognition_output(objects, db, input, rec, nullptr,
                                           {{"recognize", recognize_ms}, {"total", recognize_ms}});
        out["objects"] = objects_list(objects, *db);
        py::dict times;
        times["recognize"] = recognize_ms;
        out["times_ms"] = times;
        return out;
      },
      py::arg("cloud"), py::arg("db"), py::arg("params"), py::arg("input"));
}

}  // namespace

void bind_recognition(py::module_& m) {
  bind_recognition_outputs(m);
  bind_recognition_calls(m);
}

}  // namespace proxseg::python
