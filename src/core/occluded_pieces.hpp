// Pieces of one surface that an object in front of it cut apart [extension of 3.3; docs/method.md,
// "Selection on the image grid", rule 7b].
#pragma once
#include <proxseg/core/selection.hpp>

#include "image_grid.hpp"

#include <Eigen/Core>
#include <vector>

namespace proxseg::detail {

// comp: per pixel a component id 0..count-1, kPlane or kNone. Components that the rule of
// SelectionParams::occlusion pairs are joined: comp takes one id per joined set (the
// union-find's representative). On a colourless frame the colour tests pass.
void join_occluded_pieces(const ImageGrid& g, const std::vector<Eigen::Vector3f>& normals,
                          const SelectionParams& params, int count, std::vector<int>& comp);

}  // namespace proxseg::detail
