// Recognition [paper 3.4, Algorithm 3].
#include <proxseg/recognition/recognition.hpp>

#include "util/first_error.hpp"
#include "util/splitmix.hpp"
#include "util/stopwatch.hpp"

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numeric>

namespace proxseg {
namespace {

// splitmix64's first draw from state x: one independent RANSAC stream per view from the one seed.
std::uint64_t mix(std::uint64_t x) {
  return SplitMix{x}.next();
}

constexpr int kBatch = 8;  // views per early-exit check; fixed, so answers do not depend on threads

}  // namespace

namespace {

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

// Floating-point slack of sketch_distance() as a bound (signature_distance() sums about 130
// float differences in float arithmetic, a sketch holds the spread as a float).
constexpr double kBoundSlack = 1e-4;

// The least sketch_distance() from the candidate to the view's parts, and the view's own
// distance: at most its view_distance().
double parts_bound(const Eigen::VectorXf& candidate, bool coloured, const ModelView& view,
                   double whole, Eigen::Index shape_bins) {
  double d = whole;
  for (Eigen::Index k = 0; k < view.part_sketches.size(); ++k)
    d = std::min(
        d, sketch_distance(candidate, view.part_sketches, k, shape_bins, coloured, view.coloured));
  return d;
}

using Ranked = std::vector<std::pair<double, int>>;  // (distance, view), nearest first

// The views of a shortlist of `shortlist` taken from `ranked` (sorted): the nearest ones, and
// further the nearest view of a second object when they all show one.
std::vector<int> take_shortlist(const Ranked& ranked, const Database& db, int shortlist) {
  std::vector<int> out;
  for (const auto& r : ranked) {
    if (shortlist > 0 && static_cast<int>(out.size()) >= shortlist) {
      // Keep going only for the nearest view of a second object.
      const std::string& first = db.views[out.front()].object;
      const bool one_object =
          std::all_of(out.begin(), out.end(), [&](int v) { return db.views[v].object == first; });
      if (!one_object) break;
      if (db.views[r.second].object == first) continue;
    }
    out.push_back(r.second);
  }
  return out;
}

// The largest distance a view can have and still enter the shortlist taken from the views
// measured so far (infinite while it could take any).
double entry_distance(Ranked measured, const Database& db, int shortlist) {
  if (static_cast<int>(measured.size()) < shortlist) return std::numeric_limits<double>::infinity();
  std::sort(measured.begin(), measured.end());
  const std::vector<int> taken = take_shortlist(measured, db, shortlist);
  if (static_cast<int>(taken.size()) <= shortlist &&
      std::all_of(taken.begin(), taken.end(),
                  [&](int v) { return db.views[v].object == db.views[taken[0]].object; }))
    return std::numeric_limits<double>::infinity();  // no second object yet
  double d = 0;
  for (const auto& m : measured)
    if (std::find(taken.begin(), taken.end(), m.second) != taken.end()) d = std::max(d, m.first);
  return d;
}

}  // namespace

std::vector<int> shortlist_views(const Cloud& candidate, const Database& db, int shortlist,
                                 const std::vector<std::string>& objects, bool parts,
                                 std::vector<std::string>* damaged) {
  Ranked bounds;  // (a lower bound of the view's distance, view)
  const Eigen::VectorXf sketch = sketch_of(candidate.signature);
  const bool coloured = candidate.signature.colour.size() > 0;
  const Eigen::Index shape_bins = candidate.signature.shape.size();
  std::vector<double> whole(db.views.size(), 0.0);
  for (int v = 0; v < static_cast<int>(db.views.size()); ++v) {
    const ModelView& view = db.views[v];
    if (!objects.empty() && std::find(objects.begin(), objects.end(), view.object) == objects.end())
      continue;
    if (shortlist > 0) whole[v] = signature_distance(candidate.signature, view.signature);
    bounds.emplace_back(
        shortlist > 0 && parts
            ? parts_bound(sketch, coloured, view, whole[v], shape_bins) - kBoundSlack
            : whole[v],
        v);
  }
  // Ties (and the whole order without a shortlist) go by view index.
  std::sort(bounds.begin(), bounds.end());
  if (shortlist <= 0 || !parts) return take_shortlist(bounds, db, shortlist);
  // A view's parts are read (stored databases) and compared only while its bound says it could
  // still enter: exactly the shortlist of every view's view_distance().
  Ranked measured;
  double entry = std::numeric_limits<double>::infinity();
  for (const auto& [bound, v] : bounds) {
    if (bound > entry) break;
    double d = whole[v];
    try {
      for (const Signature& part : db.views[v].part_signatures())
        d = std::min(d, signature_distance(candidate.signature, part));
    } catch (const InputError& e) {
      if (damaged) damaged->push_back(e.what());
      continue;
    }
    measured.emplace_back(d, v);
    if (measured.size() % 16 == 0 || static_cast<int>(measured.size()) == shortlist)
      entry = entry_distance(measured, db, shortlist);
  }
  std::sort(measured.begin(), measured.end());
  return take_shortlist(measured, db, shortlist);
}

Recognition recognize(const Cloud& candidate, const Database& db, const RecognitionParams& params,
                      const std::vector<std::string>& objects, const DepthImage* scene) {
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
  const int m = static_cast<int>(views.size());
  for (int begin = 0; begin < m; begin += kBatch) {
    const int end = std::min(m, begin + kBatch);
    detail::FirstError failure;  // out of memory in one alignment: the candidate fails
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int k = begin; k < end; ++k) {
      if (failure.failed()) continue;
      const int v = views[k];
      const Cloud* view = nullptr;
      try {  // a stored view is read here, the first time it is shortlisted
        view = &db.views[v].cloud();
      } catch (const InputError& e) {
        unreadable[k] = e.what();
        continue;
      } catch (...) {
        failure.capture();
        continue;
      }
      try {
        r.alignments[v] = align(candidate, sample, *view, params.registration,
                                mix(params.seed ^ mix(static_cast<std::uint64_t>(v))));
        if (scene && params.free_space_tolerance > 0) {
          Alignment& a = r.alignments[v];
          a.free_space = free_space_violation(*scene, *view, a.pose, params.free_space_tolerance);
          a.border_unexplained = border_unexplained(*scene, candidate, *view, a.pose,
                                                    params.registration.fitness_distance);
        }
      } catch (...) {
        failure.capture();
        continue;
      }
      done[v] = 1;
    }
    failure.rethrow();
    r.views_aligned = end;
    if (params.early_exit > 0) {
      bool good = false;
      for (int k = begin; k < end; ++k)
        good |= rank_of(r.alignments[views[k]], params.score) >= params.early_exit;
      if (good) break;
    }
    if (params.early_reject > 0 && end < m) {
      double best = 0;
      for (int k = 0; k < end; ++k)
        best = std::max(best, rank_of(r.alignments[views[k]], params.score));
      if (best < params.early_reject) break;
    }
  }
  r.align_ms = align_watch.ms();
  for (const std::string& e : unreadable)
    if (!e.empty()) r.damaged.push_back(e);
  // Algorithm 3: the best view names the candidate; ties go to the earlier view. Views are
  // ranked allowing for an occlusion (rank_of()); the answer is judged on the score, which does
  // not: an occlusion may explain why a model's surface is missing, which is reason to prefer the
  // model that explains what was seen, but it is no evidence for the object. When the two
  // disagree on the object, the runner-up scores more than the best and the answer is doubtful.
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
  for (int v = 0; v < n; ++v) {
    if (!done[v]) continue;
    const Match m = to_match(v);
    if (r.best.view < 0 || m.rank > r.best.rank) r.best = m;
  }
  for (int v = 0; v < n; ++v) {
    if (!done[v] || db.views[v].object == r.best.object) continue;
    const Match m = to_match(v);
    if (r.runner_up.view < 0 || m.score > r.runner_up.score) r.runner_up = m;
  }
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
                    r.alignments[r.best.view].coloured;
  const bool named = r.lookalike_decided ? r.best.score >= params.min_score
                                         : names_best(r.best.score, runner_up, params, lone);
  r.name = r.best.view >= 0 && named ? r.best.object : "unknown";
  return r;
}

