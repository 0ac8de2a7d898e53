// The inside and the outside of one container: a mug, bowl or pot seen from above shows its
// outer wall and, through the opening, its inner wall and floor, which the rim separates by a
// depth step or a band of missing pixels [extension of 3.3; docs/method.md, "Selection on the
// image grid", rule 7c].
#pragma once
#include <proxseg/core/selection.hpp>

#include "image_grid.hpp"

#include <vector>

namespace proxseg::detail {

// comp: per pixel a component id 0..count-1, kPlane or kNone; support: the support plane (its
// normal towards the sensor). A component whose footprint on the plane lies inside the circle
// fitted to a round component's footprint, which reaches no higher than that component's rim and
// goes at least containers.min_depth below it, joins it (SelectionParams::containers): comp
// takes one id per joined set.
void join_container_pieces(const ImageGrid& g, const Plane& support, const SelectionParams& params,
                           int count, std::vector<int>& comp);

}  // namespace proxseg::detail
