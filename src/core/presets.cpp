// The named presets of segment(): "default" (the structs' own values) and "paper" (the paper's
// method as written); their JSON form is in io/report/params_json.cpp.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/parameters.hpp>

#include <string>

namespace proxseg {

SegmentParams preset(const std::string& name) {
  SegmentParams p;
  if (name == "default") return p;
  if (name == "paper") {
    // Section 3.1-3.2 and the GCO call of section 3.2.
    p.voxels.voxel_size = 0.02;
    p.features.gabor_stride = 1;  // Gabor responses at every pixel
    p.clustering.alpha = 0.85;
    p.clustering.pca_solver = PcaSolver::kDense;  // the full eigendecomposition
    p.mrf.unary_weight = 1.0;
    p.mrf.pairwise_weight = 0.275;
    p.mrf.method = MrfMethod::kSwap;
    p.mrf.max_cycles = 100;  // until a sweep lowers nothing, as GCO's swap
    // Section 3.3 as written: same-label clusters split at weak links, kept by size; none of the
    // convexity, support-plane or small-fragment extensions.
    p.selection.split_concave = false;
    p.selection.voxels.merge_convex = false;
    p.selection.cut_support_plane = false;
    p.selection.absorb_small = false;
    p.selection.geometry = SelectionParams::Geometry::kVoxels;
    p.selection.occlusion.enabled = false;
    p.selection.containers.enabled = false;
    p.selection.min_candidate_points = 500;  // the threshold this preset has always used
    p.paper_labels = true;
    return p;
  }
  throw InputError("preset: expected \"default\" or \"paper\", got \"" + name + "\"");
}

}  // namespace proxseg