namespace {

// The mean of the frame points' positions (zero for none).
Eigen::Vector3d centroid_of(const Frame& frame, const std::vector<int>& points) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int i : points) c += frame.xyz[i].cast<double>();
  return c / std::max<double>(1.0, points.size());
}

SceneObject scene_object(std::vector<int> points, std::vector<std::uint32_t> instances,
                         SceneObject::Origin origin) {
  SceneObject o;
  o.points = std::move(points);
  o.instances = std::move(instances);
  o.origin = origin;
  return o;
}

// An object of the scene with its described cloud (5 mm voxels, sensor frame) and their box.
struct Piece {
  SceneObject object;
  Cloud cloud;
  Eigen::AlignedBox3d box;
};

std::vector<Eigen::Vector3d> xyz_of(const Frame& frame, const std::vector<int>& points) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (int p : points) out.push_back(frame.xyz[p].cast<double>());
  return out;
}

std::vector<Rgb> rgb_of(const Frame& frame, const std::vector<int>& points) {
  std::vector<Rgb> out;
  if (frame.rgb.size() != frame.size()) return out;
  out.reserve(points.size());
  for (int p : points) out.push_back(frame.rgb[p]);
  return out;
}

// Whether two pieces come within distance of each other (on their described clouds: only
// points within distance of the other's box are compared).
bool near(const Piece& a, const Piece& b, double distance) {
  const Eigen::Vector3d d = Eigen::Vector3d::Constant(distance);
  const Eigen::AlignedBox3d ga(a.box.min() - d, a.box.max() + d);
  if (!ga.intersects(b.box)) return false;
  const Eigen::AlignedBox3d gb(b.box.min() - d, b.box.max() + d);
  std::vector<const Eigen::Vector3d*> pa, pb;
  for (const auto& p : a.cloud.points)
    if (gb.contains(p)) pa.push_back(&p);
  for (const auto& p : b.cloud.points)
    if (ga.contains(p)) pb.push_back(&p);
  for (const auto* p : pa)
    for (const auto* q : pb)
      if ((*p - *q).squaredNorm() <= distance * distance) return true;
  return false;
}

