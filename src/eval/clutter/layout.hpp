// The layout of a cluttered scene (docs/clutter.md): one draw of the table, the light, the
// objects and their places, captured by a camera that sees them all. Private to the library.
#pragma once
#include <proxseg/eval/clutter.hpp>

#include <string>
#include <vector>

namespace proxseg::clutter {

// Layout draw `draw` (sub-stream 1 + draw of the seed) of n objects, the LINEMOD meshes models
// among them, rendered into out. False if the objects could not all be placed, no camera showed
// them all, or some object shows fewer than min_visible_points in the frame.
bool draw_layout(const ClutterParams& P, const std::vector<std::string>& models, int n, int draw,
                 ClutterScene& out);

}  // namespace proxseg::clutter
