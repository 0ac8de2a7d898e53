// A peer's alignments named as proxseg::recognize() names (peer_naming.hpp).
#include "peer_naming.hpp"

#include <proxseg/recognition/recognition.hpp>
#include <proxseg/recognition/registration.hpp>

#include <utility>

namespace proxseg::peers {

PeerAnswer name_alignments(const Cloud& candidate, const std::vector<PeerAlignment>& aligned,
                           const Database& db, const RecognitionParams& params, int threads,
                           const std::string& excluded) {
  const int n = static_cast<int>(aligned.size());
  std::vector<char> used(n, 0);
  for (int v = 0; v < n; ++v) used[v] = aligned[v].found && db.views[v].object != excluded;
  std::vector<double> score(n, 0), rank(n, 0);
  std::vector<Alignment> scored(n);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int v = 0; v < n; ++v)
    if (used[v]) {  // no hypothesis, no pose to score
      scored[v] = score_pose(candidate, db.views[v].cloud(), aligned[v].pose, params.registration);
      score[v] = score_of(scored[v], params.score);
      rank[v] = rank_of(scored[v], params.score);
    }
  PeerAnswer p;
  int best = -1;
  for (int v = 0; v < n; ++v)
    if (used[v] && (best < 0 || rank[v] > rank[best])) best = v;
  if (best < 0) return p;
  int runner_up = -1;  // the best-scoring view of another object
  for (int v = 0; v < n; ++v)
    if (used[v] && db.views[v].object != db.views[best].object &&
        (runner_up < 0 || score[v] > score[runner_up]))
      runner_up = v;
  bool decided = false;  // the look-alike vote named the best
  if (runner_up >= 0) {
    const int winner = tell_lookalikes(candidate, db.views[best].cloud(), scored[best],
                                       db.views[runner_up].cloud(), scored[runner_up], params);
    if (winner == 2) std::swap(best, runner_up);
    decided = winner != 0;
  }
  p.best = db.views[best].object;
  p.score = score[best];
  p.pose = aligned[best].pose;
  if (runner_up >= 0) p.runner_up = score[runner_up];
  p.colour = scored[best].coloured ? scored[best].colour : -1;
  const bool lone = runner_up >= 0 && scored[best].coloured;
  const bool named =
      decided ? p.score >= params.min_score : names_best(p.score, p.runner_up, params, lone);
  if (named) p.name = p.best;
  return p;
}

}  // namespace proxseg::peers
