// Evaluation of segmentations on labelled scenes: schemes, categories, summaries.
#include <proxseg/eval/evaluation.hpp>

#include <proxseg/core/selection.hpp>
#include <proxseg/io/cloud_io.hpp>
#include "util/splitmix.hpp"

#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <limits>
#include <numeric>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>
#include "util/angles.hpp"

namespace proxseg {
namespace {

std::vector<std::uint32_t> evaluated(const Frame& frame, std::vector<std::uint32_t> truth) {
  if (frame.label.size() != frame.size())
    throw InputError("ground truth: frame has no label field (expected one label per point)");
  // mOSD files may hold NaN points under a non-zero label: only finite positions count.
  for (std::size_t i = 0; i < truth.size(); ++i)
    if (!frame.valid(i)) truth[i] = 0;
  return truth;
}

std::string fmt(double v, int digits = 3) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// Adds b * w into a (field by field) for the averaged scores.
void accumulate(SegmentationScores& a, const SegmentationScores& b, double w) {
  a.paper_precision += w * b.paper_precision;
  a.paper_recall += w * b.paper_recall;
  a.v.homogeneity += w * b.v.homogeneity;
  a.v.completeness += w * b.v.completeness;
  a.v.v += w * b.v.v;
  a.weighted_overlap += w * b.weighted_overlap;
  a.object_precision += w * b.object_precision;
  a.object_recall += w * b.object_recall;
  a.object_f += w * b.object_f;
  a.detected_075 += w * b.detected_075;
}

}  // namespace

std::vector<std::uint32_t> truth_objects(const Frame& frame) {
  return evaluated(frame, mosd_objects(frame.label));
}

std::vector<std::uint32_t> truth_parts(const Frame& frame) {
  return evaluated(frame, mosd_parts(frame.label));
}

SceneScores score_scene(const Frame& truth, const std::vector<std::uint32_t>& predicted) {
  if (predicted.size() != truth.size())
    throw InputError("prediction has " + std::to_string(predicted.size()) +
                     " points but the ground truth has " + std::to_string(truth.size()) +
                     " (expected the same cloud)");
  SceneScores s;
  s.objects = score_segmentation(truth_objects(truth), predicted, kMosdBackground);
  s.parts = score_segmentation(truth_parts(truth), predicted, kMosdBackground);
  return s;
}

std::string scene_category(const std::string& scene_name) {
  static const std::regex learn(R"(^learn(\d+)(\.\w+)?$)");
  std::smatch m;
  const std::string name = std::filesystem::path(scene_name).filename().string();
  for (const char* kind : {"clutter", "piles", "occlusion"})  // generated: clutter_kind()
    if (name.rfind(kind, 0) == 0) return kind;
  if (!std::regex_match(name, m, learn)) return "other";
  const int i = std::stoi(m[1]);
  return i <= 16   ? "boxes"
         : i <= 24 ? "stacked"
         : i <= 32 ? "occluded"
         : i <= 44 ? "cylindric"
                   : "other";
}

long scene_number(const std::string& scene_name) {
  const std::string stem = std::filesystem::path(scene_name).stem().string();
  std::size_t i = stem.size();
  while (i > 0 && std::isdigit(static_cast<unsigned char>(stem[i - 1]))) --i;
  if (i == stem.size()) return -1;
  return std::stol(stem.substr(i, 18));  // at most 18 digits: no overflow
}

std::string scene_fold(const std::string& scene_name) {
  const std::string category = scene_category(scene_name);
  if (category != "clutter" && category != "piles" && category != "occlusion") return category;
  const long n = scene_number(scene_name);
  return category + (n >= 0 && n % 2 == 1 ? "-odd" : "-even");
}

std::vector<std::filesystem::path> scene_files(const std::string& dir,
                                               const std::vector<std::string>& extensions) {
  std::string wanted;
  for (const auto& e : extensions) wanted += (wanted.empty() ? "" : " or ") + e;
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw InputError(dir + ": not a directory (expected a folder of " + wanted + " scenes)");
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    std::string ext = e.path().extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (e.is_regular_file() &&
        std::find(extensions.begin(), extensions.end(), ext) != extensions.end())
      files.push_back(e.path());
  }
  // Natural order: the trailing number of the stem compares as a number.
  auto key = [](const std::filesystem::path& p) {
    const std::string stem = p.stem().string();
    std::size_t i = stem.size();
    while (i > 0 && std::isdigit(static_cast<unsigned char>(stem[i - 1]))) --i;
    const long n = i < stem.size() ? std::stol(stem.substr(i, 9)) : -1;
    return std::make_pair(stem.substr(0, i), n);
  };
  std::sort(files.begin(), files.end(), [&](const auto& a, const auto& b) {
    return std::make_pair(key(a), a.string()) < std::make_pair(key(b), b.string());
  });
  if (files.empty()) throw InputError(dir + ": no " + wanted + " files (expected scenes)");
  return files;
}

