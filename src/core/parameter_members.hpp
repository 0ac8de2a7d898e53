// The members of the parameter structs, by name, for the parameter table (parameters.cpp).
// Boost.Fusion's adaptation lists each struct's members once; the table walks the structs
// through it (the type, default and paper value of a row come from its member) and joins each
// member to its row of parameter_rows.txt by key. A section is a member that is itself adapted
// ("selection.image" is SelectionParams::image). Internal to core.
#pragma once
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/recognition_types.hpp>

#include <boost/fusion/include/adapt_struct.hpp>
#include <boost/fusion/include/for_each.hpp>
#include <boost/fusion/include/is_sequence.hpp>
#include <boost/fusion/include/size.hpp>
#include <boost/fusion/include/value_at.hpp>
#include <string>
#include <utility>
#include <vector>

#include "util/field_count.hpp"

// A parameter struct's Boost.Fusion adaptation, checked against the struct at compile time: a
// member added to the struct but not listed here stops the build (not only a test).
#define PROXSEG_ADAPT_PARAMETERS(S, ...)                                                       \
  BOOST_FUSION_ADAPT_STRUCT(S, __VA_ARGS__)                                                    \
  static_assert(proxseg::detail::field_count<S>() == boost::fusion::result_of::size<S>::value, \
                #S "'s adaptation (parameter_members.hpp) must list every member of " #S);

// Every member of each struct, sections included; the structs' headers document them.
PROXSEG_ADAPT_PARAMETERS(proxseg::SegmentParams, voxels, features, clustering, kmeans, mrf,
                         selection, paper_labels, threads, max_memory_mib)
PROXSEG_ADAPT_PARAMETERS(proxseg::VoxelParams, voxel_size, min_points_per_voxel)
PROXSEG_ADAPT_PARAMETERS(proxseg::FeatureParams, use_colour, use_texture, use_shape, colour_weight,
                         texture_weight, shape_weight, gabor_wavelength, gabor_sigma,
                         texture_clip_quantile, gabor_stride, normal_step, normal_knn,
                         normal_edge_ratio)
PROXSEG_ADAPT_PARAMETERS(proxseg::ClusteringParams, alpha, pca_dims, pca_solver, prior_weight,
                         balance_blocks)
PROXSEG_ADAPT_PARAMETERS(proxseg::KMeansParams, max_iterations, tolerance)
PROXSEG_ADAPT_PARAMETERS(proxseg::MrfParams, enabled, unary_weight, pairwise_weight, method,
                         max_cycles)
PROXSEG_ADAPT_PARAMETERS(proxseg::SelectionParams, density_radius, weak_density_ratio,
                         cluster_tolerance, min_candidate_points, absorb_small, split_concave,
                         merge_max_concave_share, cut_support_plane, support_normal_tolerance_deg,
                         background_min_area, background_plane_distance, background_inlier_ratio,
                         geometry, voxels, image, occlusion, containers)
PROXSEG_ADAPT_PARAMETERS(proxseg::VoxelSelectionParams, concavity_tolerance_deg, merge_convex,
                         merge_min_boundary)
PROXSEG_ADAPT_PARAMETERS(proxseg::ImageSelectionParams, normal_step, edge_aware_normals,
                         depth_step_ratio, concavity_step, crease_tolerance_deg, sensor_noise_at_1m,
                         plane_band_sigmas, plane_band_min, plane_flat_sigmas, merge_links,
                         merge_window, merge_min_links, bridge_window, bridge_tolerance,
                         merge_min_agreement, island_missing_share)
PROXSEG_ADAPT_PARAMETERS(proxseg::OcclusionParams, enabled, window, min_rays, min_share,
                         normal_tolerance_deg, surface_tolerance, min_colour, min_face_rays,
                         min_face_colour)
PROXSEG_ADAPT_PARAMETERS(proxseg::ContainerParams, enabled, min_radius, max_radius, circle_rms,
                         rim_tolerance, min_depth)
PROXSEG_ADAPT_PARAMETERS(proxseg::RecognitionParams, registration, score, min_score, min_margin,
                         confident_score, explain_fitness, support_gap, shortlist, shortlist_parts,
                         trial_shortlist, early_exit, early_reject, lone_score, lone_ratio,
                         lookalike_share, lookalike_agreement, lookalike_shape, split_fitness,
                         merge_distance, merge_unnamed, min_part_points, free_space_tolerance,
                         hidden_depth, seed, threads)
PROXSEG_ADAPT_PARAMETERS(proxseg::RegistrationParams, multi_radius, ransac_iterations,
                         ransac_distance, edge_similarity, normal_tolerance_deg, ransac_candidates,
                         mutual_filter, max_points, icp_iterations, icp_starts, icp_distance,
                         point_to_plane, fitness_distance, score_distance, score_distance_slope,
                         coverage_outside_weight, colour_compare, colour_alignment,
                         brightness_sigma)

namespace proxseg::detail {

template <class S>
constexpr bool kIsSection = boost::fusion::traits::is_sequence<S>::value;

// Calls f(member) for every parameter of s (a SegmentParams, a RecognitionParams or a section),
// in the order member_keys() names them; const s gives const members.
template <class S, class F>
void for_each_parameter(S& s, F& f) {
  boost::fusion::for_each(s, [&f](auto& member) {
    if constexpr (kIsSection<std::decay_t<decltype(member)>>)
      for_each_parameter(member, f);
    else
      f(member);
  });
}

template <class S, std::size_t... I>
void add_member_keys(const std::string& prefix, std::vector<std::string>& keys,
                     std::index_sequence<I...>);

// Appends the keys of S's parameters, prefix + "name" ("selection." + "image.normal_step").
template <class S>
void add_member_keys(const std::string& prefix, std::vector<std::string>& keys) {
  add_member_keys<S>(prefix, keys,
                     std::make_index_sequence<boost::fusion::result_of::size<S>::value>{});
}

template <class S, std::size_t I>
void add_member_key(const std::string& prefix, std::vector<std::string>& keys) {
  using M = typename boost::fusion::result_of::value_at_c<S, I>::type;
  const std::string key = prefix + boost::fusion::extension::struct_member_name<S, I>::call();
  if constexpr (kIsSection<M>)
    add_member_keys<M>(key + ".", keys);
  else
    keys.push_back(key);
}

template <class S, std::size_t... I>
void add_member_keys(const std::string& prefix, std::vector<std::string>& keys,
                     std::index_sequence<I...>) {
  (add_member_key<S, I>(prefix, keys), ...);
}

}  // namespace proxseg::detail