// Two described pieces as one cloud without describing the union again: points, normals,
// features and colours side by side. Near the seam each part's FPFH misses the other part's
// points; a merge trial's registration hardly notices, and its score depends on the points only.
Cloud joined(const Cloud& a, const Cloud& b) {
  std::vector<Eigen::Vector3d> points = a.points, normals = a.normals;
  points.insert(points.end(), b.points.begin(), b.points.end());
  normals.insert(normals.end(), b.normals.begin(), b.normals.end());
  Eigen::MatrixXd features(a.features.rows(), a.features.cols() + b.features.cols());
  features << a.features, b.features;
  std::vector<Rgb> colours;
  if (!a.colours.empty() && !b.colours.empty()) {
    colours = a.colours;
    colours.insert(colours.end(), b.colours.begin(), b.colours.end());
  }
  return restore(std::move(points), std::move(normals), std::move(features), a.viewpoint,
                 std::move(colours));
}

bool named(const Piece& p) {
  return p.object.recognition.name != "unknown";
}
double score(const Piece& p) {
  return p.object.recognition.best.score;
}

// Recognises one piece of the scene: describes its points (or takes the caller's cloud: a
// merge trial's joined parts) and aligns it to the database views, of `objects` only when
// given (then the trial shortlist). Pieces too small for a description (under 10 voxels) stay
// unrecognised: false, and `out` is not made.
struct PieceRecogniser {
  const Frame& frame;
  const Database& db;
  const RecognitionParams& params;
  const std::function<void(const SceneObject&)>& progress;
  const DepthImage* scene;  // the frame's depths for the free-space check, or null

  bool operator()(SceneObject o, Piece& out, const std::vector<std::string>& objects = {},
                  Cloud* described = nullptr) const {
    const detail::Stopwatch describe_watch;
    try {
      const std::vector<Rgb> rgb = rgb_of(frame, o.points);
      out.cloud =
          described ? std::move(*described)
                    : describe_candidate(xyz_of(frame, o.points), db, rgb.empty() ? nullptr : &rgb);
    } catch (const InputError&) {
      return false;
    }
    const double describe_ms = describe_watch.ms();
    RecognitionParams p = params;
    if (!objects.empty()) p.shortlist = params.trial_shortlist;
    o.recognition = recognize(out.cloud, db, p, objects, scene);
    o.recognition.describe_ms = describe_ms;
    out.object = std::move(o);
    out.box.setEmpty();
    for (const auto& q : out.cloud.points) out.box.extend(q);
    if (progress) {
#pragma omp critical(proxseg_recognise_progress)
      progress(out.object);
    }
    return true;
  }
};