std::vector<SummaryRow> summarize(const std::vector<SceneScores>& scenes) {
  // Methods keep their first-seen order; categories their natural order, "all" last.
  std::vector<std::string> methods;
  for (const auto& s : scenes)
    if (std::find(methods.begin(), methods.end(), s.method) == methods.end())
      methods.push_back(s.method);
  const std::vector<std::string> categories = {
      "boxes", "stacked", "occluded", "cylindric", "clutter", "piles", "occlusion", "other", "all"};
  std::vector<SummaryRow> rows;
  for (const auto& method : methods)
    for (const auto& category : categories) {
      SummaryRow r;
      r.method = method;
      r.category = category;
      for (const auto& s : scenes)
        if (s.method == method && (category == "all" || s.category == category)) ++r.scenes;
      if (r.scenes == 0) continue;
      const double w = 1.0 / r.scenes;
      long lost = 0, objects = 0, lost_parts = 0, objects_parts = 0;
      for (const auto& s : scenes) {
        if (s.method != method || (category != "all" && s.category != category)) continue;
        r.seconds += w * s.seconds;
        accumulate(r.objects, s.objects, w);
        accumulate(r.parts, s.parts, w);
        r.over_segmented += w * s.objects.over_segmented;
        r.under_segmented += w * s.objects.under_segmented;
        r.truth_objects += w * s.objects.truth_objects;
        r.lost_in_background += w * s.objects.lost_in_background;
        r.unassigned_objects += w * s.objects.unassigned_objects;
        lost += s.objects.lost_in_background;
        objects += s.objects.truth_objects;
        lost_parts += s.parts.lost_in_background;
        objects_parts += s.parts.truth_objects;
      }
      // Pooled over the scenes, not a mean of ratios: a scene with one object does not weigh as
      // much as one with ten.
      r.objects.lost_in_background_share =
          objects ? static_cast<double>(lost) / static_cast<double>(objects) : 0.0;
      r.parts.lost_in_background_share =
          objects_parts ? static_cast<double>(lost_parts) / static_cast<double>(objects_parts)
                        : 0.0;
      rows.push_back(r);
    }
  return rows;
}

nlohmann::json scores_json(const SegmentationScores& s) {
  return {{"points", s.points},
          {"truth_regions", s.truth_regions},
          {"truth_objects", s.truth_objects},
          {"segments", s.segments},
          {"paper_precision", s.paper_precision},
          {"paper_recall", s.paper_recall},
          {"homogeneity", s.v.homogeneity},
          {"completeness", s.v.completeness},
          {"v_measure", s.v.v},
          {"weighted_overlap", s.weighted_overlap},
          {"object_precision", s.object_precision},
          {"object_recall", s.object_recall},
          {"object_f", s.object_f},
          {"detected_075", s.detected_075},
          {"over_segmented", s.over_segmented},
          {"under_segmented", s.under_segmented},
          {"lost_in_background", s.lost_in_background},
          {"unassigned_objects", s.unassigned_objects},
          {"lost_in_background_share", s.lost_in_background_share}};
}

