// Real YCB-Video scenes scored per labelled object: segments, names, poses, leave-one-out
// (real_eval.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/real_eval.hpp>

#include <proxseg/eval/scene_eval.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

namespace proxseg {

YcbModels read_ycb_models(const std::string& ycbv_dir) {
  const std::filesystem::path dir(ycbv_dir);
  YcbModels m;
  m.classes = read_lines((dir / "classes.txt").string());
  for (const std::string& c : m.classes) {
    m.points[c] = read_xyz((dir / "models" / c / "points.xyz").string());
    m.diameter[c] = model_diameter(m.points[c]);
  }
  return m;
}

Database ycb_database(const YcbModels& models, const std::string& db_dir) {
  Database db = open_database(db_dir, DescriptorParams{});
  for (const std::string& c : models.classes) {
    Frame f;
    for (const auto& p : models.points.at(c)) f.xyz.push_back(p.cast<float>());
    f.width = static_cast<int>(f.xyz.size());
    f.height = 1;
    add_view(db, c, f, Eigen::Vector3d::Constant(std::nan("")), "models/" + c + "/points.xyz");
  }
  return db;
}

Database without_object(const Database& db, const std::string& object) {
  Database out = db;
  out.views.erase(std::remove_if(out.views.begin(), out.views.end(),
                                 [&](const ModelView& v) { return v.object == object; }),
                  out.views.end());
  return out;
}

std::vector<std::string> ycb_frame_stems(const std::string& dir) {
  const std::string suffix = "-meta.json";
  std::vector<std::string> stems;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() > suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      stems.push_back(name.substr(0, name.size() - suffix.size()));
  }
  if (ec) throw InputError(dir + ": cannot list (" + ec.message() + ")");
  if (stems.empty()) throw InputError(dir + ": holds no *-meta.json (expected YCB-Video frames)");
  std::sort(stems.begin(), stems.end());
  return stems;
}

namespace {

// The points of each instance label (1..n), ascending.
std::vector<std::vector<int>> segments_of(const std::vector<std::uint32_t>& instance) {
  std::vector<std::vector<int>> out;
  for (std::size_t i = 0; i < instance.size(); ++i) {
    if (instance[i] == 0) continue;
    if (instance[i] > out.size()) out.resize(instance[i]);
    out[instance[i] - 1].push_back(static_cast<int>(i));
  }
  return out;
}

// Index of the segment of largest IoU with `truth` (-1 when none overlaps), and that IoU.
int best_overlap(const std::vector<int>& truth, const std::vector<std::vector<int>>& segments,
                 double& iou) {
  int best = -1;
  iou = 0;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const double x = point_iou(truth, segments[s]);
    if (x > iou) iou = x, best = static_cast<int>(s);
  }
  return best;
}

std::vector<std::vector<int>> points_of(const std::vector<SceneObject>& objects) {
  std::vector<std::vector<int>> out;
  for (const SceneObject& o : objects) out.push_back(o.points);
  return out;
}

// Share of `points` (ascending) that lie in `truth` (ascending).
double share_in(const std::vector<int>& points, const std::vector<int>& truth) {
  std::size_t n = 0;
  for (int p : points) n += std::binary_search(truth.begin(), truth.end(), p);
  return points.empty() ? 0 : double(n) / points.size();
}

// "name (N points at R m, score S, runner-up O T)".
std::string describe_answer(const SceneObject& o) {
  char buf[160];
  const Recognition& r = o.recognition;
  std::snprintf(buf, sizeof buf, " (%zu points at %.2f m, score %.2f, runner-up %s %.2f)",
                o.points.size(), o.centroid.norm(), r.best.score, r.runner_up.object.c_str(),
                r.runner_up.score);
  return r.name + buf;
}

}  // namespace

std::vector<RealObjectScore> score_segments(const YcbFrame& frame,
                                            const std::vector<std::uint32_t>& instance,
                                            const RealEvalParams& params) {
  const std::vector<std::vector<int>> segments = segments_of(instance);
  std::vector<RealObjectScore> out;
  for (const ObjectTruth& o : frame.objects) {
    if (static_cast<int>(o.points.size()) < params.min_pixels) continue;
    RealObjectScore s;
    s.object = o.name;
    s.pixels = static_cast<int>(o.points.size());
    best_overlap(o.points, segments, s.iou);
    s.segmented = s.iou >= params.min_iou;
    out.push_back(s);
  }
  return out;
}