// The selection's candidates, each recognised on its own, in the selection's order. They are
// independent: one per thread (each one's views then run on that thread), which keeps both
// cores busy better than the views of one candidate in batches; largest first, so that the last
// one to finish is a small one and no core waits long.
std::vector<Piece> recognise_candidates(const Selection& selection,
                                        const PieceRecogniser& recognise) {
  std::vector<const Candidate*> candidates;
  for (const Candidate& c : selection.components)
    if (!c.background) candidates.push_back(&c);
  std::vector<int> by_size(candidates.size());
  std::iota(by_size.begin(), by_size.end(), 0);
  std::stable_sort(by_size.begin(), by_size.end(), [&](int a, int b) {
    return candidates[a]->points.size() > candidates[b]->points.size();
  });
  std::vector<Piece> first(candidates.size());
  std::vector<char> made(candidates.size(), 0);
  const int threads =
      recognise.params.threads > 0 ? recognise.params.threads : omp_get_max_threads();
  detail::FirstError failure;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int i = 0; i < static_cast<int>(by_size.size()); ++i) {
    if (failure.failed()) continue;
    const int k = by_size[i];
    const Candidate& c = *candidates[k];
    try {
      made[k] = recognise(scene_object(c.points, {c.instance}, SceneObject::Origin::kCandidate),
                          first[k]);
    } catch (...) {
      failure.capture();
    }
  }
  failure.rethrow();
  std::vector<Piece> pieces;
  for (std::size_t k = 0; k < first.size(); ++k)
    if (made[k]) pieces.push_back(std::move(first[k]));
  return pieces;
}

// Split: the model that names a piece with a poor fitness keeps the points it explains; the
// rest is recognised on its own (and may be split again). Both parts must be named, so an
// object is not cut into itself and its fringe of noise. The explained part is tried against
// its model's object only: that is what it is being checked for.
std::vector<Piece> split_pieces(std::vector<Piece> pieces, const PieceRecogniser& recognise) {
  const RecognitionParams& params = recognise.params;
  const std::size_t min_part = static_cast<std::size_t>(params.min_part_points);
  std::deque<Piece> queue(std::make_move_iterator(pieces.begin()),
                          std::make_move_iterator(pieces.end()));
  std::vector<Piece> out;
  while (!queue.empty()) {
    Piece w = std::move(queue.front());
    queue.pop_front();
    const Recognition& r = w.object.recognition;
    bool split = false;
    // A piece whose best view reaches the minimum score but not the margin is tried too: two
    // touching objects, one of which explains the piece about as well as another model does.
    const bool fits = named(w) || (r.best.view >= 0 && r.best.score >= params.min_score);
    if (fits && r.best.fitness < params.split_fitness && w.object.points.size() >= 2 * min_part) {
      const std::vector<char> in = explained(xyz_of(recognise.frame, w.object.points),
                                             recognise.db.views[r.best.view].cloud(), r.best.pose,
                                             params.registration.fitness_distance);
      SceneObject e = scene_object({}, w.object.instances, SceneObject::Origin::kSplit), rest = e;
      for (std::size_t i = 0; i < in.size(); ++i)
        (in[i] ? e : rest).points.push_back(w.object.points[i]);
      Piece pe, pr;
      if (e.points.size() >= min_part && rest.points.size() >= min_part &&
          recognise(std::move(e), pe, {r.best.object}) && named(pe) &&
          recognise(std::move(rest), pr) && named(pr)) {
        out.push_back(std::move(pe));
        queue.push_back(std::move(pr));
        split = true;
      }
    }
    if (!split) out.push_back(std::move(w));
  }
  return out;
}

// The union of two pieces as one scene object (points in frame order, instances of both).
SceneObject united(const Piece& a, const Piece& b) {
  SceneObject u = scene_object({}, a.object.instances, SceneObject::Origin::kMerged);
  std::merge(a.object.points.begin(), a.object.points.end(), b.object.points.begin(),
             b.object.points.end(), std::back_inserter(u.points));
  u.instances.insert(u.instances.end(), b.object.instances.begin(), b.object.instances.end());
  std::sort(u.instances.begin(), u.instances.end());
  u.instances.erase(std::unique(u.instances.begin(), u.instances.end()), u.instances.end());
  return u;
}

// Whether two pieces' best views show one object (named or not): the two halves of an object
// that the selection cut in two, each too little of it to be named.
bool leans_to_one_object(const Piece& a, const Piece& b) {
  const Match &x = a.object.recognition.best, &y = b.object.recognition.best;
  return x.view >= 0 && y.view >= 0 && x.object == y.object;
}