std::string scenes_csv(const std::vector<SceneScores>& scenes) {
  std::ostringstream out;
  out << "scene,category,method,seconds";
  for (const char* scheme : {"objects", "parts"})
    for (const char* m :
         {"paper_precision", "paper_recall", "homogeneity", "completeness", "v_measure",
          "weighted_overlap", "object_precision", "object_recall", "object_f", "detected_075",
          "over_segmented", "under_segmented", "truth_objects", "segments", "lost_in_background",
          "unassigned_objects", "lost_in_background_share"})
      out << "," << scheme << "_" << m;
  out << "\n";
  for (const auto& s : scenes) {
    out << s.scene << "," << s.category << "," << s.method << "," << fmt(s.seconds, 4);
    for (const SegmentationScores* x : {&s.objects, &s.parts})
      out << "," << fmt(x->paper_precision, 4) << "," << fmt(x->paper_recall, 4) << ","
          << fmt(x->v.homogeneity, 4) << "," << fmt(x->v.completeness, 4) << "," << fmt(x->v.v, 4)
          << "," << fmt(x->weighted_overlap, 4) << "," << fmt(x->object_precision, 4) << ","
          << fmt(x->object_recall, 4) << "," << fmt(x->object_f, 4) << ","
          << fmt(x->detected_075, 4) << "," << x->over_segmented << "," << x->under_segmented << ","
          << x->truth_objects << "," << x->segments << "," << x->lost_in_background << ","
          << x->unassigned_objects << "," << fmt(x->lost_in_background_share, 4);
    out << "\n";
  }
  return out.str();
}

std::string summary_markdown(const std::vector<SummaryRow>& rows) {
  std::ostringstream out;
  out << "| method | category | scenes | object F | object P | object R | F>=0.75 | V | WOv | "
         "paper P | paper R | over | under | lost bg | parts F | parts V | s/frame |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows)
    out << "| " << r.method << " | " << r.category << " | " << r.scenes << " | "
        << fmt(r.objects.object_f) << " | " << fmt(r.objects.object_precision) << " | "
        << fmt(r.objects.object_recall) << " | " << fmt(r.objects.detected_075) << " | "
        << fmt(r.objects.v.v) << " | " << fmt(r.objects.weighted_overlap) << " | "
        << fmt(r.objects.paper_precision) << " | " << fmt(r.objects.paper_recall) << " | "
        << fmt(r.over_segmented, 2) << " | " << fmt(r.under_segmented, 2) << " | "
        << fmt(r.objects.lost_in_background_share) << " | " << fmt(r.parts.object_f) << " | "
        << fmt(r.parts.v.v) << " | " << fmt(r.seconds) << " |\n";
  return out.str();
}

nlohmann::json summary_json(const std::vector<SummaryRow>& rows) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& r : rows) {
    nlohmann::json objects = scores_json(r.objects), parts = scores_json(r.parts);
    // Counts are means over scenes here.
    objects["over_segmented"] = r.over_segmented;
    objects["under_segmented"] = r.under_segmented;
    objects["truth_objects"] = r.truth_objects;
    objects["lost_in_background"] = r.lost_in_background;
    objects["unassigned_objects"] = r.unassigned_objects;
    for (nlohmann::json* x : {&objects, &parts}) {
      x->erase("points");
      x->erase("truth_regions");
      x->erase("segments");
    }
    parts.erase("over_segmented");
    parts.erase("under_segmented");
    parts.erase("truth_objects");
    parts.erase("lost_in_background");
    parts.erase("unassigned_objects");
    j.push_back({{"method", r.method},
                 {"category", r.category},
                 {"scenes", r.scenes},
                 {"seconds_per_frame", r.seconds},
                 {"objects", objects},
                 {"parts", parts}});
  }
  return j;
}

