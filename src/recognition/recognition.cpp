// Recognition [paper 3.4, Algorithm 3]: a described candidate aligned to the shortlisted views
// of the database in batches, named after the best view's object when its score is clear of the
// runner-up's (or the look-alike vote decides), "unknown" otherwise.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/stop.hpp>
#include <proxseg/recognition/recognition.hpp>

#include "util/first_error.hpp"
#include "util/splitmix.hpp"
#include "util/stopwatch.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

namespace proxseg {
namespace {

// splitmix64's first draw from state x: one independent RANSAC stream per view from the one seed.
std::uint64_t mix(std::uint64_t x) {
  return SplitMix{x}.next();
}

constexpr int kBatch = 8;  // views per early-exit check; fixed, so answers do not depend on threads

double score_with(const Alignment& a, Score score, double coverage) {
  const double seen = (1 - a.free_space) * (1 - a.border_unexplained);
  switch (score) {
    case Score::kFitness:
      return a.fitness;
    case Score::kSymmetric:
      return symmetric_overlap(a.close_fitness, coverage) * seen;
    case Score::kColour:
      return symmetric_overlap(a.close_fitness, coverage) *
             (a.coloured ? a.colour : kColourlessAgreement) * seen;
  }
  return 0;
}

}  // namespace

int tell_lookalikes(const Cloud& candidate, const Cloud& best_view, const Alignment& best,
                    const Cloud& runner_up_view, const Alignment& runner_up,
                    const RecognitionParams& params, LookalikeVote* vote) {
  // Fewer votes than this (2.5 square cm at 5 mm voxels) are a seam or a few noisy points.
  constexpr int kMinVotes = 10;
  if (!(params.lookalike_share > 0) ||
      score_of(best, params.score) - score_of(runner_up, params.score) >= params.min_margin)
    return 0;
  // Two models of one shape: both explain the candidate's shape well. A candidate that two
  // models fit only partly is as likely an object of neither, which leans to one in colour.
  for (const Alignment* a : {&best, &runner_up})
    if (score_of(*a, Score::kSymmetric) < params.lookalike_shape) return 0;
  const LookalikeVote v = lookalike_vote(candidate, best_view, best.pose, runner_up_view,
                                         runner_up.pose, params.registration);
  if (vote) *vote = v;
  return lookalike_winner(v, params.lookalike_share, params.lookalike_agreement, kMinVotes);
}

bool explains_candidate(const ModelView& view, const Alignment& a,
                        const RecognitionParams& params) {
  // A partial view may rightly explain only a part of a candidate seen from elsewhere, and its
  // lowest point need not be the object's: it is held to neither.
  const bool full_model = !view.viewpoint.allFinite();
  if (a.stance == Stance::kSinks || (full_model && a.stance == Stance::kFloats)) return false;
  return !full_model || a.fitness >= params.explain_fitness;
}

bool names_best(double score, double runner_up, const RecognitionParams& params, bool lone) {
  const bool clear = score - runner_up >= params.min_margin || score >= params.confident_score;
  if (score >= params.min_score && clear) return true;
  return lone && params.lone_score > 0 && score >= params.lone_score &&
         runner_up <= params.lone_ratio * score;
}

double score_of(const Alignment& a, Score score) {
  return score_with(a, score, a.coverage);
}

double rank_of(const Alignment& a, Score score) {
  return score_with(a, score, a.occluded_coverage);
}

Cloud describe_candidate(const std::vector<Eigen::Vector3d>& points, const Database& db,
                         const std::vector<Rgb>* colours) {
  return describe(points, Eigen::Vector3d::Zero(), db.descriptor, colours);
}

namespace {

// Aligns the candidate to shortlisted views, those of one batch in parallel: r.alignments[v], and
// done[v] for each view aligned. A view whose record cannot be read is left out, its damage in
// unreadable[k] (k: its place in the shortlist).
struct BatchAligner {
  const Cloud& candidate;
  const Cloud& sample;  // subsample(candidate, max_points), made once
  const Database& db;
  const RecognitionParams& params;
  const SceneEvidence& scene;
  int threads;

