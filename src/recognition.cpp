// Recognition [paper 3.4, Algorithm 3].
#include <proxseg/recognition.hpp>

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace proxseg {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// splitmix64: one independent RANSAC stream per view from the one seed.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

constexpr int kBatch = 8;  // views per early-exit check; fixed, so answers do not depend on threads

}  // namespace

double score_of(const Alignment& a, Score score) {
  return score == Score::kFitness ? a.fitness : std::sqrt(a.close_fitness * a.coverage);
}

Cloud describe_candidate(const std::vector<Eigen::Vector3d>& points, const Database& db) {
  return describe(points, Eigen::Vector3d::Zero(), db.descriptor);
}

Recognition recognize(const Cloud& candidate, const Database& db, const RecognitionParams& params) {
  Recognition r;
  const int n = static_cast<int>(db.views.size());
  r.alignments.assign(n, Alignment{});
  std::vector<char> done(n, 0);
  const int threads = params.threads > 0 ? params.threads : omp_get_max_threads();
  const auto t0 = Clock::now();
  const Cloud sample = subsample(candidate, params.registration.max_points);
  for (int begin = 0; begin < n; begin += kBatch) {
    const int end = std::min(n, begin + kBatch);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int v = begin; v < end; ++v) {
      r.alignments[v] = align(candidate, sample, db.views[v].cloud, params.registration,
                              mix(params.seed ^ mix(static_cast<std::uint64_t>(v))));
      done[v] = 1;
    }
    r.views_aligned = end;
    if (params.early_exit > 0) {
      bool good = false;
      for (int v = begin; v < end; ++v)
        good |= score_of(r.alignments[v], params.score) >= params.early_exit;
      if (good) break;
    }
  }
  r.align_ms = ms_since(t0);
  // Algorithm 3: the best view names the candidate; ties go to the earlier view.
  const auto to_match = [&](int v) {
    const Alignment& a = r.alignments[v];
    return Match{db.views[v].object,        v,     a.pose, a.fitness, a.coverage,
                 score_of(a, params.score), a.rmse};
  };
  for (int v = 0; v < n; ++v) {
    if (!done[v]) continue;
    const Match m = to_match(v);
    if (r.best.view < 0 || m.score > r.best.score) r.best = m;
  }
  for (int v = 0; v < n; ++v) {
    if (!done[v] || db.views[v].object == r.best.object) continue;
    const Match m = to_match(v);
    if (r.runner_up.view < 0 || m.score > r.runner_up.score) r.runner_up = m;
  }
  r.name = r.best.view >= 0 && r.best.score >= params.min_score ? r.best.object : "unknown";
  return r;
}

}  // namespace proxseg