RealFrameScore score_recognition(const YcbFrame& frame, const std::vector<SceneObject>& objects,
                                 const YcbModels& models, const RealEvalParams& params) {
  const std::vector<std::vector<int>> segments = points_of(objects);
  RealFrameScore out;
  std::vector<char> matched(objects.size(), 0);  // the match of a labelled object of its name
  for (const ObjectTruth& o : frame.objects) {
    const int best = [&] {
      double iou = 0;
      return best_overlap(o.points, segments, iou);
    }();
    if (best >= 0 && objects[best].recognition.name == o.name &&
        point_iou(o.points, segments[best]) >= params.min_iou)
      matched[best] = 1;
    if (static_cast<int>(o.points.size()) < params.min_pixels) continue;
    RealObjectScore s;
    s.object = o.name;
    s.pixels = static_cast<int>(o.points.size());
    if (best >= 0) s.iou = point_iou(o.points, segments[best]);
    s.segmented = s.iou >= params.min_iou;
    if (s.segmented) {
      const Recognition& r = objects[best].recognition;
      s.named = r.name;
      s.best = r.best.object;
      s.score = r.best.score;
      s.runner_up = r.runner_up.object;
      s.runner_up_score = r.runner_up.score;
    }
    if (s.right()) {
      s.add_s = add_s(models.points.at(o.name), objects[best].recognition.best.pose, o.pose);
      s.pose_ok = s.add_s < params.pose_share * models.diameter.at(o.name);
    }
    out.objects.push_back(s);
  }
  for (std::size_t k = 0; k < objects.size(); ++k)
    if (!matched[k] && objects[k].recognition.name != kUnknown)
      out.other_names.push_back(describe_answer(objects[k]));
  return out;
}

LeaveOneOutScore score_leave_one_out(const YcbFrame& frame, const std::string& missing,
                                     const std::vector<SceneObject>& objects,
                                     const YcbModels& models, const RealEvalParams& params) {
  LeaveOneOutScore out;
  out.missing = missing;
  const auto truth = std::find_if(frame.objects.begin(), frame.objects.end(),
                                  [&](const ObjectTruth& o) { return o.name == missing; });
  if (truth == frame.objects.end())
    throw InputError("leave-one-out: " + missing + " is not an object of the frame");
  for (const SceneObject& s : objects)
    if (s.recognition.name != kUnknown && share_in(s.points, truth->points) > 0.5)
      out.missing_named = s.recognition.name;
  const RealFrameScore scored = score_recognition(frame, objects, models, params);
  for (const RealObjectScore& o : scored.objects) {
    if (o.object == missing) continue;
    ++out.others;
    out.others_named += o.right();
  }
  return out;
}

void RealCounts::add(const RealFrameScore& f) {
  for (const RealObjectScore& o : f.objects) {
    ++objects;
    segmented += o.segmented;
    named += o.right();
    pose_ok += o.pose_ok;
  }
  other_names += static_cast<int>(f.other_names.size());
}

void RealCounts::add(const LeaveOneOutScore& l) {
  ++loo_cases;
  loo_missing_unknown += l.missing_named.empty();
  loo_others += l.others;
  loo_others_named += l.others_named;
}

RealFrameResult evaluate_real_frame(const YcbFrame& frame, const std::string& name,
                                    const FrameRecognizer& method, const Database& db,
                                    const YcbModels& models, const RealEvalParams& params) {
  RealFrameResult out;
  const auto start = std::chrono::steady_clock::now();
  const DatabaseRecognizer recognize = method(frame);
  const std::vector<SceneObject> objects = recognize(db);
  out.counts.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.counts.frames = 1;
  const RealFrameScore score = score_recognition(frame, objects, models, params);
  out.counts.add(score);
  out.objects = score.objects;
  for (const auto& n : score.other_names) out.notes.push_back(name + ": other name " + n);
  for (const auto& s : score.objects)
    if (!s.right()) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "%s: %s (IoU %.2f) as %s: best %s %.2f, runner-up %s %.2f",
                    name.c_str(), s.object.c_str(), s.iou,
                    s.named.empty() ? "no object" : s.named.c_str(), s.best.c_str(), s.score,
                    s.runner_up.c_str(), s.runner_up_score);
      out.notes.push_back(buf);
    }
  for (const auto& s : score.objects) {
    const LeaveOneOutScore l = score_leave_one_out(
        frame, s.object, recognize(without_object(db, s.object)), models, params);
    out.counts.add(l);
    if (!l.missing_named.empty())
      out.notes.push_back(name + ": without " + s.object + ", named " + l.missing_named);
    if (l.others_named < l.others)
      out.notes.push_back(name + ": without " + s.object + ", " +
                          std::to_string(l.others - l.others_named) + " other(s) not named");
  }
  return out;
}

FrameRecognizer proxseg_recognizer(const SegmentParams& segment,
                                   const RecognitionParams& recognition) {
  return [segment, recognition](const YcbFrame& y) -> DatabaseRecognizer {
    auto seg = std::make_shared<const SegmentResult>(proxseg::segment(y.frame, segment));
    return [recognition, &y, seg](const Database& db) {
      return recognize_scene(y.frame, seg->selection, db, recognition);
    };
  };
}

RealCounts& RealCounts::operator+=(const RealCounts& o) {
  frames += o.frames;
  objects += o.objects;
  segmented += o.segmented;
  named += o.named;
  pose_ok += o.pose_ok;
  other_names += o.other_names;
  loo_cases += o.loo_cases;
  loo_missing_unknown += o.loo_missing_unknown;
  loo_others += o.loo_others;
  loo_others_named += o.loo_others_named;
  seconds += o.seconds;
  return *this;
}

}  // namespace proxseg
