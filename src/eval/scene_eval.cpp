// End-to-end scene recognition evaluation: the catalogue, the scene set and the scoring
// (scene_eval.hpp).
#include <proxseg/core/colour.hpp>
#include <proxseg/eval/object_set.hpp>
#include <proxseg/eval/rec_eval.hpp>
#include <proxseg/eval/scene_eval.hpp>

#include "assignment.hpp"
#include "eval/clutter/objects.hpp"
#include "linemod_models.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>

namespace proxseg {

namespace {

using Col = Eigen::Vector3d;  // 0..255 per channel

// A marker (cylinder along z, cap end at +z): body colour with a light printed band around it
// and a ring at the cap's edge, so that it is not one flat colour.
ColourFn marker_colours(const Col& body) {
  return [body](const Eigen::Vector3d& p) {
    const Col light(235, 233, 225);
    if (p.z() > -0.035 && p.z() < 0.015) return to_rgb8(light);  // the label band
    if (p.z() > 0.035 && p.z() < 0.04) return to_rgb8(light);    // the cap's ring
    return to_rgb8(body);
  };
}

// A box (z up, extents size): body colour with a band of `band` around its sides and a lid of
// the band's colour.
ColourFn box_colours(const Col& body, const Col& band, const Eigen::Vector3d& size) {
  return [=](const Eigen::Vector3d& p) {
    if (p.z() > size.z() / 2 - 1e-6) return to_rgb8(band);                         // lid
    if (std::abs(p.z() - 0.1 * size.z()) < 0.15 * size.z()) return to_rgb8(band);  // band
    return to_rgb8(body);
  };
}

CatalogueObject entry(const std::string& name, ClutterKind kind, Mesh mesh, bool convex,
                      bool lies = false) {
  CatalogueObject o;
  o.name = name;
  o.kind = kind;
  o.mesh = std::move(mesh);
  o.convex = convex;
  o.lies = lies;
  return o;
}

// At most n of the points, evenly spaced in their order.
std::vector<Eigen::Vector3d> evenly(const std::vector<Eigen::Vector3d>& pts, int n) {
  if (n <= 0 || static_cast<int>(pts.size()) <= n) return pts;
  std::vector<Eigen::Vector3d> out;
  out.reserve(n);
  for (int i = 0; i < n; ++i) out.push_back(pts[i * pts.size() / n]);
  return out;
}

bool is_named(const std::string& name) {
  return !name.empty() && name != kUnknown;
}

}  // namespace

SceneCatalogue scene_catalogue(const std::string& models_dir) {
  const auto linemod = [&](const char* id) {
    return detail::linemod_mesh(models_dir, id, "the scene catalogue");
  };
  SceneCatalogue c;
  const Mesh ape = linemod("obj_000001"), duck = linemod("obj_000009");
  // Known: six LINEMOD objects, two look-alikes in another colour, two markers, two boxes.
  c.entries.push_back(entry("ape", ClutterKind::mesh, ape, false));
  c.entries.push_back(entry("can", ClutterKind::mesh, linemod("obj_000005"), false));
  c.entries.push_back(entry("cat", ClutterKind::mesh, linemod("obj_000006"), false));
  c.entries.push_back(entry("driller", ClutterKind::mesh, linemod("obj_000008"), false));
  c.entries.push_back(entry("duck", ClutterKind::mesh, duck, false));
  c.entries.push_back(entry("eggbox", ClutterKind::mesh, linemod("obj_000010"), false));
  c.entries.push_back(entry("duck-blue", ClutterKind::mesh, hue_turned(duck, 0.62), false));
  c.entries.push_back(entry("ape-green", ClutterKind::mesh, hue_turned(ape, 0.33), false));
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  const double marker_r = 0.0125, marker_h = 0.13;
  c.entries.push_back(entry(
      "marker-red", ClutterKind::cylinder,
      make_cylinder(I, marker_r, marker_h, marker_colours({200, 30, 35}), clutter::kObjectCell),
      true, true));
  c.entries.push_back(entry(
      "marker-black", ClutterKind::cylinder,
      make_cylinder(I, marker_r, marker_h, marker_colours({30, 30, 34}), clutter::kObjectCell),
      true, true));
  const Eigen::Vector3d tea(0.07, 0.07, 0.14), rice(0.08, 0.06, 0.16);
  c.entries.push_back(entry(
      "box-tea", ClutterKind::box,
      make_box(I, tea, box_colours({190, 30, 30}, {240, 238, 230}, tea), clutter::kObjectCell),
      true));
  c.entries.push_back(entry(
      "box-rice", ClutterKind::box,
      make_box(I, rice, box_colours({225, 190, 40}, {110, 70, 35}, rice), clutter::kObjectCell),
      true));
  std::vector<char> known(c.entries.size(), 1);
  // Unknown: never in the database.
  c.entries.push_back(entry("glue", ClutterKind::mesh, linemod("obj_000011"), false));
  c.entries.push_back(entry("holepuncher", ClutterKind::mesh, linemod("obj_000012"), false));
  known.resize(c.entries.size(), 0);
  return make_catalogue(std::move(c.entries), std::move(known));
}

SceneCatalogue make_catalogue(std::vector<CatalogueObject> entries, std::vector<char> known) {
  SceneCatalogue c;
  c.entries = std::move(entries);
  c.known = std::move(known);
  c.known.resize(c.entries.size(), 0);
  for (const CatalogueObject& e : c.entries) {
    std::vector<Eigen::Vector3d> pts;
    pts.reserve(e.mesh.vertices.size());
    for (const auto& v : e.mesh.vertices) pts.push_back(v.cast<double>());
    c.diameters.push_back(model_diameter(pts));
    c.model_points.push_back(std::move(pts));
  }
  return c;
}

int catalogue_index(const SceneCatalogue& catalogue, const std::string& name) {
  for (std::size_t i = 0; i < catalogue.entries.size(); ++i)
    if (catalogue.entries[i].name == name) return static_cast<int>(i);
  return -1;
}

Database scene_database(const SceneCatalogue& catalogue, int views,
                        const DescriptorParams& descriptor, const std::string& dir) {
  std::vector<TestObject> objects;
  for (std::size_t i = 0; i < catalogue.entries.size(); ++i) {
    if (!catalogue.known[i]) continue;
    TestObject o;
    o.name = catalogue.entries[i].name;
    o.file = o.name;  // the views' source: "duck-blue view 3/8"
    o.mesh = catalogue.entries[i].mesh;
    objects.push_back(std::move(o));
  }
  return render_database(objects, views, descriptor, dir);
}

std::vector<std::uint32_t> seed_range(std::uint32_t first, int count) {
  std::vector<std::uint32_t> seeds;
  for (int i = 0; i < count; ++i) seeds.push_back(first + static_cast<std::uint32_t>(i));
  return seeds;
}

ClutterParams scene_set_params(std::uint32_t seed, const SceneCatalogue& catalogue,
                               const SceneSetParams& params) {
  ClutterParams p;
  p.seed = seed;
  p.min_objects = params.min_objects;
  p.max_objects = params.max_objects;
  p.mesh_share = params.mesh_share;
  p.catalogue = catalogue.entries;
  p.catalogue_share = params.catalogue_share;
  return p;
}

std::vector<TruthObject> scene_truth(const ClutterScene& scene, const SceneCatalogue& catalogue) {
  std::vector<TruthObject> truth;
  for (const ClutterObject& o : scene.objects) {
    TruthObject t;
    t.label = o.label;
    t.name = o.name;
    t.catalogue = o.catalogue;
    t.known = o.catalogue >= 0 && static_cast<std::size_t>(o.catalogue) < catalogue.known.size() &&
              catalogue.known[o.catalogue];
    t.camera_from_model = (scene.render.camera_from_world * o.world_from_object).matrix();
    truth.push_back(std::move(t));
  }
  const Frame& f = scene.frame;
  for (std::size_t k = 0; k < f.size(); ++k) {
    if (!f.valid(k)) continue;
    const std::uint32_t l = f.label[k];  // 10 * (i + 2) for object i
    if (l >= 20 && l % 10 == 0 && l / 10 - 2 < truth.size())
      truth[l / 10 - 2].points.push_back(static_cast<int>(k));
  }
  return truth;
}

std::vector<Prediction> predictions_of(const std::vector<SceneObject>& objects) {
  std::vector<Prediction> out;
  for (const SceneObject& o : objects) {
    Prediction p;
    p.points = o.points;
    p.name = o.recognition.name;
    p.best = o.recognition.best.object;
    p.score = o.recognition.best.score;
    p.runner_up = o.recognition.runner_up.view >= 0 ? o.recognition.runner_up.score : 0;
    p.colour =
        o.recognition.best.view >= 0 && o.recognition.alignments[o.recognition.best.view].coloured
            ? o.recognition.best.colour
            : -1;
    p.pose = o.recognition.best.pose;
    out.push_back(std::move(p));
  }
  return out;
}

std::vector<int> max_weight_assignment(const Eigen::MatrixXd& weight) {
  const int rows = static_cast<int>(weight.rows()), cols = static_cast<int>(weight.cols());
  std::vector<int> out(rows, -1);
  if (rows == 0 || cols == 0) return out;
  // The Hungarian method with potentials needs rows <= columns: solve the transpose otherwise.
  const bool flip = rows > cols;
  const Eigen::MatrixXd w = flip ? Eigen::MatrixXd(weight.transpose()) : weight;
  const int n = static_cast<int>(w.rows()), m = static_cast<int>(w.cols());
  // Maximum weight = minimum cost on -w (row-major).
  std::vector<double> cost(static_cast<std::size_t>(n) * m);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) cost[static_cast<std::size_t>(i) * m + j] = -w(i, j);
  const std::vector<int> col_of_row = detail::assign_min_cost(cost, n, m);
  for (int i = 0; i < n; ++i) {
    const int j = col_of_row[i];
    if (j < 0 || !(w(i, j) > 0)) continue;  // weight 0: no pair
    if (flip)
      out[j] = i;
    else
      out[i] = j;
  }
  return out;
}

