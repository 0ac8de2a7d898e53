// The parameter checks and the named presets of segment() and recognize() (pipeline.hpp,
// recognition_types.hpp); their JSON form is in io/params.cpp.
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/recognition_types.hpp>

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
    p.selection.merge_convex = false;
    p.selection.cut_support_plane = false;
    p.selection.absorb_small = false;
    p.selection.geometry = SelectionParams::Geometry::kVoxels;
    p.selection.join_occluded = false;
    p.selection.join_containers = false;
    p.selection.min_candidate_points = 500;  // the threshold this preset has always used
    p.paper_labels = true;
    return p;
  }
  throw InputError("preset: expected \"default\" or \"paper\", got \"" + name + "\"");
}

void validate(const SegmentParams& p) {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) throw InputError(std::string("field ") + field + ": expected " + expected);
  };
  auto finite = [](double v) { return std::isfinite(v); };
  require(finite(p.voxels.voxel_size) && p.voxels.voxel_size > 0, "voxels.voxel_size",
          "a positive size in metres");
  require(p.voxels.min_points_per_voxel >= 1, "voxels.min_points_per_voxel", ">= 1");
  require(finite(p.features.colour_weight) && p.features.colour_weight >= 0,
          "features.colour_weight", ">= 0");
  require(finite(p.features.texture_weight) && p.features.texture_weight >= 0,
          "features.texture_weight", ">= 0");
  require(finite(p.features.shape_weight) && p.features.shape_weight >= 0, "features.shape_weight",
          ">= 0");
  require(finite(p.features.gabor_wavelength) && p.features.gabor_wavelength >= 2,
          "features.gabor_wavelength", ">= 2 pixels (Nyquist)");
  require(finite(p.features.gabor_sigma) && p.features.gabor_sigma > 0, "features.gabor_sigma",
          "> 0 pixels");
  require(p.features.texture_clip_quantile > 0 && p.features.texture_clip_quantile <= 1,
          "features.texture_clip_quantile", "in (0, 1]");
  require(p.features.gabor_stride == 1 || p.features.gabor_stride == 2, "features.gabor_stride",
          "1 (every pixel) or 2");
  require(p.features.normal_step >= 1 && p.features.normal_step <= 50, "features.normal_step",
          "1..50 pixels");
  require(p.features.normal_knn >= 3, "features.normal_knn", ">= 3");
  require(p.clustering.alpha > 0 && p.clustering.alpha < 1, "clustering.alpha", "in (0, 1)");
  require(p.clustering.pca_dims >= 1 && p.clustering.pca_dims <= kFeatureDims,
          "clustering.pca_dims", "1..454");
  require(finite(p.clustering.prior_weight) && p.clustering.prior_weight > 0,
          "clustering.prior_weight", "> 0");
  require(p.kmeans.max_iterations >= 1, "kmeans.max_iterations", ">= 1");
  require(finite(p.kmeans.tolerance) && p.kmeans.tolerance >= 0, "kmeans.tolerance", ">= 0");
  require(finite(p.mrf.unary_weight) && p.mrf.unary_weight >= 0, "mrf.unary_weight", ">= 0");
  require(finite(p.mrf.pairwise_weight) && p.mrf.pairwise_weight >= 0, "mrf.pairwise_weight",
          ">= 0");
  require(p.mrf.max_cycles >= 1, "mrf.max_cycles", ">= 1");
  const SelectionParams& sp = p.selection;
  require(finite(sp.density_radius) && sp.density_radius > 0, "selection.density_radius",
          "a positive radius in metres");
  require(finite(sp.weak_density_ratio) && sp.weak_density_ratio >= 0 && sp.weak_density_ratio <= 1,
          "selection.weak_density_ratio", "in [0, 1]");
  require(finite(sp.cluster_tolerance) && sp.cluster_tolerance > 0, "selection.cluster_tolerance",
          "a positive distance in metres");
  require(sp.min_candidate_points >= 1, "selection.min_candidate_points", ">= 1");
  require(finite(sp.concavity_tolerance_deg) && sp.concavity_tolerance_deg >= 0 &&
              sp.concavity_tolerance_deg <= 180,
          "selection.concavity_tolerance_deg", "0..180 degrees");
  require(sp.merge_max_concave_share >= 0 && sp.merge_max_concave_share <= 1,
          "selection.merge_max_concave_share", "in [0, 1]");
  require(sp.merge_min_boundary >= 1, "selection.merge_min_boundary", ">= 1");
  require(finite(sp.support_normal_tolerance_deg) && sp.support_normal_tolerance_deg >= 0 &&
              sp.support_normal_tolerance_deg <= 90,
          "selection.support_normal_tolerance_deg", "0..90 degrees");
  require(finite(sp.background_min_area) && sp.background_min_area >= 0,
          "selection.background_min_area", ">= 0 square metres");
  require(finite(sp.background_plane_distance) && sp.background_plane_distance >= 0,
          "selection.background_plane_distance", ">= 0 metres");
  require(sp.background_inlier_ratio >= 0 && sp.background_inlier_ratio <= 1,
          "selection.background_inlier_ratio", "in [0, 1]");
  require(sp.image_normal_step >= 1 && sp.image_normal_step <= 64, "selection.image_normal_step",
          "1..64 pixels");
  require(finite(sp.depth_step_ratio) && sp.depth_step_ratio > 0, "selection.depth_step_ratio",
          "a positive share of the depth");
  require(finite(sp.crease_tolerance_deg) && sp.crease_tolerance_deg >= 0 &&
              sp.crease_tolerance_deg <= 180,
          "selection.crease_tolerance_deg", "0..180 degrees");
  require(sp.concavity_step >= 1 && sp.concavity_step <= 64, "selection.concavity_step",
          "1..64 pixels");
  require(finite(sp.sensor_noise_at_1m) && sp.sensor_noise_at_1m >= 0,
          "selection.sensor_noise_at_1m", ">= 0 metres");
  require(finite(sp.plane_band_sigmas) && sp.plane_band_sigmas >= 0, "selection.plane_band_sigmas",
          ">= 0");
  require(finite(sp.plane_band_min) && sp.plane_band_min >= 0, "selection.plane_band_min",
          ">= 0 metres");
  require(finite(sp.plane_flat_sigmas) && sp.plane_flat_sigmas >= 0, "selection.plane_flat_sigmas",
          ">= 0");
  require(sp.merge_window >= 1 && sp.merge_window <= 32, "selection.merge_window", "1..32 pixels");
  require(sp.merge_min_links >= 1, "selection.merge_min_links", ">= 1");
  require(sp.bridge_window >= 0 && sp.bridge_window <= 64, "selection.bridge_window",
          "0..64 pixels");
  require(finite(sp.bridge_tolerance) && sp.bridge_tolerance >= 0, "selection.bridge_tolerance",
          ">= 0 metres");
  require(sp.merge_min_agreement >= 0 && sp.merge_min_agreement <= 1,
          "selection.merge_min_agreement", "in [0, 1]");
  require(sp.occlusion_window >= 1 && sp.occlusion_window <= 10000, "selection.occlusion_window",
          "1..10000 pixels");
  require(sp.occlusion_min_rays >= 1, "selection.occlusion_min_rays", ">= 1");
  require(sp.occlusion_min_share >= 0 && sp.occlusion_min_share <= 1,
          "selection.occlusion_min_share", "in [0, 1]");
  require(finite(sp.occlusion_normal_tolerance_deg) && sp.occlusion_normal_tolerance_deg >= 0 &&
              sp.occlusion_normal_tolerance_deg <= 180,
          "selection.occlusion_normal_tolerance_deg", "0..180 degrees");
  require(finite(sp.occlusion_surface_tolerance) && sp.occlusion_surface_tolerance >= 0,
          "selection.occlusion_surface_tolerance", ">= 0 metres");
  require(sp.occlusion_min_colour >= 0 && sp.occlusion_min_colour <= 1,
          "selection.occlusion_min_colour", "in [0, 1]");
  require(sp.occlusion_min_face_rays >= 1, "selection.occlusion_min_face_rays", ">= 1");
  require(sp.occlusion_min_face_colour >= 0 && sp.occlusion_min_face_colour <= 1,
          "selection.occlusion_min_face_colour", "in [0, 1]");
  require(finite(sp.container_min_radius) && sp.container_min_radius >= 0,
          "selection.container_min_radius", ">= 0 metres");
  require(finite(sp.container_max_radius) && sp.container_max_radius >= sp.container_min_radius,
          "selection.container_max_radius", ">= selection.container_min_radius");
  require(finite(sp.container_circle_rms) && sp.container_circle_rms >= 0,
          "selection.container_circle_rms", ">= 0");
  require(finite(sp.container_rim_tolerance) && sp.container_rim_tolerance >= 0,
          "selection.container_rim_tolerance", ">= 0 metres");
  require(finite(sp.container_min_depth) && sp.container_min_depth >= 0,
          "selection.container_min_depth", ">= 0 metres");
  require(sp.island_missing_share >= 0 && sp.island_missing_share <= 1,
          "selection.island_missing_share", "in [0, 1]");
  require(p.threads >= 0 && p.threads <= 1024, "threads", "0 (all cores) .. 1024");
  require(finite(p.max_memory_mib) && p.max_memory_mib >= 0, "max_memory_mib",
          ">= 0 MiB (0 = no limit)");
}

