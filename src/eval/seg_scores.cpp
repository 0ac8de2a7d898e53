// Segmentation scores of a labelled scene: the mOSD truth in both schemes and a prediction's
// scores against it (seg_scores.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/seg_scores.hpp>

#include <string>

namespace proxseg {
namespace {

std::vector<std::uint32_t> evaluated(const Frame& frame, std::vector<std::uint32_t> truth) {
  if (frame.label.size() != frame.size())
    throw InputError("ground truth: frame has no label field (expected one label per point)");
  // mOSD files may hold NaN points under a non-zero label: only finite positions count.
  for (std::size_t i = 0; i < truth.size(); ++i)
    if (!frame.valid(i)) truth[i] = 0;
  return truth;
}

}  // namespace

std::vector<std::uint32_t> truth_objects(const Frame& frame) {
  return evaluated(frame, mosd_objects(frame.label));
}

std::vector<std::uint32_t> truth_parts(const Frame& frame) {
  return evaluated(frame, mosd_parts(frame.label));
}

SceneScores score_scene(const Frame& truth, const std::vector<std::uint32_t>& predicted) {
  if (predicted.size() != truth.size())
    throw InputError("prediction has " + std::to_string(predicted.size()) +
                     " points but the ground truth has " + std::to_string(truth.size()) +
                     " (expected the same cloud)");
  SceneScores s;
  s.objects = score_segmentation(truth_objects(truth), predicted, kMosdBackground);
  s.parts = score_segmentation(truth_parts(truth), predicted, kMosdBackground);
  return s;
}

}  // namespace proxseg
