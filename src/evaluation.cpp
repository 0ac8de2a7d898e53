// Evaluation of segmentations on labelled scenes: schemes, categories, summaries.
#include <proxseg/evaluation.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>

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
  if (!std::regex_match(name, m, learn)) return "other";
  const int i = std::stoi(m[1]);
  return i <= 16   ? "boxes"
         : i <= 24 ? "stacked"
         : i <= 32 ? "occluded"
         : i <= 44 ? "cylindric"
                   : "other";
}

std::vector<std::filesystem::path> scene_files(const std::string& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw InputError(dir + ": not a directory (expected a folder of labelled PCD scenes)");
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".pcd") files.push_back(e.path());
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
  if (files.empty()) throw InputError(dir + ": no .pcd files (expected labelled PCD scenes)");
  return files;
}

std::vector<SummaryRow> summarize(const std::vector<SceneScores>& scenes) {
  // Methods keep their first-seen order; categories their natural order, "all" last.
  std::vector<std::string> methods;
  for (const auto& s : scenes)
    if (std::find(methods.begin(), methods.end(), s.method) == methods.end())
      methods.push_back(s.method);
  const std::vector<std::string> categories = {"boxes",     "stacked", "occluded",
                                               "cylindric", "other",   "all"};
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
      for (const auto& s : scenes) {
        if (s.method != method || (category != "all" && s.category != category)) continue;
        r.seconds += w * s.seconds;
        accumulate(r.objects, s.objects, w);
        accumulate(r.parts, s.parts, w);
        r.over_segmented += w * s.objects.over_segmented;
        r.under_segmented += w * s.objects.under_segmented;
        r.truth_objects += w * s.objects.truth_objects;
      }
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
          {"under_segmented", s.under_segmented}};
}

std::string scenes_csv(const std::vector<SceneScores>& scenes) {
  std::ostringstream out;
  out << "scene,category,method,seconds";
  for (const char* scheme : {"objects", "parts"})
    for (const char* m :
         {"paper_precision", "paper_recall", "homogeneity", "completeness", "v_measure",
          "weighted_overlap", "object_precision", "object_recall", "object_f", "detected_075",
          "over_segmented", "under_segmented", "truth_objects", "segments"})
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
          << x->truth_objects << "," << x->segments;
    out << "\n";
  }
  return out.str();
}

std::string summary_markdown(const std::vector<SummaryRow>& rows) {
  std::ostringstream out;
  out << "| method | category | scenes | object F | object P | object R | F>=0.75 | V | WOv | "
         "paper P | paper R | over | under | parts F | parts V | s/frame |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows)
    out << "| " << r.method << " | " << r.category << " | " << r.scenes << " | "
        << fmt(r.objects.object_f) << " | " << fmt(r.objects.object_precision) << " | "
        << fmt(r.objects.object_recall) << " | " << fmt(r.objects.detected_075) << " | "
        << fmt(r.objects.v.v) << " | " << fmt(r.objects.weighted_overlap) << " | "
        << fmt(r.objects.paper_precision) << " | " << fmt(r.objects.paper_recall) << " | "
        << fmt(r.over_segmented, 2) << " | " << fmt(r.under_segmented, 2) << " | "
        << fmt(r.parts.object_f) << " | " << fmt(r.parts.v.v) << " | " << fmt(r.seconds) << " |\n";
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
    for (nlohmann::json* x : {&objects, &parts}) {
      x->erase("points");
      x->erase("truth_regions");
      x->erase("segments");
    }
    parts.erase("over_segmented");
    parts.erase("under_segmented");
    parts.erase("truth_objects");
    j.push_back({{"method", r.method},
                 {"category", r.category},
                 {"scenes", r.scenes},
                 {"seconds_per_frame", r.seconds},
                 {"objects", objects},
                 {"parts", parts}});
  }
  return j;
}

}  // namespace proxseg