// Merge: the best-scoring union of two near pieces that beats both parts, until none does.
// A union is tried against the objects its parts are named after (two unnamed parts, with
// merge_unnamed: the one object both lean to): it can only beat a part as one of them. Unions are
// recognised once: a piece is known by its first point and its size (pieces are disjoint, and a
// merged piece is larger than both of its parts).
std::vector<Piece> merge_pieces(std::vector<Piece> pieces, const PieceRecogniser& recognise) {
  using Key = std::array<std::size_t, 4>;
  const auto key_of = [](const Piece& a, const Piece& b) {
    Key k{std::size_t(a.object.points[0]), a.object.points.size(), std::size_t(b.object.points[0]),
          b.object.points.size()};
    if (k[2] < k[0]) std::swap(k[0], k[2]), std::swap(k[1], k[3]);
    return k;
  };
  std::map<Key, Piece> tried;
  for (;;) {
    int best_i = -1, best_j = -1;
    double best = -1;
    for (std::size_t i = 0; i < pieces.size(); ++i)
      for (std::size_t j = i + 1; j < pieces.size(); ++j) {
        const Piece &a = pieces[i], &b = pieces[j];
        const bool same_lean = recognise.params.merge_unnamed && leans_to_one_object(a, b);
        if ((!named(a) && !named(b) && !same_lean) || !near(a, b, recognise.params.merge_distance))
          continue;
        const Key key = key_of(a, b);
        auto it = tried.find(key);
        if (it == tried.end()) {
          std::vector<std::string> objects;
          for (const Piece* part : {&a, &b})
            if (named(*part) || same_lean) objects.push_back(part->object.recognition.best.object);
          Cloud both = joined(a.cloud, b.cloud);
          Piece p;
          if (!recognise(united(a, b), p, objects, &both)) continue;
          it = tried.emplace(key, std::move(p)).first;
        }
        const Piece& u = it->second;
        if (named(u) && score(u) > std::max(score(a), score(b)) && score(u) > best)
          best = score(u), best_i = static_cast<int>(i), best_j = static_cast<int>(j);
      }
    if (best_i < 0) break;
    pieces[best_i] = std::move(tried.at(key_of(pieces[best_i], pieces[best_j])));
    pieces.erase(pieces.begin() + best_j);
  }
  return pieces;
}

}  // namespace

std::vector<SceneObject> recognize_scene(const Frame& frame, const Selection& selection,
                                         const Database& db, const RecognitionParams& params,
                                         const std::function<void(const SceneObject&)>& progress) {
  const DepthImage depths = params.free_space_tolerance > 0 ? depth_image(frame) : DepthImage{};
  const PieceRecogniser recognise{frame, db, params, progress, depths.empty() ? nullptr : &depths};
  std::vector<Piece> pieces = recognise_candidates(selection, recognise);
  if (params.split_fitness > 0) pieces = split_pieces(std::move(pieces), recognise);
  if (params.merge_distance > 0) pieces = merge_pieces(std::move(pieces), recognise);
  // In frame order (of their first points), whatever order the passes left them in.
  std::sort(pieces.begin(), pieces.end(),
            [](const Piece& a, const Piece& b) { return a.object.points[0] < b.object.points[0]; });
  std::vector<SceneObject> out;
  for (auto& p : pieces) {
    SceneObject& o = out.emplace_back(std::move(p.object));
    o.id = static_cast<int>(out.size());
    o.centroid = centroid_of(frame, o.points);
  }
  return out;
}

SceneObject recognize_object(const Frame& cloud, const Database& db,
                             const RecognitionParams& params) {
  SceneObject o;
  std::vector<Eigen::Vector3d> points;
  std::vector<Rgb> colours;
  const bool coloured = cloud.rgb.size() == cloud.size();
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (cloud.valid(i)) {
      o.points.push_back(static_cast<int>(i));
      points.push_back(cloud.xyz[i].cast<double>());
      if (coloured) colours.push_back(cloud.rgb[i]);
    }
  o.centroid = centroid_of(cloud, o.points);
  const detail::Stopwatch describing;
  const Cloud described = describe_candidate(points, db, coloured ? &colours : nullptr);
  const double describe_ms = describing.ms();
  o.recognition = recognize(described, db, params);
  o.recognition.describe_ms = describe_ms;
  return o;
}

}  // namespace proxseg
