// Segmentation metrics [paper 4].
#pragma once
#include <cstdint>
#include <vector>

namespace proxseg {

// V-measure (Rosenberg and Hirschberg 2007) of a predicted labelling against ground truth,
// over the points whose truth is non-zero. Entropies in nats; 1 = perfect.
struct VMeasure {
  double homogeneity = 0, completeness = 0, v = 0;
};
VMeasure v_measure(const std::vector<std::uint32_t>& truth,
                   const std::vector<std::uint32_t>& predicted);

// mOSD labels to objects: 0 stays 0 (invalid), 1-9 (table parts) -> 1, 20-29 -> 2, 30-39 -> 3, ...
std::vector<std::uint32_t> mosd_objects(const std::vector<std::uint32_t>& labels);

}  // namespace proxseg
