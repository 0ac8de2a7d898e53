// Cross-validated choice among variants (bench/seg_cv.cpp): each fold's variant is chosen on the
// scenes outside the fold, so no scene's score comes from a choice that saw it.
#pragma once
#include <proxseg/core/errors.hpp>

#include <string>
#include <vector>

namespace proxseg {

// scores[scene][variant]: a score to maximise (e.g. object F) of every variant on every scene;
// fold_of_scene[scene]: the fold the scene belongs to (scene_fold, scene_names.hpp). For each
// fold the variant with the best mean score over the scenes OUTSIDE the fold is chosen (ties ->
// the first variant) and scored on the fold's scenes. Throws InputError if there are no scenes
// or fewer than two folds, std::invalid_argument if the matrix is not rectangular or the sizes
// differ.
struct CrossValidation {
  std::vector<std::string> folds;               // in first-seen order of fold_of_scene
  std::vector<int> fold_scenes;                 // per fold: its number of scenes
  std::vector<std::vector<double>> fold_means;  // [fold][variant]: mean score on the fold
  std::vector<double> variant_means;            // per variant: mean over all scenes
  std::vector<int> chosen;                      // per fold: the variant chosen without the fold
  std::vector<double> training;                 // per fold: that variant's mean outside the fold
  std::vector<double> held_out;                 // per fold: that variant's mean on the fold
  std::vector<int> scene_variant;               // per scene: the variant chosen for its fold
  std::vector<double> scene_score;              // per scene: that variant's score on it
  double overall = 0;                           // mean of scene_score: the cross-validated score
  int best_in_sample = 0;                       // the variant with the best mean over all scenes
  double in_sample = 0;                         // its mean (optimistic: chosen on the same scenes)
};
CrossValidation cross_validate(const std::vector<std::vector<double>>& scores,
                               const std::vector<std::string>& fold_of_scene);

}  // namespace proxseg
