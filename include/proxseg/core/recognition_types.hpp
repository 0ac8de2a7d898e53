// The plain data of recognition [paper 3.4, Algorithm 3]: its options, a candidate's
// recognition and a recognised scene object. recognize() and recognize_scene(), which make them,
// are in the recognition library (proxseg/recognition/recognition.hpp); the reports and the
// parameters' JSON form (io) need only these.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/registration_types.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace proxseg {

// The look-alike vote between a candidate's two best views (proxseg/recognition/lookalike.hpp).
struct LookalikeVote {
  int compared = 0;   // candidate points that both posed views explain (within score_distance)
  int differing = 0;  // of those, the points where the two views' colours disagree
  int first = 0, second = 0;  // of those, the points that agree clearly better with each view
  // Mean colour agreement of each view's voters with that view: a candidate of neither colour
  // may still lean to one of them, but agrees with it poorly.
  double first_agreement = 0, second_agreement = 0;
};

enum class Score {
  kFitness,    // the paper's eq. 5: candidate points explained by the model (one-sided)
  kSymmetric,  // sqrt(close_fitness x coverage), both within score_distance: also the share of
               // the visible model the candidate explains, so that a small box on the face of a
               // big one does not score 1
  kColour,     // kSymmetric x the colour agreement of the explained points (Alignment::colour):
               // tells apart objects of one shape in different colours. When the candidate or the
               // view has no colour, x kColourlessAgreement instead.
};
// The names of its values, in its order: how the CLI, JSON configs and Python spell them.
inline std::vector<std::string> value_names(Score) {
  return {"fitness", "symmetric", "colour"};
}

// The colour term of a comparison without colour: about what a right answer's colour agreement
// is (docs/method.md "Colour in recognition"), so that a view without colour neither wins over
// coloured ones nor passes the minimum score for free.
constexpr double kColourlessAgreement = 0.93;

struct RecognitionParams {
  RegistrationParams registration;
  Score score = Score::kColour;
  double min_score = 0.55;  // best score below it: "unknown" (unless a lone match, below)
  // Best score minus the runner-up's (the best view of another object) below it: "unknown"
  // [extension, docs/method.md "Unknown objects"]: another model explains the candidate about as
  // well, as happens for an object the database does not hold, which several models fit a bit.
  double min_margin = 0.15;
  // At or above this best score the margin is not asked for: a model that explains this much of
  // the candidate and of its own visible surface names it even when a look-alike comes close
  // (the YCB-Video gelatin box, 0.89, against the pudding box, 0.76, by shape alone).
  double confident_score = 0.8;
  // An answer explains the candidate [extension, docs/method.md "Real sensors"]: a full model
  // (a view without a viewpoint, such as `db add --xyz` makes) competes as the answer or the
  // runner-up only when its fitness (eq. 5) is at least this; with none, the answer is
  // "unknown". A model that explains a part of the candidate (a small box on a big box's face,
  // a mug on a can) would need another object beside it to explain the rest: it is neither the
  // answer nor a rival of one that explains it all. Partial views are not held to it: they may
  // rightly explain only what they saw of a candidate seen from elsewhere. 0 = every view.
  // Chosen on the real video0001 (named 8 -> 14 of 20 at 0.8-0.9); no change on frames/.
  double explain_fitness = 0.85;
  // Physical support [extension, docs/method.md "Real sensors"] (metres; 0 = off): in a scene
  // with a support plane, a pose whose lowest point lies more than this under the plane (through
  // the table), or a full model's more than this over it with no other object's top surface
  // under it (in the air), is neither the answer nor the runner-up (stance(), support.hpp).
  // Partial views are not held to floating: their lowest point need not be the object's.
  double support_gap = 0.02;
  // A lone match [extension, docs/method.md "Recognition that generalises"]: a best score under
  // min_score but at least lone_score still names the object when the runner-up, and every other
  // object's view that explains the candidate in any stance (through the table too), scores at
  // most lone_ratio of it (Lowe's ratio test), and only when colour was compared (both clouds
  // coloured) and another object's views competed over the whole shortlist: a piece of an
  // object (a fragment, a merge with a neighbour) that shape and colour both single out from
  // every other model. Without colour, or with a runner-up from a trial's few objects, a far
  // runner-up says little: an unknown object that fits one model of a small database a bit is
  // far from all the others too. 0 = off.
  double lone_score = 0.4;
  double lone_ratio = 0.45;
  // Look-alikes [extension, docs/method.md "Recognition that generalises"]: when the runner-up
  // comes within min_margin of the best and both explain the candidate's shape alike well
  // (Score::kSymmetric at least lookalike_shape: two models of one shape), the candidate points
  // where the two views' colours differ vote (lookalike_vote(), lookalike.hpp). At least
  // lookalike_share of the votes (and 10 votes) for one of them, whose voters agree with its
  // colours at least lookalike_agreement on average, name it (made the best if it was the
  // runner-up) without the margin. 0 = off.
  double lookalike_share = 0.8;
  double lookalike_agreement = 0.6;
  double lookalike_shape = 0.75;
  // Views aligned per candidate: the ones nearest to it by signature (view_distance(), or
  // signature_distance() without shortlist_parts; registration.hpp), with the nearest view of a
  // second object when they all show one, so that there is a runner-up [extension,
  // docs/method.md "A database that scales"]; 0 = every view (the paper).
  int shortlist = 24;
  // Compare the candidate also with the signatures of parts of each view (the view without the
  // points near one of several centres, as an occlusion leaves it), nearest of them counting, so
  // that a partly hidden object still finds its views.
  bool shortlist_parts = true;
  // Views aligned per split or merge trial of recognize_scene(), among the views of the objects
  // the trial concerns (nearest by signature); 0 = all of those objects' views.
  int trial_shortlist = 4;