CrossValidation cross_validate(const std::vector<std::vector<double>>& scores,
                               const std::vector<std::string>& fold_of_scene) {
  const std::size_t n = scores.size();
  if (n == 0 || scores[0].empty())
    throw std::invalid_argument("cross_validate: no scenes or no variants");
  const std::size_t v = scores[0].size();
  for (const auto& row : scores)
    if (row.size() != v) throw std::invalid_argument("cross_validate: rows of different sizes");
  if (fold_of_scene.size() != n)
    throw std::invalid_argument("cross_validate: one fold per scene expected");
  CrossValidation cv;
  std::vector<int> fold(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto it = std::find(cv.folds.begin(), cv.folds.end(), fold_of_scene[i]);
    fold[i] = static_cast<int>(it - cv.folds.begin());
    if (it == cv.folds.end()) cv.folds.push_back(fold_of_scene[i]);
  }
  const std::size_t nf = cv.folds.size();
  if (nf < 2) throw std::invalid_argument("cross_validate: fewer than two folds");
  // Sums per fold and variant and over all scenes, in scene order.
  std::vector<std::vector<double>> fold_sum(nf, std::vector<double>(v, 0.0));
  std::vector<double> total(v, 0.0);
  cv.fold_scenes.assign(nf, 0);
  for (std::size_t i = 0; i < n; ++i) {
    ++cv.fold_scenes[fold[i]];
    for (std::size_t k = 0; k < v; ++k) {
      fold_sum[fold[i]][k] += scores[i][k];
      total[k] += scores[i][k];
    }
  }
  // The best of a list of means; strict > leaves ties to the first variant.
  const auto best_of = [v](const std::vector<double>& means) {
    int best = 0;
    for (std::size_t k = 1; k < v; ++k)
      if (means[k] > means[best]) best = static_cast<int>(k);
    return best;
  };
  cv.variant_means.resize(v);
  for (std::size_t k = 0; k < v; ++k) cv.variant_means[k] = total[k] / static_cast<double>(n);
  cv.best_in_sample = best_of(cv.variant_means);
  cv.in_sample = cv.variant_means[cv.best_in_sample];
  cv.fold_means.assign(nf, std::vector<double>(v, 0.0));
  cv.chosen.resize(nf);
  cv.training.resize(nf);
  cv.held_out.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const double inside = cv.fold_scenes[f], outside = static_cast<double>(n) - inside;
    std::vector<double> training(v);
    for (std::size_t k = 0; k < v; ++k) {
      cv.fold_means[f][k] = fold_sum[f][k] / inside;
      // The training mean summed afresh over the other scenes, not total - fold (no rounding
      // difference between two variants with the same scores outside the fold).
      double sum = 0;
      for (std::size_t i = 0; i < n; ++i)
        if (fold[i] != static_cast<int>(f)) sum += scores[i][k];
      training[k] = sum / outside;
    }
    cv.chosen[f] = best_of(training);
    cv.training[f] = training[cv.chosen[f]];
    cv.held_out[f] = cv.fold_means[f][cv.chosen[f]];
  }
  cv.scene_variant.resize(n);
  cv.scene_score.resize(n);
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    cv.scene_variant[i] = cv.chosen[fold[i]];
    cv.scene_score[i] = scores[i][cv.scene_variant[i]];
    sum += cv.scene_score[i];
  }
  cv.overall = sum / static_cast<double>(n);
  return cv;
}

std::vector<std::string> read_lines(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open (expected a text file)");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

YcbFrame read_ycb_frame(const std::string& dir, const std::string& stem,
                        const std::vector<std::string>& classes) {
  const std::string base = (std::filesystem::path(dir) / stem).string();
  const std::string meta_path = base + "-meta.json", label_path = base + "-label.png";
  YcbFrame y;
  y.intrinsics = read_ycb_meta(meta_path);
  y.frame = read_rgbd(base + "-color.png", base + "-depth.png", y.intrinsics);
  const std::vector<std::uint8_t> label =
      read_label_image(label_path, y.frame.width, y.frame.height);
  nlohmann::json meta;
  {
    std::ifstream in(meta_path);
    meta = nlohmann::json::parse(in, nullptr, false);  // read_ycb_meta has parsed it already
  }
  // cls_indexes: N ids (or [id] each); poses: 3 x 4 x N numbers.
  const auto bad = [&](const std::string& what) {
    throw InputError(meta_path + ": " + what + " (expected cls_indexes of N class ids and poses " +
                     "of 3 x 4 x N numbers)");
  };
  if (!meta.is_object() || !meta.contains("cls_indexes") || !meta.contains("poses"))
    bad("missing cls_indexes or poses");
  const auto& ids = meta.at("cls_indexes");
  const auto& poses = meta.at("poses");
  if (!ids.is_array()) bad("cls_indexes is not an array");
  const std::size_t n_objects = ids.size();
  if (!poses.is_array() || poses.size() != 3) bad("poses is not 3 rows");
  for (const auto& row : poses) {
    if (!row.is_array() || row.size() != 4) bad("a row of poses has not 4 columns");
    for (const auto& cell : row) {
      if (!cell.is_array() || cell.size() != n_objects) bad("poses has not one value per object");
      for (const auto& v : cell)
        if (!v.is_number() || !std::isfinite(v.get<double>())) bad("poses has a non-number");
    }
  }
  for (std::size_t n = 0; n < n_objects; ++n) {
    ObjectTruth o;
    const auto& id = ids[n].is_array() && ids[n].size() == 1 ? ids[n][0] : ids[n];
    if (!id.is_number_integer()) bad("cls_indexes[" + std::to_string(n) + "] is not an integer");
    const auto index = id.get<std::int64_t>();
    if (index < 1 || index > static_cast<std::int64_t>(classes.size()))
      throw InputError(meta_path + ": cls_indexes[" + std::to_string(n) +
                       "] = " + std::to_string(index) + " is not a class of classes.txt");
    o.class_index = static_cast<int>(index);
    o.name = classes[o.class_index - 1];
    o.pose.setIdentity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) o.pose(r, c) = poses[r][c][n].get<double>();
    for (std::size_t i = 0; i < label.size(); ++i)
      if (label[i] == o.class_index && y.frame.valid(i)) o.points.push_back(static_cast<int>(i));
    y.objects.push_back(std::move(o));
  }
  return y;
}

