// Segmentation outputs: PREFIX.pcd, PREFIX.png, PREFIX.json (all written atomically).
#pragma once
#include <proxseg/pipeline.hpp>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg {

// The report written to PREFIX.json: parameters, stage times, counts, energies, label sizes.
nlohmann::json segmentation_report(const Frame& frame, const SegmentParams& params,
                                   const SegmentResult& result);
// A picture of the labels: the colour image with labels blended in and boundaries drawn
// (organized input), or the points rendered from the sensor origin (unorganized input). PNG bytes.
std::string label_image_png(const Frame& frame, const std::vector<std::uint32_t>& point_labels);
// Writes PREFIX.pcd, PREFIX.png and PREFIX.json; each appears whole or not at all. Returns the
// report written to PREFIX.json.
nlohmann::json write_segmentation(const std::string& prefix, const Frame& frame,
                                  const SegmentParams& params, const SegmentResult& result);

// Writes one unorganized PCD (x y z rgb) per candidate object (not the background) to
// DIR/candidate_<id>.pcd, creating DIR; all files or none. Returns the paths written.
std::vector<std::string> write_candidates(const std::string& dir, const Frame& frame,
                                          const SegmentResult& result);

}  // namespace proxseg
