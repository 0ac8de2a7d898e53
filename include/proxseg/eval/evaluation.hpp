// Evaluation of segmentations on labelled scenes [paper 4]: per-scene scores under the mOSD
// "objects" and "parts" schemes, and summaries per method and category (CSV, Markdown, JSON).
// The metrics themselves are in metrics.hpp; their definitions in docs/metrics.md.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/eval/metrics.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <Eigen/Core>
#include <cstdint>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg {

// The evaluated truth of a labelled frame: 0 where the position is not finite or the label is 0,
// else the mOSD object (table -> 1, label / 10 for objects) or part (table -> 1, label).
std::vector<std::uint32_t> truth_objects(const Frame& frame);
std::vector<std::uint32_t> truth_parts(const Frame& frame);
// The truth id of the supporting background in both schemes.
inline const std::vector<std::uint32_t> kMosdBackground = {1};

struct SceneScores {
  std::string scene;     // file name without directory
  std::string category;  // see scene_category
  std::string method;    // e.g. "proxseg default", "lccp"
  double seconds = 0;    // wall time of the method on this scene (0 if not timed)
  SegmentationScores objects, parts;
};

// Scores a predicted per-point labelling against the frame's truth (sizes must match).
SceneScores score_scene(const Frame& truth, const std::vector<std::uint32_t>& predicted);

// The category of a scene from its name: an mOSD learn scene ("learn17.pcd" -> "stacked"): 0-16
// boxes, 17-24 stacked, 25-32 occluded, 33-44 cylindric; a name starting with "clutter" (the
// generated clutter set of `proxseg synth --clutter`, clutter-001.pcd ...) -> "clutter"; any
// other name -> "other".
std::string scene_category(const std::string& scene_name);

// The number at the end of a scene's file stem ("clutter-017.pcd" -> 17, "learn3.pcd" -> 3), or
// -1 if the stem does not end in a digit.
long scene_number(const std::string& scene_name);

// The cross-validation fold of a scene (seg_cv): its category for mOSD learn scenes (boxes,
// stacked, occluded, cylindric), "<kind>-odd" / "<kind>-even" for generated scenes (clutter,
// piles, occlusion: the file name's prefix) by the parity of their number (the seed of the
// generated scene; no number -> even), "other" else.
std::string scene_fold(const std::string& scene_name);

// The files of a folder with one of the extensions (lower case), in natural order (learn2 before
// learn10). InputError if the folder does not exist or holds no such file.
std::vector<std::filesystem::path> scene_files(const std::string& dir,
                                               const std::vector<std::string>& extensions = {
                                                   ".pcd"});

// Means over scenes of every score, per method and category, plus an "all" category.
struct SummaryRow {
  std::string method, category;
  int scenes = 0;
  double seconds = 0;
  // Means of the scores; the int counts stay 0 here. Except lost_in_background_share (objects
  // and parts): pooled, the sum of lost objects over the sum of truth objects of the scenes.
  SegmentationScores objects, parts;
  double over_segmented = 0, under_segmented = 0, truth_objects = 0;  // mean counts, objects
  double lost_in_background = 0, unassigned_objects = 0;              // mean counts, objects
};
std::vector<SummaryRow> summarize(const std::vector<SceneScores>& scenes);

// Per-scene rows: every score of both schemes (objects_*, parts_*), lost_in_background,
// unassigned_objects and lost_in_background_share included.
std::string scenes_csv(const std::vector<SceneScores>& scenes);
std::string summary_markdown(const std::vector<SummaryRow>& rows);
nlohmann::json summary_json(const std::vector<SummaryRow>& rows);
nlohmann::json scores_json(const SegmentationScores& s);