Occlusion occlude(const std::vector<Eigen::Vector3d>& view, double max_radius, std::uint64_t seed) {
  if (view.empty()) throw InputError("occlude: the view has no points");
  if (!(max_radius >= 0) || !std::isfinite(max_radius))
    throw InputError("occlude: expected a finite max_radius >= 0");
  SplitMix rng{seed};
  const auto uniform = [&rng]() { return rng.uniform(); };
  Occlusion o;
  o.centre = view[std::min(view.size() - 1, static_cast<std::size_t>(uniform() * view.size()))];
  o.radius = uniform() * max_radius;
  for (const auto& p : view)
    if ((p - o.centre).norm() > o.radius) o.points.push_back(p);
  o.removed_share = 1.0 - double(o.points.size()) / view.size();
  return o;
}

namespace {

// The frame of a box from its faces: the most common normal direction (sign ignored), then the
// most common one at right angles to it. Principal axes fail for boxes with two near-equal sides
// (the foam brick): their cross-section has no preferred direction, so PCA turns the box frame
// by an arbitrary angle and no turn of that frame maps the box onto itself.
Eigen::Matrix3d face_axes(const std::vector<Eigen::Vector3d>& model) {
  open3d::geometry::PointCloud cloud(model);
  cloud.EstimateNormals(open3d::geometry::KDTreeSearchParamKNN(20));
  const auto& normals = cloud.normals_;
  const double parallel = std::cos(detail::radians(5)), orthogonal = std::sin(detail::radians(5));
  const std::size_t stride = std::max<std::size_t>(1, normals.size() / 300);
  auto most_common = [&](auto accept) {
    Eigen::Vector3d best = Eigen::Vector3d::Zero();
    std::size_t best_count = 0;
    for (std::size_t i = 0; i < normals.size(); i += stride) {
      if (!accept(normals[i])) continue;
      std::size_t count = 0;
      for (const auto& n : normals) count += std::abs(n.dot(normals[i])) >= parallel;
      if (count > best_count) best_count = count, best = normals[i];
    }
    return best;
  };
  const Eigen::Vector3d a = most_common([](const Eigen::Vector3d&) { return true; });
  Eigen::Vector3d b =
      most_common([&](const Eigen::Vector3d& n) { return std::abs(n.dot(a)) <= orthogonal; });
  if (a.isZero() || b.isZero()) return Eigen::Matrix3d::Identity();
  b = (b - b.dot(a) * a).normalized();
  Eigen::Matrix3d axes;
  axes << a, b, a.cross(b);
  return axes;
}

}  // namespace

