// Segmentation outputs: PREFIX.pcd, PREFIX.png, PREFIX.json (all written atomically).
#pragma once
#include <proxseg/pipeline.hpp>
#include <proxseg/recognition.hpp>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg {

// What made a report: {"version": PROXSEG_VERSION, "commit": git_commit()}; every JSON report
// of the CLI carries it under "proxseg", beside its parameters.
nlohmann::json build_info();

// The report written to PREFIX.json: proxseg's build_info, parameters, stage times, counts,
// energies, label sizes.
nlohmann::json segmentation_report(const Frame& frame, const SegmentParams& params,
                                   const SegmentResult& result);
// A picture of the labels: the colour image with labels blended in and boundaries drawn
// (organized input), or the points rendered from the sensor origin (unorganized input). PNG bytes.
std::string label_image_png(const Frame& frame, const std::vector<std::uint32_t>& point_labels);
// Writes PREFIX.pcd, PREFIX.png and PREFIX.json; each appears whole or not at all. Returns the
// report written to PREFIX.json.
nlohmann::json write_segmentation(const std::string& prefix, const Frame& frame,
                                  const SegmentParams& params, const SegmentResult& result);

// Writes one unorganized PCD (x y z rgb) per candidate object (not the background) to
// DIR/candidate_<id>.pcd, creating DIR; all files or none. Returns the paths written.
std::vector<std::string> write_candidates(const std::string& dir, const Frame& frame,
                                          const SegmentResult& result);

// ---- Recognition outputs (proxseg recognize) ----

struct RecognizedObject {
  int id = 0;              // 1.. in the scene (0 for a cloud given with --object)
  std::size_t points = 0;  // the object's points
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::vector<std::uint32_t> instances;  // the selection's candidates it holds points of
  std::string origin = "candidate";      // candidate, split or merged (recognize_scene)
  Recognition recognition;
};
// One candidate's entry of PREFIX.json: name, fitness, coverage, score, pose (4x4 rows,
// candidate frame <- model frame), the view, the runner-up and times.
nlohmann::json recognition_json(const RecognizedObject& object, const Database& db);
// The scene with every recognised object's aligned model view drawn over it in its own colour
// and labelled with its name and score (organized input: over the colour image, projected with a
// pinhole fitted to the cloud; unorganized input: the points seen from the sensor). PNG bytes.
std::string recognition_image_png(const Frame& frame, const std::vector<RecognizedObject>& objects,
                                  const Database& db);

}  // namespace proxseg
