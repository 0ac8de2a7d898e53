// A recognition peer's alignments named exactly as proxseg::recognize() names its own: each pose
// scored with proxseg's score (the candidate's colours too), ranked allowing for an occlusion and
// judged on the score, ties to the earlier view, the look-alike vote and names_best() with the
// same parameters. The benchmarks that run peers on scenes (scene_bench, real_bench) share it,
// so that the comparison is about registration alone.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/recognition_types.hpp>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "peers_rec.hpp"

namespace proxseg::peers {

struct PeerAnswer {
  std::string name = "unknown";  // best, or "unknown" when the rule does not name it
  std::string best;              // the best view's object ("" when no view was aligned)
  double score = 0, runner_up = 0;
  double colour = -1;  // the best alignment's colour agreement; -1 when colour was not compared
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  // candidate frame <- model frame
};

// `aligned` holds one alignment per database view (a peer's align()). Views of `excluded` (an
// object name; "" = none) are left out, as if the database did not hold them (leave-one-out).
// Scoring runs over `threads` OpenMP threads.
PeerAnswer name_alignments(const Cloud& candidate, const std::vector<PeerAlignment>& aligned,
                           const Database& db, const RecognitionParams& params, int threads,
                           const std::string& excluded = "");

}  // namespace proxseg::peers
