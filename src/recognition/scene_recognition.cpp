// Recognition of a scene [paper 3.4, Algorithm 3]: every candidate of a selection recognised on
// its own, then the split and merge passes that correct the selection with the models (pieces
// a model explains only partly are split, near pieces that one model explains better together
// are merged); and one object given as a cloud of its own.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/stop.hpp>
#include <proxseg/recognition/recognition.hpp>

#include "util/first_error.hpp"
#include "util/stopwatch.hpp"

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <deque>
#include <map>
#include <numeric>

namespace proxseg {
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
  return p.object.recognition.name != kUnknown;
}
double score(const Piece& p) {
  return p.object.recognition.best.score;
}

// Recognises one piece of the scene: describes its points (or takes the caller's cloud: a
// merge trial's joined parts) and aligns it to the database views, of `objects` only when
// given (then the trial shortlist). Pieces too small for a description (under 10 voxels) stay
// unrecognised: false, and `out` is not made.
struct PieceRecognizer {
  const Frame& frame;
  const Database& db;
  const RecognitionParams& params;
  const std::function<void(const SceneObject&)>& progress;
  const DepthImage* depths;     // the frame's depths for the free-space check, or null
  const SupportScene* support;  // the surfaces the objects stand on, or null

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
    std::vector<float> surfaces;
    if (support) surfaces = surfaces_around(*support, o.points);
    o.recognition =
        recognize(out.cloud, db, p, objects, {depths, support, support ? &surfaces : nullptr});
    o.recognition.describe_ms = describe_ms;
    out.object = std::move(o);
    out.box.setEmpty();
    for (const auto& q : out.cloud.points) out.box.extend(q);
    if (progress) {
#pragma omp critical(proxseg_recognize_progress)
      progress(out.object);
    }
    return true;
  }
};

// The selection's candidates, each recognised on its own, in the selection's order. They are
// independent: one task each, largest first, which keeps the cores busier than the views of one
// candidate in batches; the views of a candidate are tasks too (BatchAligner), so that a thread
// done with the candidates takes over views of the last ones instead of waiting.
std::vector<Piece> recognize_candidates(const Selection& selection,
                                        const PieceRecognizer& recognize_piece) {
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
      recognize_piece.params.threads > 0 ? recognize_piece.params.threads : omp_get_max_threads();
  detail::FirstError failure;
  StopToken* const stop = current_stop_token();  // the team's threads check the caller's
#pragma omp parallel num_threads(threads)
  {
    const StopScope inherit(stop, false);
#pragma omp single
    for (const int k : by_size) {
#pragma omp task firstprivate(k)
      {
        const Candidate& c = *candidates[k];
        try {
          stop_point();
          if (!failure.failed())
            made[k] = recognize_piece(
                scene_object(c.points, {c.instance}, SceneObject::Origin::kCandidate), first[k]);
        } catch (...) {
          failure.capture();
        }
      }
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
std::vector<Piece> split_pieces(std::vector<Piece> pieces, const PieceRecognizer& recognize_piece) {
  const RecognitionParams& params = recognize_piece.params;
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
      const std::vector<char> in = explained(xyz_of(recognize_piece.frame, w.object.points),
                                             recognize_piece.db.views[r.best.view].cloud(),
                                             r.best.pose, params.registration.fitness_distance);
      SceneObject e = scene_object({}, w.object.instances, SceneObject::Origin::kSplit), rest = e;
      for (std::size_t i = 0; i < in.size(); ++i)
        (in[i] ? e : rest).points.push_back(w.object.points[i]);
      Piece pe, pr;
      if (e.points.size() >= min_part && rest.points.size() >= min_part &&
          recognize_piece(std::move(e), pe, {r.best.object}) && named(pe) &&
          recognize_piece(std::move(rest), pr) && named(pr)) {
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
std::vector<Piece> merge_pieces(std::vector<Piece> pieces, const PieceRecognizer& recognize_piece) {
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
        const bool same_lean = recognize_piece.params.merge_unnamed && leans_to_one_object(a, b);
        if ((!named(a) && !named(b) && !same_lean) ||
            !near(a, b, recognize_piece.params.merge_distance))
          continue;
        const Key key = key_of(a, b);
        auto it = tried.find(key);
        if (it == tried.end()) {
          std::vector<std::string> objects;
          for (const Piece* part : {&a, &b})
            if (named(*part) || same_lean) objects.push_back(part->object.recognition.best.object);
          Cloud both = joined(a.cloud, b.cloud);
          Piece p;
          if (!recognize_piece(united(a, b), p, objects, &both)) continue;
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
  const SupportScene support =
      params.support_gap > 0 ? support_scene(frame, selection, support_plane(frame, selection))
                             : SupportScene{};
  const PieceRecognizer recognize_piece{frame,
                                        db,
                                        params,
                                        progress,
                                        depths.empty() ? nullptr : &depths,
                                        support.empty() ? nullptr : &support};
  std::vector<Piece> pieces = recognize_candidates(selection, recognize_piece);
  if (params.split_fitness > 0) pieces = split_pieces(std::move(pieces), recognize_piece);
  if (params.merge_distance > 0) pieces = merge_pieces(std::move(pieces), recognize_piece);
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
