// End-to-end scene recognition evaluation: generated cluttered tabletops (clutter.hpp) whose
// objects are partly drawn from a fixed catalogue (known objects, colour look-alikes, unknown
// objects), run through segment() + recognize_scene() [paper 3.1-3.4] or a peer, and scored
// against the ground truth: detection by point IoU (maximum-weight matching), recognition
// precision / recall / F1 over the known objects, unknown objects named, pose by ADD-S, and the
// ROC with negatives as the minimum score varies. bench/scene_bench (`make bench-scenes`) runs
// it; docs/metrics.md ("Scenes") defines the measures.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/clutter.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace proxseg {

// The scene set's catalogue: ClutterParams::catalogue plus what the scoring needs per entry.
// Known entries (in the database) come first.
struct SceneCatalogue {
  std::vector<CatalogueObject> entries;
  std::vector<char> known;  // per entry: 1 = in the database (a recogniser may name it)
  // Per entry: the mesh's vertices (object frame = model frame, metres), for ADD-S.
  std::vector<std::vector<Eigen::Vector3d>> model_points;
  std::vector<double> diameters;  // per entry: largest distance between two vertices, metres
};

// The 14 entries of the scene set. Known: the LINEMOD ape, can, cat, driller, duck and eggbox
// (obj_000001, 05, 06, 08, 09, 10 of models_dir, millimetres), "duck-blue" and "ape-green" (the
// same meshes, hue turned to blue / green, saturation and value kept: look-alikes that only
// colour tells apart), the markers "marker-red" and "marker-black" (one cylinder, radius
// 12.5 mm, 130 mm long, always lying) and the boxes "box-tea" (70 x 70 x 140 mm, red / white)
// and "box-rice" (80 x 60 x 160 mm, yellow / brown): near in shape, different in colour.
// Unknown (never in the database): the LINEMOD glue and holepuncher (obj_000011, 12).
// Throws InputError when models_dir lacks one of the meshes.
SceneCatalogue scene_catalogue(const std::string& models_dir);
// A catalogue of these entries, `known` per entry (1 = in the database), with the model points
// and diameters the scoring needs.
SceneCatalogue make_catalogue(std::vector<CatalogueObject> entries, std::vector<char> known);
// Index of the entry called name, -1 when there is none.
int catalogue_index(const SceneCatalogue& catalogue, const std::string& name);

// The database of the known entries: `views` render_views() each (render_database() of
// rec_eval.hpp), in memory or, with dir, written there and read back.
Database scene_database(const SceneCatalogue& catalogue, int views,
                        const DescriptorParams& descriptor, const std::string& dir = "");

// Seeds first, first + 1, ..., first + count - 1.
std::vector<std::uint32_t> seed_range(std::uint32_t first, int count);

// The scene set: the generator's defaults except for these.
struct SceneSetParams {
  int min_objects = 8, max_objects = 14;  // objects per scene, uniform
  // Probability that a free or touching object comes from the catalogue (the others are the
  // generator's random boxes and cylinders: unknown objects too).
  double catalogue_share = 0.75;
  // No LINEMOD meshes besides the catalogue's: they would be unknown look-alikes of the known
  // ones at a random scale.
  double mesh_share = 0;
  std::vector<std::uint32_t> dev_seeds = seed_range(1, 20);       // the development split
  std::vector<std::uint32_t> report_seeds = seed_range(101, 20);  // the report split
};

// The generator's parameters of scene `seed` (no models_dir: the meshes come with the
// catalogue).
ClutterParams scene_set_params(std::uint32_t seed, const SceneCatalogue& catalogue,
                               const SceneSetParams& params = {});

// One object of a generated scene as the scoring sees it.
struct TruthObject {
  std::uint32_t label = 0;  // ClutterObject::label
  std::string name;         // the catalogue entry's, else the generator's (box, cylinder, ...)
  int catalogue = -1;       // entry index, -1 = a random box or cylinder
  bool known = false;       // a catalogue entry that is in the database
  std::vector<int> points;  // frame point indices (valid points with its label), ascending
  Eigen::Matrix4d camera_from_model = Eigen::Matrix4d::Identity();
};
std::vector<TruthObject> scene_truth(const ClutterScene& scene, const SceneCatalogue& catalogue);

// One recognised object of a recogniser's answer for a scene.
struct Prediction {
  std::vector<int> points;  // frame point indices, ascending
  std::string name;         // a database object, or "unknown" (best score under min_score)
  std::string best;         // the best view's object before min_score ("" = nothing aligned)
  double score = 0;         // of the best view
  double runner_up = 0;     // best score of any other object's views
  double colour = -1;       // the best view's colour agreement (Alignment::colour), -1 = none
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  // camera <- model, of the best view
};
// recognize_scene()'s objects as predictions (the candidates are in the sensor frame, so the
// best view's pose is camera <- model).
std::vector<Prediction> predictions_of(const std::vector<SceneObject>& objects);

struct SceneEvalParams {
  double min_iou = 0.5;         // a truth and a prediction match only at this point IoU or more
  double pose_share = 0.1;      // pose ok: ADD-S under this share of the object's diameter
  int max_model_points = 2000;  // ADD-S on at most this many model points (evenly sampled)
};

