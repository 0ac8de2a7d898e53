// Pieces of one surface that an object in front of it cut apart [extension of 3.3; docs/method.md,
// "Selection on the image grid", rule 7b].
#pragma once
#include <proxseg/core/selection.hpp>

#include "image_grid.hpp"

#include <Eigen/Core>
#include <vector>

namespace proxseg::detail {

// comp: per pixel a component id 0..count-1, kPlane or kNone. Two components join (comp takes
// the smaller id of each joined set) when at least occlusion_min_rays image rays (rows, columns,
// diagonals) run from one to the other across pixels that all lie in front of both ends (an
// occluder; missing pixels are passed too), most such rays end on one continuous surface (the
// normals at both ends within occlusion_normal_tolerance_deg, each end within
// occlusion_surface_tolerance plus 5 % of the gap of the other's tangent plane), and, on a
// coloured frame, the two components' hue-saturation histograms [3.1's colour feature] intersect
// by at least occlusion_min_colour.
void join_occluded_pieces(const ImageGrid& g, const std::vector<Eigen::Vector3f>& normals,
                          const SelectionParams& params, int count, std::vector<int>& comp);

}  // namespace proxseg::detail