  // > 0: stop after the first batch of views (8 at a time, nearest by signature first) in which
  // some view reached this score. Faster; may change the answer (a later view could score
  // higher). 0 = align every shortlisted view.
  double early_exit = 0.8;
  // > 0: stop after a batch of views in which no view so far reached this rank (rank_of()):
  // nothing of the database fits (an unknown object, a piece of one), and the views further down
  // the shortlist are less like the candidate. Faster; may change the answer (a thin object
  // whose own views come late). 0 = align the whole shortlist (docs/method.md has the measured
  // choice of the default).
  double early_reject = 0.3;
  // Scenes [extension, docs/method.md "Candidates that recognition splits or merges"]: the model
  // that names a candidate also tells which of its points belong to it.
  // Split: a named candidate whose best fitness is under split_fitness is cut into the points
  // its model explains and the rest, when both have min_part_points and both are named on their
  // own (two touching objects that the selection kept together). 0 = off.
  double split_fitness = 0.8;
  // Merge: two candidates whose points come within merge_distance (metres) and whose union is
  // named with a better score than either part become one (an object cut in two by a missing
  // rim or a shadow). 0 = off.
  double merge_distance = 0.03;
  // Merge also two unnamed pieces whose best views show one object (an object cut in two, each
  // half too little of it to be named); otherwise one of the two must be named.
  bool merge_unnamed = true;
  int min_part_points = 500;  // points of the frame
  // Scenes [extension, docs/method.md "Recognition that generalises"]: a view put where the
  // sensor saw through it is not the object. Scores are multiplied by 1 - the share of the
  // posed view's sensor-facing points more than free_space_tolerance + 0.005 z^2 metres in front
  // of the measured depth (free_space_violation()). Organized frames only; 0 = off.
  double free_space_tolerance = 0.01;
  // Occlusion [extension, docs/method.md "Real sensors"] (metres; 0 = off): the view's visible
  // points outside the candidate's silhouette behind a surface the sensor measured more than
  // this + 0.005 z^2 nearer (an occluder in front) are left out of the coverage instead of
  // counting as missing (coverage_counts() with a scene), so that an object half behind another
  // is judged on its visible half. Organized frames only; needs free_space_tolerance > 0.
  double hidden_depth = 0.03;
  std::uint64_t seed = 1;
  int threads = 0;  // 0 = all cores; the answer does not depend on it
};

// Checks ranges (distances > 0, scores in [0, 1], ...); throws InputError naming the field.
void validate(const RecognitionParams& params);

struct Match {
  std::string object;                                  // empty when there is none
  int view = -1;                                       // index into Database::views
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  // candidate frame <- model frame
  double fitness = 0, coverage = 0, score = 0, rmse = 0;
  double rank = 0;    // rank_of(): the score allowing for an occlusion, which chose the best view
  double colour = 1;  // Alignment::colour
  double free_space = 0;  // Alignment::free_space
};

// The name of a candidate that no object of the database explains (paper 3.4, Alg. 3): never
// the name of a database object.
inline constexpr const char* kUnknown = "unknown";

struct Recognition {
  std::string name;  // best.object, or kUnknown (neither names_best() nor the vote names it)
  Match best;        // the view of the best rank (Match::rank)
  Match runner_up;   // the best-scoring view (Match::score) of any other object
  // The look-alike vote between best and runner_up when the runner-up came within min_margin
  // (compared = 0 otherwise); `first` counts for best, also when the vote made it the best.
  LookalikeVote lookalike;
  bool lookalike_decided = false;     // the vote named best (RecognitionParams::lookalike_share)
  std::vector<Alignment> alignments;  // per database view (empty slots: not aligned)
  int views_aligned = 0;  // the shortlist's views aligned (fewer on an early exit or reject)
  double align_ms = 0;    // wall time over all views
  // Views left out because their stored records are damaged ("where: what"); the others still
  // answer.
  std::vector<std::string> damaged;
  double describe_ms = 0;  // describing the candidate (recognize_object, recognize_scene; 0 from
                           // recognize(), which is given it described)
};

// One recognised object: the frame points it holds, the selection instances they came from,
// and its recognition.
struct SceneObject {
  int id = 0;               // 1.. in recognize_scene's order; 0 for recognize_object
  std::vector<int> points;  // frame point indices, ascending
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // of those points, metres
  std::vector<std::uint32_t> instances;  // the candidates (instance ids) it holds points of
  enum class Origin { kCandidate, kSplit, kMerged } origin = Origin::kCandidate;
  Recognition recognition;
};

}  // namespace proxseg
