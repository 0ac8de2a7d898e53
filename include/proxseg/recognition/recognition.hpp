// Recognition [paper 3.4, Algorithm 3]: align a candidate to every model view of the database
// and name it after the view with the best score, or "unknown" under a threshold.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/recognition_types.hpp>
#include <proxseg/core/selection.hpp>
#include <proxseg/recognition/lookalike.hpp>
#include <proxseg/recognition/registration.hpp>
#include <proxseg/recognition/support.hpp>
#include <proxseg/recognition/visibility.hpp>

#include <functional>
#include <string>
#include <vector>

namespace proxseg {

// Whether recognize() names the best view's object: score >= min_score and either score -
// runner_up >= min_margin or score >= confident_score; or, when `lone` (colour compared, a
// runner-up from the whole shortlist), score >= lone_score and runner_up <= lone_ratio x score.
// runner_up: the best score of another object, 0 when there is none.
bool names_best(double score, double runner_up, const RecognitionParams& params, bool lone = false);
// Whether a view aligned to a candidate may be its answer or the runner-up: a full model (a
// view with no viewpoint, seen from everywhere) must explain explain_fitness of the candidate
// and must not float (Alignment::stance); a partial view may explain a part (the candidate may
// show sides the view does not); no pose may sink through the support plane.
bool explains_candidate(const ModelView& view, const Alignment& a, const RecognitionParams& params);

// The look-alike vote [extension, docs/method.md "Recognition that generalises"] between the
// best view of a candidate and the runner-up (the best view of another object), each with its
// alignment: 0 when it does not decide (the runner-up is not within min_margin, either view
// explains the candidate's shape under lookalike_shape, or the vote is not clear, see
// RecognitionParams::lookalike_share), 1 when it names the best, 2 when it names the runner-up.
// The vote, when taken, goes to `vote`.
int tell_lookalikes(const Cloud& candidate, const Cloud& best_view, const Alignment& best,
                    const Cloud& runner_up_view, const Alignment& runner_up,
                    const RecognitionParams& params, LookalikeVote* vote = nullptr);

// The score of an alignment (Score); what the minimum score, the margin and the confident score
// judge.
double score_of(const Alignment& a, Score score);
// The same with Alignment::occluded_coverage for coverage: what ranks the views, allowing for an
// occlusion [extension, docs/method.md "A database that scales"].
double rank_of(const Alignment& a, Score score);

// Describes the candidate's points (sensor frame; sensor at the origin) like the database views,
// with their colours when given (one per point).
Cloud describe_candidate(const std::vector<Eigen::Vector3d>& points, const Database& db,
                         const std::vector<Rgb>* colours = nullptr);
// The views recognize() aligns: those of `objects` (every object when empty), the `shortlist`
// nearest to the candidate by signature (all when 0; with `parts`, by view_distance(), the
// nearest of each view's signature and its parts' ones), nearest first, and the nearest view of
// another object when those show only one. A view's parts are read only when its part sketches
// (ModelView::part_sketches) still let it in; a view whose parts record is damaged is left out
// and named in `damaged`.
std::vector<int> shortlist_views(const Cloud& candidate, const Database& db, int shortlist,
                                 const std::vector<std::string>& objects = {}, bool parts = true,
                                 std::vector<std::string>* damaged = nullptr);
// The parameters recognition uses for a candidate: the score distance at its range
// (RegistrationParams::score_distance_slope).
RecognitionParams at_range(const RecognitionParams& params, const Cloud& candidate);
// Algorithm 3 for one described candidate, over the views of `objects` (all when empty).
// With the scene's evidence (recognize_scene() passes it), every alignment is also checked
// against the sensor's free space (its depths, when free_space_tolerance > 0) and for its
// stance on the support plane (when support_gap > 0).
Recognition recognize(const Cloud& candidate, const Database& db, const RecognitionParams& params,
                      const std::vector<std::string>& objects = {},
                      const SceneEvidence& scene = {});

// Algorithm 3 for one object given as a cloud of its own (every valid point of `cloud`, with its
// colours when it has them): describes it like the database views (Recognition::describe_ms)
// and aligns it. id 0, points = the valid points, instances empty.
SceneObject recognize_object(const Frame& cloud, const Database& db,
                             const RecognitionParams& params);

// Algorithm 3 over every candidate of a selection (background excluded), then the split and
// merge passes of RecognitionParams. `progress` is called after each recognition with the
// object just recognised (the candidates' in any order: they run in parallel; one call at a
// time; its id not yet set). Objects come in order of their smallest point index, with ids 1...
std::vector<SceneObject> recognize_scene(
    const Frame& frame, const Selection& selection, const Database& db,
    const RecognitionParams& params, const std::function<void(const SceneObject&)>& progress = {});

}  // namespace proxseg