double point_iou(const std::vector<int>& a, const std::vector<int>& b) {
  std::size_t i = 0, j = 0, both = 0;
  while (i < a.size() && j < b.size()) {
    if (a[i] < b[j])
      ++i;
    else if (b[j] < a[i])
      ++j;
    else
      ++both, ++i, ++j;
  }
  const std::size_t either = a.size() + b.size() - both;
  return either ? double(both) / double(either) : 0;
}

std::vector<int> match_objects(const std::vector<TruthObject>& truth,
                               const std::vector<Prediction>& predictions, double min_iou,
                               std::vector<double>* iou) {
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(truth.size(), predictions.size());
  for (std::size_t i = 0; i < truth.size(); ++i)
    for (std::size_t j = 0; j < predictions.size(); ++j) {
      const double x = point_iou(truth[i].points, predictions[j].points);
      if (x >= min_iou && x > 0) w(i, j) = x;  // pairs under min_iou may not be matched at all
    }
  const std::vector<int> match = max_weight_assignment(w);
  if (iou) {
    iou->assign(truth.size(), 0);
    for (std::size_t i = 0; i < truth.size(); ++i)
      if (match[i] >= 0) (*iou)[i] = w(i, match[i]);
  }
  return match;
}

// Largest distance between two points: pairs are visited in decreasing order of the sum of
// their distances to the centroid, which bounds their distance, so most are never visited.
double model_diameter(const std::vector<Eigen::Vector3d>& pts) {
  if (pts.size() < 2) return 0;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : pts) c += p;
  c /= static_cast<double>(pts.size());
  std::vector<std::pair<double, std::size_t>> r(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) r[i] = {(pts[i] - c).norm(), i};
  std::sort(r.begin(), r.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  double best = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (2 * r[i].first <= best) break;
    for (std::size_t j = i + 1; j < r.size(); ++j) {
      if (r[i].first + r[j].first <= best) break;
      best = std::max(best, (pts[r[i].second] - pts[r[j].second]).norm());
    }
  }
  return best;
}

