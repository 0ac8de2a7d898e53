// SegmentParams <-> JSON. Every parameter is listed once, in fields(); to_json, params_from_json
// and the CLI's config handling all go through that list.
#include <proxseg/io/params.hpp>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "input_file.hpp"

namespace proxseg {

void to_json(nlohmann::json& j, MrfMethod m) {
  j = m == MrfMethod::kSwap ? "swap" : "expansion";
}
void to_json(nlohmann::json& j, PcaSolver s) {
  j = s == PcaSolver::kDense ? "dense" : "lanczos";
}
void to_json(nlohmann::json& j, SelectionParams::Geometry g) {
  j = g == SelectionParams::Geometry::kImage ? "image" : "voxels";
}
void to_json(nlohmann::json& j, MultiRadius m) {
  j = m == MultiRadius::kConcatenate ? "concatenate" : "best_of";
}
void to_json(nlohmann::json& j, ColourCompare c) {
  j = c == ColourCompare::kPoints      ? "points"
      : c == ColourCompare::kHistogram ? "histogram"
                                       : "best";
}
void to_json(nlohmann::json& j, Score s) {
  j = s == Score::kFitness ? "fitness" : s == Score::kSymmetric ? "symmetric" : "colour";
}

namespace {

using nlohmann::json;

// (section, key, reference) for every parameter; section "" is the top level.
template <class P, class F>
void fields(P& p, F&& f) {
  f("voxels", "voxel_size", p.voxels.voxel_size);
  f("voxels", "min_points_per_voxel", p.voxels.min_points_per_voxel);
  f("features", "use_colour", p.features.use_colour);
  f("features", "use_texture", p.features.use_texture);
  f("features", "use_shape", p.features.use_shape);
  f("features", "colour_weight", p.features.colour_weight);
  f("features", "texture_weight", p.features.texture_weight);
  f("features", "shape_weight", p.features.shape_weight);
  f("features", "gabor_wavelength", p.features.gabor_wavelength);
  f("features", "gabor_sigma", p.features.gabor_sigma);
  f("features", "texture_clip_quantile", p.features.texture_clip_quantile);
  f("features", "gabor_stride", p.features.gabor_stride);
  f("features", "normal_step", p.features.normal_step);
  f("features", "normal_knn", p.features.normal_knn);
  f("clustering", "alpha", p.clustering.alpha);
  f("clustering", "pca_dims", p.clustering.pca_dims);
  f("clustering", "pca_solver", p.clustering.pca_solver);
  f("clustering", "prior_weight", p.clustering.prior_weight);
  f("clustering", "balance_blocks", p.clustering.balance_blocks);
  f("kmeans", "max_iterations", p.kmeans.max_iterations);
  f("kmeans", "tolerance", p.kmeans.tolerance);
  f("mrf", "enabled", p.mrf.enabled);
  f("mrf", "unary_weight", p.mrf.unary_weight);
  f("mrf", "pairwise_weight", p.mrf.pairwise_weight);
  f("mrf", "method", p.mrf.method);
  f("mrf", "max_cycles", p.mrf.max_cycles);
  f("selection", "density_radius", p.selection.density_radius);
  f("selection", "weak_density_ratio", p.selection.weak_density_ratio);
  f("selection", "cluster_tolerance", p.selection.cluster_tolerance);
  f("selection", "min_candidate_points", p.selection.min_candidate_points);
  f("selection", "concavity_tolerance_deg", p.selection.concavity_tolerance_deg);
  f("selection", "split_concave", p.selection.split_concave);
  f("selection", "merge_convex", p.selection.merge_convex);
  f("selection", "merge_links", p.selection.merge_links);
  f("selection", "merge_max_concave_share", p.selection.merge_max_concave_share);
  f("selection", "merge_min_boundary", p.selection.merge_min_boundary);
  f("selection", "cut_support_plane", p.selection.cut_support_plane);
  f("selection", "absorb_small", p.selection.absorb_small);
  f("selection", "support_normal_tolerance_deg", p.selection.support_normal_tolerance_deg);
  f("selection", "background_min_area", p.selection.background_min_area);
  f("selection", "background_plane_distance", p.selection.background_plane_distance);
  f("selection", "background_inlier_ratio", p.selection.background_inlier_ratio);
  f("selection", "geometry", p.selection.geometry);
  f("selection", "image_normal_step", p.selection.image_normal_step);
  f("selection", "depth_step_ratio", p.selection.depth_step_ratio);
  f("selection", "concavity_step", p.selection.concavity_step);
  f("selection", "crease_tolerance_deg", p.selection.crease_tolerance_deg);
  f("selection", "sensor_noise_at_1m", p.selection.sensor_noise_at_1m);
  f("selection", "plane_band_sigmas", p.selection.plane_band_sigmas);
  f("selection", "plane_band_min", p.selection.plane_band_min);
  f("selection", "plane_flat_sigmas", p.selection.plane_flat_sigmas);
  f("selection", "merge_window", p.selection.merge_window);
  f("selection", "merge_min_links", p.selection.merge_min_links);
  f("selection", "bridge_window", p.selection.bridge_window);
  f("selection", "bridge_tolerance", p.selection.bridge_tolerance);
  f("selection", "merge_min_agreement", p.selection.merge_min_agreement);
  f("selection", "island_missing_share", p.selection.island_missing_share);
  f("selection", "join_occluded", p.selection.join_occluded);
  f("selection", "occlusion_window", p.selection.occlusion_window);
  f("selection", "occlusion_min_rays", p.selection.occlusion_min_rays);
  f("selection", "occlusion_min_share", p.selection.occlusion_min_share);
  f("selection", "occlusion_normal_tolerance_deg", p.selection.occlusion_normal_tolerance_deg);
  f("selection", "occlusion_surface_tolerance", p.selection.occlusion_surface_tolerance);
  f("selection", "occlusion_min_colour", p.selection.occlusion_min_colour);
  f("selection", "occlusion_min_face_rays", p.selection.occlusion_min_face_rays);
  f("selection", "occlusion_min_face_colour", p.selection.occlusion_min_face_colour);
  f("selection", "edge_aware_normals", p.selection.edge_aware_normals);
  f("selection", "join_containers", p.selection.join_containers);
  f("selection", "container_min_radius", p.selection.container_min_radius);
  f("selection", "container_max_radius", p.selection.container_max_radius);
  f("selection", "container_circle_rms", p.selection.container_circle_rms);
  f("selection", "container_rim_tolerance", p.selection.container_rim_tolerance);
  f("selection", "container_min_depth", p.selection.container_min_depth);
  f("", "paper_labels", p.paper_labels);
  f("", "threads", p.threads);
  f("", "max_memory_mib", p.max_memory_mib);
}

// The same for recognition [3.4].
template <class P, class F>
void recognition_fields(P& p, F&& f) {
  f("registration", "multi_radius", p.registration.multi_radius);
  f("registration", "ransac_iterations", p.registration.ransac_iterations);
  f("registration", "ransac_distance", p.registration.ransac_distance);
  f("registration", "edge_similarity", p.registration.edge_similarity);
  f("registration", "normal_tolerance_deg", p.registration.normal_tolerance_deg);
  f("registration", "ransac_candidates", p.registration.ransac_candidates);
  f("registration", "mutual_filter", p.registration.mutual_filter);
  f("registration", "max_points", p.registration.max_points);
  f("registration", "icp_iterations", p.registration.icp_iterations);
  f("registration", "icp_starts", p.registration.icp_starts);
  f("registration", "icp_distance", p.registration.icp_distance);
  f("registration", "point_to_plane", p.registration.point_to_plane);
  f("registration", "fitness_distance", p.registration.fitness_distance);
  f("registration", "score_distance", p.registration.score_distance);
  f("registration", "coverage_outside_weight", p.registration.coverage_outside_weight);
  f("registration", "colour_compare", p.registration.colour_compare);
  f("registration", "colour_alignment", p.registration.colour_alignment);
  f("registration", "brightness_sigma", p.registration.brightness_sigma);
  f("", "score", p.score);
  f("", "min_score", p.min_score);
  f("", "min_margin", p.min_margin);
  f("", "confident_score", p.confident_score);
  f("", "shortlist", p.shortlist);
  f("", "shortlist_parts", p.shortlist_parts);
  f("", "trial_shortlist", p.trial_shortlist);
  f("", "merge_unnamed", p.merge_unnamed);
  f("", "early_exit", p.early_exit);
  f("", "early_reject", p.early_reject);
  f("", "lone_score", p.lone_score);
  f("", "lone_ratio", p.lone_ratio);
  f("", "lookalike_share", p.lookalike_share);
  f("", "lookalike_agreement", p.lookalike_agreement);
  f("", "lookalike_shape", p.lookalike_shape);
  f("", "split_fitness", p.split_fitness);
  f("", "merge_distance", p.merge_distance);
  f("", "min_part_points", p.min_part_points);
  f("", "free_space_tolerance", p.free_space_tolerance);
  f("", "seed", p.seed);
  f("", "threads", p.threads);
}

std::string field_name(const std::string& section, const std::string& key) {
  return section.empty() ? key : section + "." + key;
}

[[noreturn]] void wrong_type(const std::string& name, const char* expected, const json& v) {
  throw InputError("field " + name + ": expected " + expected + ", got " + v.dump());
}

void read_value(const std::string& name, const json& v, double& out) {
  if (!v.is_number()) wrong_type(name, "a number", v);
  out = v.get<double>();
}
void read_value(const std::string& name, const json& v, int& out) {
  if (!v.is_number_integer()) wrong_type(name, "an integer", v);
  out = v.get<int>();
}
void read_value(const std::string& name, const json& v, bool& out) {
  if (!v.is_boolean()) wrong_type(name, "true or false", v);
  out = v.get<bool>();
}
void read_value(const std::string& name, const json& v, std::uint64_t& out) {
  if (!v.is_number_unsigned()) wrong_type(name, "a non-negative integer", v);
  out = v.get<std::uint64_t>();
}
void read_value(const std::string& name, const json& v, MultiRadius& out) {
  if (v == "concatenate")
    out = MultiRadius::kConcatenate;
  else if (v == "best_of")
    out = MultiRadius::kBestOf;
  else
    wrong_type(name, "\"concatenate\" or \"best_of\"", v);
}
void read_value(const std::string& name, const json& v, ColourCompare& out) {
  if (v == "points")
    out = ColourCompare::kPoints;
  else if (v == "histogram")
    out = ColourCompare::kHistogram;
  else if (v == "best")
    out = ColourCompare::kBest;
  else
    wrong_type(name, "\"points\", \"histogram\" or \"best\"", v);
}
void read_value(const std::string& name, const json& v, Score& out) {
  if (v == "fitness")
    out = Score::kFitness;
  else if (v == "symmetric")
    out = Score::kSymmetric;
  else if (v == "colour")
    out = Score::kColour;
  else
    wrong_type(name, "\"colour\", \"symmetric\" or \"fitness\"", v);
}
void read_value(const std::string& name, const json& v, SelectionParams::Geometry& out) {
  if (v == "image")
    out = SelectionParams::Geometry::kImage;
  else if (v == "voxels")
    out = SelectionParams::Geometry::kVoxels;
  else
    wrong_type(name, "\"image\" or \"voxels\"", v);
}
void read_value(const std::string& name, const json& v, PcaSolver& out) {
  if (v == "dense")
    out = PcaSolver::kDense;
  else if (v == "lanczos")
    out = PcaSolver::kLanczos;
  else
    wrong_type(name, "\"dense\" or \"lanczos\"", v);
}
void read_value(const std::string& name, const json& v, MrfMethod& out) {
  if (v == "swap")
    out = MrfMethod::kSwap;
  else if (v == "expansion")
    out = MrfMethod::kExpansion;
  else
    wrong_type(name, "\"swap\" or \"expansion\"", v);
}

template <class P, class Fields>
json to_json_with(const P& params, Fields fields) {
  json j = json::object();
  fields(params, [&](const std::string& section, const std::string& key, const auto& value) {
    if (section.empty())
      j[key] = value;
    else
      j[section][key] = value;
  });
  return j;
}

template <class P, class Fields>
P from_json_with(const json& j, P base, Fields fields) {
  if (!j.is_object()) throw InputError("config: expected a JSON object, got " + j.dump());
  // Unknown keys are errors: a typo must not silently leave a default in place.
  std::set<std::string> sections, known;
  fields(base, [&](const std::string& section, const std::string& key, auto&) {
    sections.insert(section);
    known.insert(field_name(section, key));
  });
  for (const auto& [key, value] : j.items()) {
    if (sections.count(key)) {
      if (!value.is_object()) wrong_type(key, "an object", value);
      for (const auto& [sub, ignored] : value.items())
        if (!known.count(key + "." + sub))
          throw InputError("config: unknown key " + key + "." + sub);
    } else if (!known.count(key)) {
      throw InputError("config: unknown key " + key);
    }
  }
  fields(base, [&](const std::string& section, const std::string& key, auto& value) {
    const json* v = section.empty() ? &j : (j.contains(section) ? &j.at(section) : nullptr);
    if (v && v->contains(key)) read_value(field_name(section, key), v->at(key), value);
  });
  validate(base);
  return base;
}

const auto kSegmentFields = [](auto& p, auto&& f) { fields(p, f); };
const auto kRecognitionFields = [](auto& p, auto&& f) { recognition_fields(p, f); };

json read_json_file(const std::string& path) {
  const std::string text = detail::read_input_file(path);
  try {
    return json::parse(text);
  } catch (const json::exception& e) {  // parse errors, and numbers out of range (out_of_range.406)
    throw InputError(path + ": not valid JSON (" + e.what() + ")");
  }
}

}  // namespace

json to_json(const SegmentParams& params) {
  return to_json_with(params, kSegmentFields);
}

SegmentParams params_from_json(const json& j, SegmentParams base) {
  return from_json_with(j, base, kSegmentFields);
}

json to_json(const DescriptorParams& d) {
  return {{"voxel_size", d.voxel_size},
          {"normal_radius", d.normal_radius},
          {"fpfh_radii", d.fpfh_radii}};
}

json to_json(const RecognitionParams& params) {
  return to_json_with(params, kRecognitionFields);
}

RecognitionParams recognition_params_from_json(const json& j, RecognitionParams base) {
  return from_json_with(j, base, kRecognitionFields);
}

std::pair<SegmentParams, RecognitionParams> read_recognize_params(const std::string& path,
                                                                  SegmentParams seg,
                                                                  RecognitionParams rec) {
  const json j = read_json_file(path);
  try {
    if (!j.is_object())
      throw InputError("expected {\"segmentation\": {...}, \"recognition\": {...}}");
    for (const auto& [key, value] : j.items())
      if (key != "segmentation" && key != "recognition")
        throw InputError("config: unknown key " + key +
                         " (expected \"segmentation\" and/or \"recognition\")");
    if (j.contains("segmentation")) seg = params_from_json(j.at("segmentation"), seg);
    if (j.contains("recognition")) rec = recognition_params_from_json(j.at("recognition"), rec);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
  return {seg, rec};
}

SegmentParams read_params(const std::string& path, SegmentParams base) {
  const json j = read_json_file(path);
  try {
    return params_from_json(j, base);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace proxseg