  // What the rest of the frame says of a pose: what it stands on; free space, the image border,
  // hidden points.
  void judge_in_scene(Alignment& a, const Cloud& view) const {
    if (scene.support && scene.surfaces && params.support_gap > 0) {
      const StanceCheck s =
          stance(*scene.support, *scene.surfaces, candidate, view, a.pose, params.support_gap);
      a.stance = s.stance;
      a.bottom = s.bottom;
    }
    if (!scene.depths || !(params.free_space_tolerance > 0)) return;
    const DepthImage& depths = *scene.depths;
    a.free_space = free_space_violation(depths, view, a.pose, params.free_space_tolerance);
    a.border_unexplained =
        border_unexplained(depths, candidate, view, a.pose, params.registration.fitness_distance);
    if (!(params.hidden_depth > 0)) return;
    const CoverageCounts c = coverage_counts(
        candidate, view, a.pose, params.registration.score_distance, depths, params.hidden_depth);
    const double visible = c.inside + c.outside, all = visible + c.hidden;
    const double counted = c.inside + params.registration.coverage_outside_weight * c.outside;
    a.coverage = visible > 0 ? c.explained / visible : 0;
    a.occluded_coverage = counted > 0 ? std::min(1.0, c.explained / counted) : 0;
    a.hidden = all > 0 ? c.hidden / all : 0;
  }

  // Aligns the shortlist's k-th view.
  void align_one(const std::vector<int>& views, int k, Recognition& r, std::vector<char>& done,
                 std::vector<std::string>& unreadable, detail::FirstError& failure) const {
    if (failure.failed()) return;
    const int v = views[k];
    const Cloud* view = nullptr;
    try {  // a stored view is read here, the first time it is shortlisted
      stop_point();
      view = &db.views[v].cloud();
    } catch (const InputError& e) {
      unreadable[k] = e.what();
      return;
    } catch (...) {
      failure.capture();
      return;
    }
    try {
      r.alignments[v] = align(candidate, sample, *view, params.registration,
                              mix(params.seed ^ mix(static_cast<std::uint64_t>(v))));
      judge_in_scene(r.alignments[v], *view);
    } catch (...) {
      failure.capture();
      return;
    }
    done[v] = 1;
  }