void validate(const RecognitionParams& p) {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) throw InputError(std::string("field ") + field + ": expected " + expected);
  };
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  const RegistrationParams& r = p.registration;
  require(r.ransac_iterations >= 1 && r.ransac_iterations <= 10000000,
          "registration.ransac_iterations", "1 .. 10^7");
  require(positive(r.ransac_distance), "registration.ransac_distance", "> 0 metres");
  require(r.edge_similarity >= 0 && r.edge_similarity < 1, "registration.edge_similarity",
          "in [0, 1)");
  require(r.normal_tolerance_deg > 0 && r.normal_tolerance_deg <= 180,
          "registration.normal_tolerance_deg", "in (0, 180] degrees");
  require(r.ransac_candidates >= 1 && r.ransac_candidates <= 1000, "registration.ransac_candidates",
          "1 .. 1000");
  require(r.max_points >= 0, "registration.max_points", ">= 0 (0 = all)");
  require(r.icp_iterations >= 0 && r.icp_iterations <= 100000, "registration.icp_iterations",
          "0 .. 100000");
  require(r.icp_starts >= 1 && r.icp_starts <= 100, "registration.icp_starts", "1 .. 100");
  require(positive(r.icp_distance), "registration.icp_distance", "> 0 metres");
  require(positive(r.fitness_distance), "registration.fitness_distance", "> 0 metres");
  require(positive(r.score_distance), "registration.score_distance", "> 0 metres");
  require(r.brightness_sigma >= 0 && std::isfinite(r.brightness_sigma),
          "registration.brightness_sigma", ">= 0 (0 = chromaticity only)");
  require(r.coverage_outside_weight >= 0 && r.coverage_outside_weight <= 1,
          "registration.coverage_outside_weight", "in [0, 1]");
  require(p.min_score >= 0 && p.min_score <= 1, "min_score", "in [0, 1]");
  require(p.min_margin >= 0 && p.min_margin <= 1, "min_margin", "in [0, 1]");
  require(p.confident_score >= 0 && p.confident_score <= 1, "confident_score",
          "in [0, 1] (1: always ask for the margin)");
  require(p.shortlist >= 0, "shortlist", ">= 0 (0 = every view)");
  require(p.trial_shortlist >= 0, "trial_shortlist", ">= 0 (0 = every view of the objects)");
  require(p.early_exit >= 0 && p.early_exit <= 1, "early_exit", "0 (off) or a score in (0, 1]");
  require(p.lone_score >= 0 && p.lone_score <= 1, "lone_score", "0 (off) or a score in (0, 1]");
  require(p.lone_ratio >= 0 && p.lone_ratio <= 1, "lone_ratio", "0 .. 1");
  require(p.lookalike_share == 0 || (p.lookalike_share > 0.5 && p.lookalike_share <= 1),
          "lookalike_share", "0 (off) or a share in (0.5, 1]");
  require(p.lookalike_agreement >= 0 && p.lookalike_agreement <= 1, "lookalike_agreement",
          "in [0, 1]");
  require(p.lookalike_shape >= 0 && p.lookalike_shape <= 1, "lookalike_shape", "in [0, 1]");
  require(p.early_reject >= 0 && p.early_reject <= 1, "early_reject",
          "0 (off) or a rank in (0, 1]");
  require(p.split_fitness >= 0 && p.split_fitness <= 1, "split_fitness", "0 (off) .. 1");
  require(p.merge_distance >= 0 && p.merge_distance <= 1, "merge_distance", "0 (off) .. 1 metre");
  require(p.min_part_points >= 1, "min_part_points", ">= 1");
  require(p.free_space_tolerance >= 0 && std::isfinite(p.free_space_tolerance),
          "free_space_tolerance", ">= 0 metres (0 = off)");
  require(p.threads >= 0 && p.threads <= 1024, "threads", "0 (all cores) .. 1024");
}

}  // namespace proxseg