std::vector<Eigen::Matrix4d> box_symmetries(const std::vector<Eigen::Vector3d>& model,
                                            double tolerance) {
  if (model.empty()) return {Eigen::Matrix4d::Identity()};
  Frame f;
  for (const auto& p : model) f.xyz.push_back(p.cast<float>());
  f.rgb.assign(model.size(), Rgb{0, 0, 0});
  f.width = static_cast<int>(model.size());
  f.height = 1;
  std::vector<int> all(model.size());
  std::iota(all.begin(), all.end(), 0);
  // Two candidate box frames: the face normals, then (as a fallback) the principal axes.
  std::vector<OrientedBox> boxes;
  {
    OrientedBox box;
    box.axes = face_axes(model);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const auto& p : model) {
      const Eigen::Vector3d q = box.axes.transpose() * p;
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
    box.extent = hi - lo;
    box.centre = box.axes * ((lo + hi) / 2);
    boxes.push_back(box);
  }
  boxes.push_back(oriented_box(f, all));
  std::vector<Eigen::Matrix4d> out = {Eigen::Matrix4d::Identity()};
  // Mean distance from each turned point to the nearest model point (brute force on a subsample:
  // models are a few thousand points and this runs once per model).
  const std::size_t stride = std::max<std::size_t>(1, model.size() / 400);
  auto maps_onto_itself = [&](const Eigen::Matrix4d& s) {
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < model.size(); i += stride, ++n) {
      const Eigen::Vector3d q = s.topLeftCorner<3, 3>() * model[i] + s.topRightCorner<3, 1>();
      double best = std::numeric_limits<double>::infinity();
      for (const auto& p : model) best = std::min(best, (p - q).squaredNorm());
      sum += std::sqrt(best);
    }
    return n && sum / n < tolerance;
  };
  // A turn within 10 degrees of a known one is the same symmetry seen from the other frame.
  auto known = [&](const Eigen::Matrix3d& r) {
    for (const auto& o : out)
      if (Eigen::AngleAxisd(Eigen::Matrix3d(o.topLeftCorner<3, 3>().transpose() * r)).angle() <
          detail::radians(10))
        return true;
    return false;
  };
  for (const OrientedBox& box : boxes) {
    // The principal axes only when the faces gave nothing: where both give turns, the principal
    // ones are the same symmetries a few degrees off, and their products would pass for small
    // symmetric turns.
    if (out.size() > 1) break;
    // Candidate turns in the box frame: 180 degrees about each axis; 90 and 270 about an axis
    // whose other two extents are equal within tolerance.
    std::vector<Eigen::Matrix3d> turns;
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector3d axis = Eigen::Vector3d::Unit(a);
      turns.push_back(Eigen::AngleAxisd(detail::kPi, axis).toRotationMatrix());
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      if (std::abs(box.extent[b] - box.extent[c]) < 2 * tolerance)
        for (double angle : {detail::kPi / 2, 3 * detail::kPi / 2})
          turns.push_back(Eigen::AngleAxisd(angle, axis).toRotationMatrix());
    }
    for (const Eigen::Matrix3d& t : turns) {
      Eigen::Matrix4d s = Eigen::Matrix4d::Identity();
      const Eigen::Matrix3d r = box.axes * t * box.axes.transpose();
      s.topLeftCorner<3, 3>() = r;
      s.topRightCorner<3, 1>() = box.centre - r * box.centre;
      if (!known(r) && maps_onto_itself(s)) out.push_back(s);
    }
  }
  // Products of symmetries are symmetries: a square prism's 180-degree turns about the diagonals
  // of its square are a 90-degree turn about its axis followed by a 180-degree one about a side.
  for (std::size_t i = 1; i < out.size(); ++i)
    for (std::size_t j = 1; j <= i && out.size() < 24; ++j)
      for (const Eigen::Matrix4d& s :
           {Eigen::Matrix4d(out[i] * out[j]), Eigen::Matrix4d(out[j] * out[i])})
        if (!known(s.topLeftCorner<3, 3>()) && maps_onto_itself(s)) out.push_back(s);
  return out;
}

PoseError pose_error(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth,
                     const std::vector<Eigen::Matrix4d>& symmetries) {
  PoseError best{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  const auto one = [&](const Eigen::Matrix4d& t) {
    const Eigen::Matrix3d dr = estimate.topLeftCorner<3, 3>().transpose() * t.topLeftCorner<3, 3>();
    const double angle = detail::degrees(Eigen::AngleAxisd(dr).angle());
    const double dt = (estimate.topRightCorner<3, 1>() - t.topRightCorner<3, 1>()).norm();
    // Rank by rotation first: symmetric equivalents differ mostly in rotation.
    if (angle < best.rotation_deg) best = {dt, angle};
  };
  one(truth);
  for (const auto& s : symmetries) one(truth * s);
  return best;
}

PoseError axial_pose_error(const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth,
                           const Eigen::Vector3d& centre, const Eigen::Vector3d& axis) {
  const Eigen::Vector3d a = estimate.topLeftCorner<3, 3>() * axis.normalized();
  const Eigen::Vector3d b = truth.topLeftCorner<3, 3>() * axis.normalized();
  const Eigen::Vector3d ca =
      estimate.topLeftCorner<3, 3>() * centre + estimate.topRightCorner<3, 1>();
  const Eigen::Vector3d cb = truth.topLeftCorner<3, 3>() * centre + truth.topRightCorner<3, 1>();
  return {(ca - cb).norm(), detail::degrees(std::acos(std::clamp(a.dot(b), -1.0, 1.0)))};
}

}  // namespace proxseg
