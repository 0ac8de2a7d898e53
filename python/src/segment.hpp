// What segment.cpp shares with recognition.cpp (proxseg.recognize segments first).
#pragma once
#include <proxseg/core/pipeline.hpp>

#include "bindings.hpp"

namespace proxseg::python {

// Parameters from a complete dict in the JSON config's layout, checked (ValueError naming the
// field).
SegmentParams segment_params(const py::handle& params);

// The result as proxseg.segment's Python layer takes it: "report" (the CLI's JSON report as a
// dict), "labels", "labels_kmeans", "instances" (numpy uint32 in the frame's shape) and
// "candidate_points" (per instance, numpy int32 point indices). Moves the arrays out of r.
py::dict segmentation_dict(const Frame& frame, const SegmentParams& params, SegmentResult&& r);

}  // namespace proxseg::python
