// Recognition [paper 3.4, Algorithm 3]: align a candidate to every model view of the database
// and name it after the view with the best score, or "unknown" under a threshold.
#pragma once
#include <proxseg/database.hpp>
#include <proxseg/registration.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace proxseg {

enum class Score {
  kFitness,    // the paper's eq. 5: candidate points explained by the model (one-sided)
  kSymmetric,  // sqrt(close_fitness x coverage), both within score_distance: also the share of
               // the visible model the candidate explains, so that a small box on the face of a
               // big one does not score 1
};

struct RecognitionParams {
  RegistrationParams registration;
  Score score = Score::kSymmetric;
  double min_score = 0.5;  // best score below it: "unknown"
  // > 0: stop after the first batch of views (8 at a time, in database order) in which some
  // view reached this score. Faster; may change the answer (a later view could score higher).
  double early_exit = 0;
  std::uint64_t seed = 1;
  int threads = 0;  // 0 = all cores; the answer does not depend on it
};

struct Match {
  std::string object;                                  // empty when there is none
  int view = -1;                                       // index into Database::views
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  // candidate frame <- model frame
  double fitness = 0, coverage = 0, score = 0, rmse = 0;
};

struct Recognition {
  std::string name;  // best.object, or "unknown" when best.score < min_score
  Match best;
  Match runner_up;                    // the best view of any other object
  std::vector<Alignment> alignments;  // per database view (empty slots if skipped early)
  int views_aligned = 0;
  double align_ms = 0;     // wall time over all views
  double describe_ms = 0;  // left to the caller, which describes the candidate (the CLI does)
};

double score_of(const Alignment& a, Score score);

// Describes the candidate's points (sensor frame; sensor at the origin) like the database views.
Cloud describe_candidate(const std::vector<Eigen::Vector3d>& points, const Database& db);
// Algorithm 3 for one described candidate.
Recognition recognize(const Cloud& candidate, const Database& db, const RecognitionParams& params);

}  // namespace proxseg