// Cross-validated choice among variants (bench/seg_cv.cpp). scores[scene][variant]: a score to
// maximise (e.g. object F) of every variant on every scene; fold_of_scene[scene]: the fold the
// scene belongs to. For each fold the variant with the best mean score over the scenes OUTSIDE
// the fold is chosen (ties -> the first variant) and scored on the fold's scenes, so no scene's
// score comes from a choice that saw it. Throws std::invalid_argument if the matrix is empty or
// not rectangular, the sizes differ, or there are fewer than two folds.
struct CrossValidation {
  std::vector<std::string> folds;               // in first-seen order of fold_of_scene
  std::vector<int> fold_scenes;                 // per fold: its number of scenes
  std::vector<std::vector<double>> fold_means;  // [fold][variant]: mean score on the fold
  std::vector<double> variant_means;            // per variant: mean over all scenes
  std::vector<int> chosen;                      // per fold: the variant chosen without the fold
  std::vector<double> training;                 // per fold: that variant's mean outside the fold
  std::vector<double> held_out;                 // per fold: that variant's mean on the fold
  std::vector<int> scene_variant;               // per scene: the variant chosen for its fold
  std::vector<double> scene_score;              // per scene: that variant's score on it
  double overall = 0;                           // mean of scene_score: the cross-validated score
  int best_in_sample = 0;                       // the variant with the best mean over all scenes
  double in_sample = 0;                         // its mean (optimistic: chosen on the same scenes)
};
CrossValidation cross_validate(const std::vector<std::vector<double>>& scores,
                               const std::vector<std::string>& fold_of_scene);

// ---- Recognition on YCB-Video frames (../shared/data/ycbv) ----

struct ObjectTruth {
  std::string name;         // class name from classes.txt
  int class_index = 0;      // 1-based, the value of its pixels in -label.png
  Eigen::Matrix4d pose;     // camera <- model (meta.json "poses")
  std::vector<int> points;  // its pixels (indices into frame) with a valid depth
};
struct YcbFrame {
  Frame frame;            // camera frame, organized
  Intrinsics intrinsics;  // from -meta.json
  std::vector<ObjectTruth> objects;
};
// Reads DIR/<stem>-color.png, -depth.png, -label.png and -meta.json; classes from classes.txt.
YcbFrame read_ycb_frame(const std::string& dir, const std::string& stem,
                        const std::vector<std::string>& classes);
// Non-empty lines of a text file (classes.txt).
std::vector<std::string> read_lines(const std::string& path);

// The paper's occlusion generator [4]: a random point of the view and a random radius (uniform
// in [0, max_radius]); every point within the radius of that point is removed. The share of
// removed points is what the paper's Table 3 bins by. Same view and seed, same occlusion.
struct Occlusion {
  std::vector<Eigen::Vector3d> points;  // what is left, in the view's order
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0;
  double removed_share = 0;  // removed / view points
};
Occlusion occlude(const std::vector<Eigen::Vector3d>& view, double max_radius, std::uint64_t seed);

// The rotational symmetries of a model that are symmetries of its box (the 180 degree turns
// about its axes, the 90 degree turns about an axis whose two other extents are equal, and their
// products) and that map the model's points onto themselves within tolerance (mean distance), as
// model-frame transforms about the box centre. The box is found from the model's face normals
// (principal axes as a fallback). The identity is always first.
std::vector<Eigen::Matrix4d> box_symmetries(const std::vector<Eigen::Vector3d>& model,
                                            double tolerance);
struct PoseError {
  double translation = 0;  // metres
  double rotation_deg = 0;
};
// Error of an estimated pose (camera <- model) against the truth, the least over the truth's
// symmetric equivalents truth * S.
PoseError pose_error(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth,
                     const std::vector<Eigen::Matrix4d>& symmetries);
// The error of a pose of an object that looks the same under any turn about an axis (model
// frame: a point and a direction), e.g. a mug whose handle is hidden: the angle between the
// estimated and true axes and the distance between the estimated and true positions of centre.
PoseError axial_pose_error(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth,
                           const Eigen::Vector3d& centre, const Eigen::Vector3d& axis);

}  // namespace proxseg
