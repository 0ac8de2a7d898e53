// The parameter checks (the ranges of the table, parameters.hpp) and the named presets of
// segment() and recognize(); their JSON form is in io/params.cpp.
#include <proxseg/core/parameters.hpp>

#include <cmath>
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

namespace {

// Every row's range (parameters.hpp): InputError "field KEY: expected RANGE, got VALUE".
template <class P>
void check_ranges(const P& p, const std::vector<Parameter>& table) {
  for (const Parameter& row : table) {
    const ParamValue value = get_parameter(p, row.key());
    if (!in_range(row, value))
      throw InputError("field " + row.key() + ": expected " + row.range_text() + ", got " +
                       format_parameter(value));
  }
}

}  // namespace

void validate(const SegmentParams& p) {
  check_ranges(p, segment_parameters());
  const SelectionParams& sp = p.selection;
  if (sp.containers.max_radius < sp.containers.min_radius)
    throw InputError(
        "field selection.containers.max_radius: expected >= "
        "selection.containers.min_radius (" +
        format_parameter(sp.containers.min_radius) + "), got " +
        format_parameter(sp.containers.max_radius));
}

void validate(const RecognitionParams& p) {
  check_ranges(p, recognition_parameters());
}

}  // namespace proxseg
