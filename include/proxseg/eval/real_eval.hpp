// Real YCB-Video scenes scored per labelled object (docs/results.md "Real scenes"): segmented
// (a candidate at IoU >= 0.5), named right, pose within ADD-S of 10 % of the diameter, names given
// to no object of that name, and leave-one-out (the object's model missing from the database: it
// must come out unknown, the others still named). Each video is one fold: its frames are one
// scene seen several times, not independent samples.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/recognition_types.hpp>
#include <proxseg/eval/ycb_frames.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace proxseg {

// The 21 YCB-Video models: classes.txt's names in order, each model's points.xyz (metres, the
// pose frame of meta.json) and diameter (largest distance between two of its points).
struct YcbModels {
  std::vector<std::string> classes;
  std::map<std::string, std::vector<Eigen::Vector3d>> points;
  std::map<std::string, double> diameter;
};
// Reads DIR/classes.txt and DIR/models/<class>/points.xyz. InputError naming a missing file.
YcbModels read_ycb_models(const std::string& ycbv_dir);

// A database of every model (one full-model view each, as `proxseg db add --xyz` makes it),
// written to `db_dir` (made; must not hold a database).
Database ycb_database(const YcbModels& models, const std::string& db_dir);
// `db` without the views of `object` (in memory; the other views shared).
Database without_object(const Database& db, const std::string& object);

// The frames of one YCB-Video folder: the stems of its *-meta.json files, in order.
std::vector<std::string> ycb_frame_stems(const std::string& dir);

struct RealEvalParams {
  int min_pixels = 200;     // labelled objects with fewer valid pixels are not scored
  double min_iou = 0.5;     // a candidate segments an object at this IoU or more
  double pose_share = 0.1;  // pose right: ADD-S under this share of the diameter
};

// One labelled object of one frame.
struct RealObjectScore {
  std::string object;
  int pixels = 0;     // its valid labelled pixels
  double iou = 0;     // with the candidate (or recognised object) that overlaps it most
  std::string named;  // that object's name ("" when no object reaches min_iou)
  // That object's best view and runner-up (Recognition::best, ::runner_up): what the answer
  // was made of.
  std::string best, runner_up;
  double score = 0, runner_up_score = 0;
  double add_s = -1;       // metres, when named right; else -1
  bool pose_ok = false;    // named right and ADD-S under pose_share x diameter
  bool segmented = false;  // iou >= min_iou
  bool right() const { return segmented && named == object; }
};

struct RealFrameScore {
  std::vector<RealObjectScore> objects;  // the scored (>= min_pixels) labelled objects
  // Names given to a recognised object that is not the match of a labelled object of that name:
  // "name (N points at R m, score S, runner-up O T)".
  std::vector<std::string> other_names;
};

// The best IoU of each scored labelled object among the segments (instance labels per point of
// the frame, 0 = none).
std::vector<RealObjectScore> score_segments(const YcbFrame& frame,
                                            const std::vector<std::uint32_t>& instance,
                                            const RealEvalParams& params = {});
// Recognised objects (recognize_scene()) against the frame's labels and poses.
RealFrameScore score_recognition(const YcbFrame& frame, const std::vector<SceneObject>& objects,
                                 const YcbModels& models, const RealEvalParams& params = {});

// One leave-one-out case: the frame recognised without `missing`'s model.
struct LeaveOneOutScore {
  std::string missing;
  // The name given to a recognised object lying mostly (> half its points) on the missing
  // object's pixels ("" when none is named).
  std::string missing_named;
  int others = 0, others_named = 0;  // the other scored objects; of them, named right
};
LeaveOneOutScore score_leave_one_out(const YcbFrame& frame, const std::string& missing,
                                     const std::vector<SceneObject>& objects,
                                     const YcbModels& models, const RealEvalParams& params = {});

// Sums over the frames of a fold.
struct RealCounts {
  int frames = 0;
  int objects = 0, segmented = 0, named = 0, pose_ok = 0, other_names = 0;
  int loo_cases = 0, loo_missing_unknown = 0, loo_others = 0, loo_others_named = 0;
  double seconds = 0;  // wall time of segment + recognize, summed over frames
  void add(const RealFrameScore& f);
  void add(const LeaveOneOutScore& l);
  RealCounts& operator+=(const RealCounts& o);
};

// A method's recognised objects of one frame for a database (the full one or one without an
// object); made once per frame so that its segmentation serves every database.
using DatabaseRecognizer = std::function<std::vector<SceneObject>(const Database&)>;
using FrameRecognizer = std::function<DatabaseRecognizer(const YcbFrame&)>;

// What a frame's evaluation adds: its counts (wall time of the whole database's recognition,
// leave-one-out not timed), its scored objects and its misses, "FRAME: what".
struct RealFrameResult {
  RealCounts counts;
  std::vector<RealObjectScore> objects;
  std::vector<std::string> notes;
};
// The frame recognised with the whole database, then once per scored object without it.
RealFrameResult evaluate_real_frame(const YcbFrame& frame, const std::string& name,
                                    const FrameRecognizer& method, const Database& db,
                                    const YcbModels& models, const RealEvalParams& params = {});
// proxseg as a FrameRecognizer: segment() once, recognize_scene() per database. The parameters
// are copied.
FrameRecognizer proxseg_recognizer(const SegmentParams& segment,
                                   const RecognitionParams& recognition);

}  // namespace proxseg
