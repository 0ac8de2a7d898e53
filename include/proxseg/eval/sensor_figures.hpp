// A depth sensor's figures measured on real frames with ground truth (docs/method.md "Real
// sensors"): axial noise on planar patches against range, the distance of an object's points to
// its model put at the true pose against range, and missing returns at object borders and
// inside objects. What the generated scenes' sensor model should reproduce.
#pragma once
#include <proxseg/eval/real_eval.hpp>

#include <vector>

namespace proxseg {

struct SensorFigures {
  // Planar patches (14 x 14 pixels, planar and facing the sensor within 45 degrees) by range, in
  // 0.1 m bins from 0: patches, median axial RMS (metres).
  std::vector<int> patches;
  std::vector<double> patch_rms;
  // Per labelled object: its median range and the 50th / 90th percentiles of its points'
  // distances to the model at the true pose (metres).
  struct ObjectResidual {
    std::string object;
    double range = 0, p50 = 0, p90 = 0;
  };
  std::vector<ObjectResidual> residuals;
  // Missing returns: labelled pixels within 3 pixels of another label (borders) and the others
  // (inside), and how many of each have no depth.
  long border = 0, border_missing = 0, inside = 0, inside_missing = 0;
  SensorFigures& operator+=(const SensorFigures& o);
};

// Measures one frame.
SensorFigures measure_sensor(const YcbFrame& frame, const YcbModels& models);

}  // namespace proxseg
