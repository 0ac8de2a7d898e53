// Segmentation and recognition outputs: PREFIX.pcd, PREFIX.png, PREFIX.json (all written
// atomically).
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/recognition_types.hpp>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg {

// Which files a segmentation or recognition writes beside PREFIX (the CLI's --outputs).
struct OutputSet {
  // PREFIX.label.png and PREFIX.instance.png (segment), PREFIX.object.png (recognize a scene):
  // 16-bit grey PNGs of the frame's size (label_png), one value per point, the compact output of
  // a large batch.
  bool labels = false;
  bool pcd = true;    // PREFIX.pcd: the frame and its labels, binary_compressed
  bool png = true;    // PREFIX.png: the picture
  bool json = true;   // PREFIX.json: the report
  bool html = false;  // PREFIX.html: the 3D page (view_page.hpp)
};
// "labels,pcd,png,json,html": any of them, comma-separated, or "all", or "none" (alone: no file,
// the results computed and reported all the same). InputError naming the field and the unknown
// word, or for an empty list.
OutputSet parse_outputs(const std::string& list, const std::string& field = "--outputs");
// The canonical list, in the order labels,pcd,png,json,html; "none" for no output.
std::string to_string(const OutputSet& outputs);
// The files a segmentation (recognition = false) or the recognition of a scene writes for these
// outputs.
std::vector<std::string> output_files(const std::string& prefix, const OutputSet& outputs,
                                      bool recognition);

// What made a report: {"version": PROXSEG_VERSION, "commit": git_commit()}; every JSON report
// of the CLI carries it under "proxseg", beside its parameters.
nlohmann::json build_info();
// j as JSON text (j.dump(indent)) with names shown: a string that is not UTF-8 (a file or frame
// name's bytes) is written with its bad bytes as \xFF text, and one holding text that reads as
// such an escape is escaped too (docs/robustness.md). What reports, summaries and --json print;
// never throws on such bytes.
std::string json_text(const nlohmann::json& j, int indent = -1);

// The report written to PREFIX.json: proxseg's build_info, parameters, the input (with "colour":
// whether it has colours), the feature blocks computed ("features": colour, texture, shape, and a
// "note" when the input's lack of colour took blocks off, colourless_note), stage times, counts,
// energies, label sizes.
nlohmann::json segmentation_report(const Frame& frame, const SegmentParams& params,
                                   const SegmentResult& result);
// Which of the blocks `features` asks for a frame without colours takes off: "the colour and
// texture blocks are off", "the colour block is off" (no texture asked for, or no image grid) or
// "the texture block is off"; "" for a frame with colours or when none of them was asked for.
std::string colourless_note(const Frame& frame, const FeatureParams& features);
// A picture of the labels: the colour image with labels blended in and boundaries drawn
// (organized input), or the points rendered from the sensor origin (unorganized input); a frame
// without colours shows grey by depth instead (nearer is lighter). PNG bytes.
std::string label_image_png(const Frame& frame, const std::vector<std::uint32_t>& point_labels);
// The labels as a 16-bit grey PNG of frame.width x frame.height pixels (an unorganized frame:
// one row of frame.size() pixels), one value per point in point order: a compact, lossless
// per-point label output that image tools open; read_label_png (cloud_io.hpp) reads it back.
// InputError naming the largest label if one exceeds 65535 (a 16-bit sample cannot hold it);
// std::invalid_argument if labels is not one per point or the frame is empty.
std::string label_png(const Frame& frame, const std::vector<std::uint32_t>& labels);
// Writes output_files(prefix, outputs, false) (PREFIX.pcd with fields label and instance,
// PREFIX.png, PREFIX.json, and with outputs.labels PREFIX.label.png and PREFIX.instance.png): all
// made in memory and written with write_files_atomic, all or none. Returns the report (also when
// outputs.json is off).
nlohmann::json write_segmentation(const std::string& prefix, const Frame& frame,
                                  const SegmentParams& params, const SegmentResult& result,
                                  const OutputSet& outputs = {});
// The same files from what they are made of: the per-point labels and instances of a result and
// its report (segmentation_report), as the Python module's SegmentResult.save keeps them.
// threads != 1: the picture is made on a second thread. InputError when the arrays are not one
// per point of frame.
void write_segmentation(const std::string& prefix, const Frame& frame,
                        const std::vector<std::uint32_t>& point_labels,
                        const std::vector<std::uint32_t>& instance, const nlohmann::json& report,
                        const OutputSet& outputs, int threads);

// Writes one unorganized PCD (x y z rgb; x y z for a frame without colours) per candidate object
// (not the background) to DIR/candidate_<id>.pcd, creating DIR; all files or none. Returns the
// paths written.
std::vector<std::string> write_candidates(const std::string& dir, const Frame& frame,
                                          const SegmentResult& result);

// ---- Recognition outputs (proxseg recognize): the objects of recognize_scene() or the one of
// recognize_object() ----

// One candidate's entry of PREFIX.json: name, fitness, coverage, score, pose (4x4 rows,
// candidate frame <- model frame), the view, the runner-up and times.
nlohmann::json recognition_json(const SceneObject& object, const Database& db);
// PREFIX.json's "candidates": recognition_json of each object and its "colour" [r, g, b] in
// PREFIX.png, so that a program can match the report to the picture too.
nlohmann::json recognition_candidates_json(const std::vector<SceneObject>& objects,
                                           const Database& db);
// The colour of each object in PREFIX.png, in order. Named objects take a fixed palette of 30
// colours (10 hues x bright, dark and pale; neighbouring ids far apart in hue), unknown ones grey
// shades (32), each in id order; past that the colours repeat (the ids drawn on the objects still
// tell them apart). Depends only on the objects' order and names: the same scene, the same colours.
std::vector<Rgb> recognition_colours(const std::vector<SceneObject>& objects);
// PREFIX.pcd's field `object`: per frame point the id of the object that holds it, 0 for none.
// std::invalid_argument if a point index is outside the frame or two objects hold one point.
std::vector<std::uint32_t> recognition_labels(const Frame& frame,
                                              const std::vector<SceneObject>& objects);
// The scene with every object in its colour (its frame points tinted and outlined, a named
// object's aligned model view drawn over it) and its id at its centroid (organized input: over
// the colour image, frame size, or grey by depth without colours; unorganized input: the points
// seen from the sensor, 640x480), beside a legend on the right: per object its colour swatch, id,
// name and best score, in report order (more columns when they do not fit the height). PNG bytes.
std::string recognition_image_png(const Frame& frame, const std::vector<SceneObject>& objects,
                                  const Database& db);
// The report of `proxseg recognize` before its times and files: the input, the database
// (dir, objects, views, descriptor), build_info, the parameters (segmentation only for a scene,
// seg != nullptr) and the candidates (recognition_candidates_json).
nlohmann::json recognition_report(const std::string& input, const std::string& db_dir,
                                  const Database& db, const RecognitionParams& rec,
                                  const SegmentParams* seg,
                                  const std::vector<SceneObject>& objects);
// Writes PREFIX.json (the report with "picture", and for a scene "labels", added), PREFIX.png and
// for a scene PREFIX.pcd (the frame with field `object` = recognition_labels) and, with
// outputs.labels, PREFIX.object.png (the same ids, label_png), each when outputs asks for it. All
// are made in memory and written with write_files_atomic: all or none. Returns the report.
nlohmann::json write_recognition(const std::string& prefix, const Frame& frame,
                                 const std::vector<SceneObject>& objects, const Database& db,
                                 nlohmann::json report, bool scene, const OutputSet& outputs = {});

}  // namespace proxseg