  // The views of one batch in parallel: on threads of their own, or, when the candidate is itself
  // a task of a parallel region (recognize_scene()'s candidates), as tasks that a thread done
  // with the other candidates takes over.
  void operator()(const std::vector<int>& views, int begin, int end, Recognition& r,
                  std::vector<char>& done, std::vector<std::string>& unreadable) const {
    detail::FirstError failure;  // out of memory in one alignment: the candidate fails
    if (omp_in_parallel()) {
#pragma omp taskloop grainsize(1) shared(views, r, done, unreadable, failure)
      for (int k = begin; k < end; ++k) align_one(views, k, r, done, unreadable, failure);
    } else {
      StopToken* const stop = current_stop_token();  // the team's threads check the caller's
#pragma omp parallel num_threads(threads)
      {
        const StopScope inherit(stop, false);
#pragma omp for schedule(dynamic, 1)
        for (int k = begin; k < end; ++k) align_one(views, k, r, done, unreadable, failure);
      }
    }
    failure.rethrow();
  }
};

// Whether the views aligned so far (the shortlist's first `end`, the last batch from `begin`)
// stop the alignments: one of the batch that may be the answer (explains_candidate()) ranks
// early_exit, or none ranks early_reject.
bool stop_aligning(const Recognition& r, const Database& db, const std::vector<int>& views,
                   int begin, int end, const RecognitionParams& params) {
  const int m = static_cast<int>(views.size());
  if (params.early_exit > 0) {
    bool good = false;
    for (int k = begin; k < end; ++k) {
      const Alignment& a = r.alignments[views[k]];
      good |= rank_of(a, params.score) >= params.early_exit &&
              explains_candidate(db.views[views[k]], a, params);
    }
    if (good) return true;
  }
  if (params.early_reject > 0 && end < m) {
    double best = 0;
    for (int k = 0; k < end; ++k)
      best = std::max(best, rank_of(r.alignments[views[k]], params.score));
    if (best < params.early_reject) return true;
  }
  return false;
}

// Algorithm 3: the best view names the candidate; ties go to the earlier view. Views are
// ranked allowing for an occlusion (rank_of()); the answer is judged on the score, which does
// not: an occlusion may explain why a model's surface is missing, which is reason to prefer the
// model that explains what was seen, but it is no evidence for the object. When the two
// disagree on the object, the runner-up scores more than the best and the answer is doubtful.
void choose_best(Recognition& r, const Database& db, const RecognitionParams& params,
                 const std::vector<char>& done) {
  const int n = static_cast<int>(db.views.size());
  const auto to_match = [&](int v) {
    const Alignment& a = r.alignments[v];
    Match m;
    m.object = db.views[v].object;
    m.view = v;
    m.pose = a.pose;
    m.fitness = a.fitness;
    m.coverage = a.coverage;
    m.score = score_of(a, params.score);
    m.rank = rank_of(a, params.score);
    m.rmse = a.rmse;
    m.colour = a.colour;
    m.free_space = a.free_space;
    return m;
  };
  // Full models that explain only a part of the candidate compete neither as the answer nor as
  // its rival (RecognitionParams::explain_fitness); when none explains it, the best of all is
  // kept to report, and the answer is unknown (recognize()).
  const auto explains = [&](int v) {
    return explains_candidate(db.views[v], r.alignments[v], params);
  };
  for (const bool whole : {true, false}) {
    for (int v = 0; v < n; ++v) {
      if (!done[v] || (whole && !explains(v))) continue;
      const Match m = to_match(v);
      if (r.best.view < 0 || m.rank > r.best.rank) r.best = m;
    }
    if (r.best.view >= 0) break;
  }
  for (int v = 0; v < n; ++v) {
    if (!done[v] || db.views[v].object == r.best.object || !explains(v)) continue;
    const Match m = to_match(v);
    if (r.runner_up.view < 0 || m.score > r.runner_up.score) r.runner_up = m;
  }
}

// The best score of another object than the answer's among the views that explain the
// candidate whatever their stance: a model that fits it only through the table or in the air is
// no answer, but it fits the candidate's shape as well, so the answer is no lone match.
double rival_in_any_stance(const Recognition& r, const Database& db,
                           const RecognitionParams& params, const std::vector<char>& done) {
  double rival = 0;
  for (int v = 0; v < static_cast<int>(db.views.size()); ++v) {
    if (!done[v] || db.views[v].object == r.best.object) continue;
    Alignment a = r.alignments[v];
    a.stance = Stance::kStands;
    if (explains_candidate(db.views[v], a, params))
      rival = std::max(rival, score_of(a, params.score));
  }
  return rival;
}

}  // namespace

RecognitionParams at_range(const RecognitionParams& params, const Cloud& candidate) {
  RecognitionParams out = params;
  RegistrationParams& g = out.registration;
  const double range = (candidate.centroid - candidate.viewpoint).norm();
  if (g.score_distance_slope > 0 && std::isfinite(range))
    g.score_distance = std::max(g.score_distance, g.score_distance_slope * range);
  return out;
}

Recognition recognize(const Cloud& candidate, const Database& db,
                      const RecognitionParams& given_params,
                      const std::vector<std::string>& objects, const SceneEvidence& scene) {
  // The sensor's error at the candidate's range sets the score's distance.
  const RecognitionParams params = at_range(given_params, candidate);
  Recognition r;
  const int n = static_cast<int>(db.views.size());
  r.alignments.assign(n, Alignment{});
  std::vector<char> done(n, 0);
  const int threads = params.threads > 0 ? params.threads : omp_get_max_threads();
  const detail::Stopwatch align_watch;
  const Cloud sample = subsample(candidate, params.registration.max_points);
  const std::vector<int> views =
      shortlist_views(candidate, db, params.shortlist, objects, params.shortlist_parts, &r.damaged);
  std::vector<std::string> unreadable(views.size());  // per shortlisted view, its record's damage
  const BatchAligner align_batch{candidate, sample, db, params, scene, threads};
  const int m = static_cast<int>(views.size());
  for (int begin = 0; begin < m; begin += kBatch) {
    stop_point();
    const int end = std::min(m, begin + kBatch);
    align_batch(views, begin, end, r, done, unreadable);
    r.views_aligned = end;
    if (stop_aligning(r, db, views, begin, end, params)) break;
  }
  r.align_ms = align_watch.ms();
  for (const std::string& e : unreadable)
    if (!e.empty()) r.damaged.push_back(e);
  choose_best(r, db, params, done);
  if (r.best.view >= 0 && r.runner_up.view >= 0) {
    const int winner = tell_lookalikes(
        candidate, db.views[r.best.view].cloud(), r.alignments[r.best.view],
        db.views[r.runner_up.view].cloud(), r.alignments[r.runner_up.view], params, &r.lookalike);
    if (winner == 2) {  // the runner-up's colours are the candidate's: it is the answer
      std::swap(r.best, r.runner_up);
      std::swap(r.lookalike.first, r.lookalike.second);
      std::swap(r.lookalike.first_agreement, r.lookalike.second_agreement);
    }
    r.lookalike_decided = winner != 0;
  }
  const double runner_up = r.runner_up.view >= 0 ? r.runner_up.score : 0.0;
  const bool lone = objects.empty() && r.runner_up.view >= 0 && r.best.view >= 0 &&
                    r.alignments[r.best.view].coloured &&
                    rival_in_any_stance(r, db, params, done) <= params.lone_ratio * r.best.score;
  const bool named = r.lookalike_decided ? r.best.score >= params.min_score
                                         : names_best(r.best.score, runner_up, params, lone);
  r.name = r.best.view >= 0 && named &&
                   explains_candidate(db.views[r.best.view], r.alignments[r.best.view], params)
               ? r.best.object
               : kUnknown;
  return r;
}

}  // namespace proxseg
