// Cross-validated choice among variants: chosen outside each fold, scored on it
// (cross_validation.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/eval/cross_validation.hpp>

#include <algorithm>
#include <cstddef>
#include <stdexcept>

namespace proxseg {

CrossValidation cross_validate(const std::vector<std::vector<double>>& scores,
                               const std::vector<std::string>& fold_of_scene) {
  const std::size_t n = scores.size();
  if (n == 0 || scores[0].empty()) throw InputError("cross_validate: no scenes or no variants");
  const std::size_t v = scores[0].size();
  for (const auto& row : scores)
    if (row.size() != v) throw std::invalid_argument("cross_validate: rows of different sizes");
  if (fold_of_scene.size() != n)
    throw std::invalid_argument("cross_validate: one fold per scene expected");
  CrossValidation cv;
  std::vector<int> fold(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto it = std::find(cv.folds.begin(), cv.folds.end(), fold_of_scene[i]);
    fold[i] = static_cast<int>(it - cv.folds.begin());
    if (it == cv.folds.end()) cv.folds.push_back(fold_of_scene[i]);
  }
  const std::size_t nf = cv.folds.size();
  if (nf < 2) throw InputError("cross_validate: fewer than two folds");
  // Sums per fold and variant and over all scenes, in scene order.
  std::vector<std::vector<double>> fold_sum(nf, std::vector<double>(v, 0.0));
  std::vector<double> total(v, 0.0);
  cv.fold_scenes.assign(nf, 0);
  for (std::size_t i = 0; i < n; ++i) {
    ++cv.fold_scenes[fold[i]];
    for (std::size_t k = 0; k < v; ++k) {
      fold_sum[fold[i]][k] += scores[i][k];
      total[k] += scores[i][k];
    }
  }
  // The best of a list of means; strict > leaves ties to the first variant.
  const auto best_of = [v](const std::vector<double>& means) {
    int best = 0;
    for (std::size_t k = 1; k < v; ++k)
      if (means[k] > means[best]) best = static_cast<int>(k);
    return best;
  };
  cv.variant_means.resize(v);
  for (std::size_t k = 0; k < v; ++k) cv.variant_means[k] = total[k] / static_cast<double>(n);
  cv.best_in_sample = best_of(cv.variant_means);
  cv.in_sample = cv.variant_means[cv.best_in_sample];
  cv.fold_means.assign(nf, std::vector<double>(v, 0.0));
  cv.chosen.resize(nf);
  cv.training.resize(nf);
  cv.held_out.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const double inside = cv.fold_scenes[f], outside = static_cast<double>(n) - inside;
    std::vector<double> training(v);
    for (std::size_t k = 0; k < v; ++k) {
      cv.fold_means[f][k] = fold_sum[f][k] / inside;
      // The training mean summed afresh over the other scenes, not total - fold (no rounding
      // difference between two variants with the same scores outside the fold).
      double sum = 0;
      for (std::size_t i = 0; i < n; ++i)
        if (fold[i] != static_cast<int>(f)) sum += scores[i][k];
      training[k] = sum / outside;
    }
    cv.chosen[f] = best_of(training);
    cv.training[f] = training[cv.chosen[f]];
    cv.held_out[f] = cv.fold_means[f][cv.chosen[f]];
  }
  cv.scene_variant.resize(n);
  cv.scene_score.resize(n);
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    cv.scene_variant[i] = cv.chosen[fold[i]];
    cv.scene_score[i] = scores[i][cv.scene_variant[i]];
    sum += cv.scene_score[i];
  }
  cv.overall = sum / static_cast<double>(n);
  return cv;
}

}  // namespace proxseg