double add_s(const std::vector<Eigen::Vector3d>& model, const Eigen::Matrix4d& estimate,
             const Eigen::Matrix4d& truth) {
  if (model.empty()) return 0;
  const Eigen::Affine3d E(estimate), T(truth);
  std::vector<Eigen::Vector3d> placed(model.size());
  for (std::size_t i = 0; i < model.size(); ++i) placed[i] = E * model[i];
  double sum = 0;
  for (const auto& m : model) {
    const Eigen::Vector3d t = T * m;
    double best = std::numeric_limits<double>::infinity();
    for (const auto& q : placed) best = std::min(best, (q - t).squaredNorm());
    sum += std::sqrt(best);
  }
  return sum / static_cast<double>(model.size());
}

SceneCounts& SceneCounts::operator+=(const SceneCounts& o) {
  // Every count, field by field.
  for (int SceneCounts::*count :
       {&SceneCounts::scenes, &SceneCounts::truths, &SceneCounts::known, &SceneCounts::unknown,
        &SceneCounts::predictions, &SceneCounts::detected, &SceneCounts::tp, &SceneCounts::fn,
        &SceneCounts::fp, &SceneCounts::unknown_named, &SceneCounts::known_unknown,
        &SceneCounts::pose_ok})
    this->*count += o.*count;
  seconds += o.seconds;
  return *this;
}

