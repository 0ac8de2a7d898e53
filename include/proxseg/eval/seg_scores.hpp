// Segmentation scores of a labelled scene [paper 4]: the mOSD truth under the "objects" and
// "parts" schemes and the scores of a predicted labelling against both. The metrics themselves
// are in metrics.hpp, their definitions in docs/metrics.md; summaries over scenes in
// seg_summary.hpp.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/eval/metrics.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace proxseg {

// The evaluated truth of a labelled frame: 0 where the position is not finite or the label is 0,
// else the mOSD object (table -> 1, label / 10 for objects) or part (table -> 1, label).
std::vector<std::uint32_t> truth_objects(const Frame& frame);
std::vector<std::uint32_t> truth_parts(const Frame& frame);
// The truth id of the supporting background in both schemes.
inline const std::vector<std::uint32_t> kMosdBackground = {1};

struct SceneScores {
  std::string scene;     // file name without directory
  std::string category;  // see scene_category (scene_names.hpp)
  std::string method;    // e.g. "proxseg default", "lccp"
  double seconds = 0;    // wall time of the method on this scene (0 if not timed)
  SegmentationScores objects, parts;
};

// Scores a predicted per-point labelling against the frame's truth (sizes must match).
SceneScores score_scene(const Frame& truth, const std::vector<std::uint32_t>& predicted);

}  // namespace proxseg