// Maximum-weight assignment of rows to columns (the Hungarian method, O(n^3)) for weights >= 0:
// assignment[r] = the column of row r, -1 for none. Any shape; pairs of weight 0 are left
// unassigned. The total weight is the largest possible (greedy picking is not: it may take a
// heavy pair that blocks two others).
std::vector<int> max_weight_assignment(const Eigen::MatrixXd& weight);
// |a and b| / |a or b| of two ascending index lists (0 when both are empty).
double point_iou(const std::vector<int>& a, const std::vector<int>& b);
// Truth i -> prediction index or -1: the assignment of maximum total IoU among pairs of IoU >=
// min_iou. iou (optional) gets the matched pairs' IoU per truth (0 when unmatched).
std::vector<int> match_objects(const std::vector<TruthObject>& truth,
                               const std::vector<Prediction>& predictions, double min_iou,
                               std::vector<double>* iou = nullptr);

// The largest distance between two of the points (a model's diameter, metres; 0 for fewer than
// two points).
double model_diameter(const std::vector<Eigen::Vector3d>& points);
// ADD-S: the mean over the model points put in place by truth of the distance to the nearest
// model point put in place by estimate (both camera <- model), metres. Symmetric objects in an
// equivalent pose score 0.
double add_s(const std::vector<Eigen::Vector3d>& model, const Eigen::Matrix4d& estimate,
             const Eigen::Matrix4d& truth);

// One prediction of one scene, for the per-prediction CSV and the curve.
struct PredictionRow {
  std::uint32_t scene = 0;  // its seed
  int prediction = 0;       // index into the scene's predictions
  int truth = -1;           // the matched truth (index into scene_truth()), -1 = none
  std::string truth_name;   // "" when unmatched
  bool truth_known = false;
  double iou = 0;
  std::string name, best;  // Prediction::name and ::best
  double score = 0, runner_up = 0, colour = -1;
  double add_s = -1;  // metres, when the prediction names its matched known truth; else -1
  bool pose_ok = false;
};

// Counts over scenes (sums; the rates are over the sums).
struct SceneCounts {
  int scenes = 0;
  int truths = 0, known = 0, unknown = 0;  // truth objects: all, known, unknown
  int predictions = 0;
  int detected = 0;       // truths matched to a prediction (IoU >= min_iou)
  int tp = 0;             // known truths whose matched prediction carries their name
  int fn = 0;             // the other known truths
  int fp = 0;             // predictions with a known name that are not a TP
  int unknown_named = 0;  // unknown truths whose matched prediction carries a known name
  int known_unknown = 0;  // known truths whose matched prediction is "unknown"
  int pose_ok = 0;        // TPs with ADD-S under pose_share x diameter
  double seconds = 0;     // wall time, summed over scenes (set by the caller)
  double detection() const { return truths ? double(detected) / truths : 0; }
  double precision() const { return tp + fp ? double(tp) / (tp + fp) : 0; }
  double recall() const { return known ? double(tp) / known : 0; }
  double f1() const {
    const double p = precision(), r = recall();
    return p + r > 0 ? 2 * p * r / (p + r) : 0;
  }
  double unknown_named_share() const { return unknown ? double(unknown_named) / unknown : 0; }
  double known_unknown_share() const { return known ? double(known_unknown) / known : 0; }
  double pose_rate() const { return tp ? double(pose_ok) / tp : 0; }
  double seconds_per_scene() const { return scenes ? seconds / scenes : 0; }
  SceneCounts& operator+=(const SceneCounts& o);
};

struct SceneEvaluation {
  SceneCounts counts;               // of this scene (seconds left at 0)
  std::vector<int> match;           // truth i -> prediction index or -1
  std::vector<PredictionRow> rows;  // one per prediction, in order
};
// Scores one scene (seed `scene`): matching, recognition, unknowns named, pose.
SceneEvaluation evaluate_scene(std::uint32_t scene, const std::vector<TruthObject>& truth,
                               const std::vector<Prediction>& predictions,
                               const SceneCatalogue& catalogue, const SceneEvalParams& params = {});

// The ROC with negatives: the rows' answers re-thresholded at min_score (a prediction is named
// `best` when names_best() says so under `rule` with its min_score replaced, as recognize()
// names), with the matching kept.
struct SceneCurvePoint {
  double min_score = 0;
  int tp = 0, fp = 0, unknown_named = 0;
  double tpr = 0;                  // tp / known truths (recall)
  double unknown_named_share = 0;  // unknown_named / unknown truths
  double precision = 1;            // tp / (tp + fp); 1 when nothing is named
  double f1 = 0;
};
// The rule of a bare minimum score: no margin.
RecognitionParams threshold_rule();
SceneCurvePoint scene_point(const std::vector<PredictionRow>& rows, int known, int unknown,
                            double min_score, const RecognitionParams& rule = threshold_rule());
// From above every score down to 0: one point per distinct score, then min_score 0.
std::vector<SceneCurvePoint> scene_curve(const std::vector<PredictionRow>& rows, int known,
                                         int unknown,
                                         const RecognitionParams& rule = threshold_rule());
// The point of the largest F1 whose unknown_named_share is at most max_unknown_named (ties: the
// higher min_score); the curve's first point (nothing named) when none qualifies.
SceneCurvePoint best_threshold(const std::vector<SceneCurvePoint>& curve,
                               double max_unknown_named = 0.1);

}  // namespace proxseg