SceneEvaluation evaluate_scene(std::uint32_t scene, const std::vector<TruthObject>& truth,
                               const std::vector<Prediction>& predictions,
                               const SceneCatalogue& catalogue, const SceneEvalParams& params) {
  SceneEvaluation e;
  std::vector<double> iou;
  e.match = match_objects(truth, predictions, params.min_iou, &iou);
  SceneCounts& c = e.counts;
  c.scenes = 1;
  c.truths = static_cast<int>(truth.size());
  c.predictions = static_cast<int>(predictions.size());
  e.rows.resize(predictions.size());
  for (std::size_t j = 0; j < predictions.size(); ++j) {
    PredictionRow& r = e.rows[j];
    const Prediction& p = predictions[j];
    r.scene = scene;
    r.prediction = static_cast<int>(j);
    r.name = p.name;
    r.best = p.best;
    r.score = p.score;
    r.runner_up = p.runner_up;
    r.colour = p.colour;
  }
  std::vector<char> tp(predictions.size(), 0);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const TruthObject& t = truth[i];
    (t.known ? c.known : c.unknown) += 1;
    const int m = e.match[i];
    if (m < 0) {
      c.fn += t.known;
      continue;
    }
    ++c.detected;
    PredictionRow& r = e.rows[m];
    r.truth = static_cast<int>(i);
    r.truth_name = t.name;
    r.truth_known = t.known;
    r.iou = iou[i];
    const Prediction& p = predictions[m];
    if (!t.known) {
      c.unknown_named += is_named(p.name);
      continue;
    }
    if (p.name != t.name) {
      ++c.fn;
      c.known_unknown += !is_named(p.name);
      continue;
    }
    ++c.tp;
    tp[m] = 1;
    const std::size_t k = static_cast<std::size_t>(t.catalogue);
    r.add_s = add_s(evenly(catalogue.model_points.at(k), params.max_model_points), p.pose,
                    t.camera_from_model);
    r.pose_ok = r.add_s < params.pose_share * catalogue.diameters.at(k);
    c.pose_ok += r.pose_ok;
  }
  for (std::size_t j = 0; j < predictions.size(); ++j)
    c.fp += is_named(predictions[j].name) && !tp[j];
  return e;
}

RecognitionParams threshold_rule() {
  RecognitionParams rule;
  rule.min_margin = 0;
  rule.confident_score = 1;
  rule.lone_score = 0;
  return rule;
}

SceneCurvePoint scene_point(const std::vector<PredictionRow>& rows, int known, int unknown,
                            double min_score, const RecognitionParams& rule) {
  SceneCurvePoint p;
  p.min_score = min_score;
  RecognitionParams at = rule;
  at.min_score = min_score;
  for (const PredictionRow& r : rows) {
    // The lone match as recognize() allows it: colour compared (a merge or split trial's piece
    // did not have it; the rows do not tell those apart).
    const bool lone = r.colour >= 0;
    if (r.best.empty() || !names_best(r.score, r.runner_up, at, lone)) continue;  // "unknown"
    const bool right = r.truth >= 0 && r.truth_known && r.best == r.truth_name;
    (right ? p.tp : p.fp) += 1;
    p.unknown_named += r.truth >= 0 && !r.truth_known;
  }
  p.tpr = known ? double(p.tp) / known : 0;
  p.unknown_named_share = unknown ? double(p.unknown_named) / unknown : 0;
  p.precision = p.tp + p.fp ? double(p.tp) / (p.tp + p.fp) : 1;
  p.f1 = p.precision + p.tpr > 0 && p.tp > 0 ? 2 * p.precision * p.tpr / (p.precision + p.tpr) : 0;
  return p;
}

std::vector<SceneCurvePoint> scene_curve(const std::vector<PredictionRow>& rows, int known,
                                         int unknown, const RecognitionParams& rule) {
  std::vector<double> scores;
  for (const PredictionRow& r : rows)
    if (!r.best.empty()) scores.push_back(r.score);
  std::sort(scores.begin(), scores.end(), std::greater<double>());
  scores.erase(std::unique(scores.begin(), scores.end()), scores.end());
  std::vector<SceneCurvePoint> curve = {
      scene_point(rows, known, unknown, scores.empty() ? 1.0 : scores.front() + 1e-9, rule)};
  for (double s : scores) curve.push_back(scene_point(rows, known, unknown, s, rule));
  return curve;
}

SceneCurvePoint best_threshold(const std::vector<SceneCurvePoint>& curve,
                               double max_unknown_named) {
  const SceneCurvePoint* best = nullptr;
  for (const SceneCurvePoint& p : curve)
    if (p.unknown_named_share <= max_unknown_named && (!best || p.f1 > best->f1)) best = &p;
  if (best) return *best;
  return curve.empty() ? SceneCurvePoint{} : curve.front();
}

}  // namespace proxseg
