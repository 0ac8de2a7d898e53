// Shared by the two selection geometries (voxels and image grid): what makes a component
// background.
#pragma once
#include <proxseg/core/selection.hpp>

namespace proxseg {

// A component is background (table, floor, wall) when its two largest box extents span at least
// background_min_area and background_inlier_ratio of its points lie within
// background_plane_distance of its best plane. Needs c.box and c.centroid.
bool is_background(const Frame& frame, const Candidate& c, const SelectionParams& params);

// c.box (oriented_box) and c.centroid (the mean of c.points) from one pass of moments.
void describe_shape(const Frame& frame, Candidate& c);

}  // namespace proxseg
