// The rows of the parameter table (parameters.hpp): every parameter of SegmentParams and
// RecognitionParams is one line of segment_fields() or recognition_fields(), the row (name,
// unit, help, range, flag) beside the member it describes. Type, default and the paper preset's
// value are read from the member itself (parameters.cpp), so that they cannot disagree with the
// structs.
#pragma once
#include <proxseg/core/parameters.hpp>
#include <proxseg/core/pipeline.hpp>

#include <cstring>
#include <limits>

namespace proxseg::detail {

constexpr double kInf = std::numeric_limits<double>::infinity();

// What a line of the table says besides the member: plain pointers and numbers, so that walking
// the table (get_parameter, set_parameter) allocates nothing.
struct Row {
  const char* section;
  const char* name;
  const char* unit;
  const char* help;
  double min = -kInf, max = kInf;
  bool min_open = false, max_open = false, zero_off = false;
  const char* flag = "";
  const char* alias = "";
  bool paper_preset = false;  // the paper states it: its value is preset("paper")'s
  const char* paper = "";     // recognition: the paper's value as text

  Row(const char* s, const char* n, const char* u, const char* h)
      : section(s), name(n), unit(u), help(h) {}
  Row& at_least(double v) { return min = v, *this; }
  Row& above(double v) { return min = v, min_open = true, *this; }
  Row& at_most(double v) { return max = v, *this; }
  Row& below(double v) { return max = v, max_open = true, *this; }
  Row& in(double lo, double hi) { return min = lo, max = hi, *this; }
  Row& share() { return in(0, 1); }  // [0, 1]
  Row& or_zero() { return zero_off = true, *this; }
  Row& cli(const char* f, const char* a = "") { return flag = f, alias = a, *this; }
  Row& in_paper() { return paper_preset = true, *this; }
  Row& paper_says(const char* text) { return paper = text, *this; }
  bool is(const char* key_section, const char* key_name) const {
    return std::strcmp(section, key_section) == 0 && std::strcmp(name, key_name) == 0;
  }
};

// The names of each enum's values, in the enum's order (the JSON and CLI spelling).
template <class E>
struct Names;
template <>
struct Names<MrfMethod> {
  static constexpr const char* v[] = {"swap", "expansion"};
};
template <>
struct Names<PcaSolver> {
  static constexpr const char* v[] = {"dense", "lanczos"};
};
template <>
struct Names<SelectionParams::Geometry> {
  static constexpr const char* v[] = {"voxels", "image"};
};
template <>
struct Names<MultiRadius> {
  static constexpr const char* v[] = {"concatenate", "best_of"};
};
template <>
struct Names<ColourCompare> {
  static constexpr const char* v[] = {"points", "histogram", "best"};
};
template <>
struct Names<Score> {
  static constexpr const char* v[] = {"fitness", "symmetric", "colour"};
};

template <class S, class F>
void selection_fields(S& s, F&& f);

// Segmentation [3.1-3.3], in the order of the pipeline.
// Long: the table itself, one row per parameter in the order of docs/parameters.md.
template <class P, class F>
void segment_fields(P& p, F&& f) {
  using R = Row;
  auto& v = p.voxels;
  f(R("voxels", "voxel_size", "m", "Voxel side [3.1]").above(0).cli("voxel-size").in_paper(),
    v.voxel_size);
  f(R("voxels", "min_points_per_voxel", "",
      "Sparser voxels are not clustered (they inherit a "
      "label later)")
        .at_least(1)
        .cli("min-points"),
    v.min_points_per_voxel);
  auto& fe = p.features;
  f(R("features", "use_colour", "", "The colour block: hue-saturation histograms [3.1]")
        .cli("no-colour", "no-color")
        .in_paper(),
    fe.use_colour);
  f(R("features", "use_texture", "", "The texture block: Gabor responses [3.1]")
        .cli("no-texture")
        .in_paper(),
    fe.use_texture);
  f(R("features", "use_shape", "", "The shape block: normals and curvature [3.1]")
        .cli("no-shape")
        .in_paper(),
    fe.use_shape);
  f(R("features", "colour_weight", "", "Weight of the colour block")
        .at_least(0)
        .cli("colour-weight", "color-weight"),
    fe.colour_weight);
  f(R("features", "texture_weight", "", "Weight of the texture block")
        .at_least(0)
        .cli("texture-weight"),
    fe.texture_weight);
  f(R("features", "shape_weight", "", "Weight of the shape block").at_least(0).cli("shape-weight"),
    fe.shape_weight);
  f(R("features", "gabor_wavelength", "px", "Gabor wavelength at every pyramid level").at_least(2),
    fe.gabor_wavelength);
  f(R("features", "gabor_sigma", "px", "Gabor envelope at every pyramid level").above(0),
    fe.gabor_sigma);
  f(R("features", "texture_clip_quantile", "",
      "Each filter's upper histogram edge: this quantile of its responses over the frame")
        .above(0)
        .at_most(1),
    fe.texture_clip_quantile);
  f(R("features", "gabor_stride", "px",
      "1 = Gabor responses at every pixel; 2 = on the grid of 2 x 2 cells")
        .in(1, 2)
        .in_paper(),
    fe.gabor_stride);
  f(R("features", "normal_step", "px", "Organized clouds: offset of the normals' differences")
        .in(1, 50),
    fe.normal_step);
  f(R("features", "normal_knn", "", "Unorganized clouds: neighbours of the PCA normals")
        .at_least(3),
    fe.normal_knn);
  f(R("features", "normal_edge_ratio", "",
      "Organized clouds: normals smoothed only within this depth share per pixel (0 = box)")
        .at_least(0),
    fe.normal_edge_ratio);
  auto& c = p.clustering;
  f(R("clustering", "alpha", "", "Chi-square confidence of Algorithm 1's same-centroid test")
        .above(0)
        .below(1)
        .cli("alpha")
        .in_paper(),
    c.alpha);
  f(R("clustering", "pca_dims", "", "Principal axes the features are projected on")
        .in(1, kFeatureDims)
        .cli("pca-dims"),
    c.pca_dims);
  f(R("clustering", "pca_solver", "", "Principal axes by the full eigensolver or by Lanczos")
        .in_paper(),
    c.pca_solver);
  f(R("clustering", "prior_weight", "", "Shrinkage of centroid covariances to the global one")
        .above(0)
        .cli("prior-weight"),
    c.prior_weight);
  f(R("clustering", "balance_blocks", "", "Scale the feature blocks to equal variance first"),
    c.balance_blocks);
  f(R("kmeans", "max_iterations", "", "Most k-means iterations").at_least(1),
    p.kmeans.max_iterations);
  f(R("kmeans", "tolerance", "", "k-means stops when no centroid moves more (relative)")
        .at_least(0),
    p.kmeans.tolerance);
  auto& m = p.mrf;
  f(R("mrf", "enabled", "", "MRF refinement of the k-means labels [3.2]").cli("no-mrf").in_paper(),
    m.enabled);
  f(R("mrf", "unary_weight", "", "w_u, the weight of the data term [3.2]")
        .at_least(0)
        .cli("wu")
        .in_paper(),
    m.unary_weight);
  f(R("mrf", "pairwise_weight", "", "w_c, the Potts weight per neighbouring voxel pair [3.2]")
        .at_least(0)
        .cli("wc")
        .in_paper(),
    m.pairwise_weight);
  f(R("mrf", "method", "", "Graph-cut moves").cli("mrf-method").in_paper(), m.method);
  f(R("mrf", "max_cycles", "", "Most sweeps over the labels (paper: until nothing changes)")
        .at_least(1)
        .cli("mrf-cycles")
        .in_paper(),
    m.max_cycles);
  selection_fields(p.selection, f);
  f(R("", "paper_labels", "",
      "Compute the paper's labels (stages 2-4) also where the selection does not need them")
        .cli("paper-labels")
        .in_paper(),
    p.paper_labels);
  f(R("", "threads", "", "Worker threads, 0 = all cores; results do not depend on it")
        .in(0, 1024)
        .cli("threads"),
    p.threads);
  f(R("", "max_memory_mib", "MiB",
      "Refuse a frame whose segmentation would need more (an estimate); 0 = no limit")
        .at_least(0)
        .cli("max-memory"),
    p.max_memory_mib);
}

// Selection [3.3] and its extensions (docs/method.md, "Selection").
// Long: the table itself, one row per parameter in the order of docs/parameters.md.
template <class S, class F>
void selection_fields(S& s, F&& f) {
  using R = Row;
  const char* sel = "selection";
  f(R(sel, "density_radius", "m", "Weak links: the radius of the density count [3.3]").above(0),
    s.density_radius);
  f(R(sel, "weak_density_ratio", "", "Weak links: points under this share of the median density")
        .share(),
    s.weak_density_ratio);
  f(R(sel, "cluster_tolerance", "m", "Euclidean clustering: points closer are connected [3.3]")
        .above(0)
        .cli("cluster-tolerance"),
    s.cluster_tolerance);
  f(R(sel, "min_candidate_points", "", "Smaller components are not candidates [3.3]")
        .at_least(1)
        .cli("min-candidate-points"),
    s.min_candidate_points);
  f(R(sel, "absorb_small", "", "Small components join their main large neighbour").in_paper(),
    s.absorb_small);
  f(R(sel, "concavity_tolerance_deg", "deg", "Voxels: normals turning more are a concave edge")
        .in(0, 180),
    s.concavity_tolerance_deg);
  f(R(sel, "split_concave", "", "Voxels: cut clusters at concave edges (after LCCP)").in_paper(),
    s.split_concave);
  f(R(sel, "merge_convex", "", "Voxels: join components across convex boundaries").in_paper(),
    s.merge_convex);
  f(R(sel, "merge_max_concave_share", "", "Most share of concave links across a merged boundary")
        .share(),
    s.merge_max_concave_share);
  f(R(sel, "merge_min_boundary", "", "Voxels: fewest edges of a boundary judged for a merge")
        .at_least(1),
    s.merge_min_boundary);
  f(R(sel, "cut_support_plane", "", "Cut the dominant plane (the table) from the objects")
        .in_paper(),
    s.cut_support_plane);
  f(R(sel, "support_normal_tolerance_deg", "deg", "Support plane: normals within this angle")
        .in(0, 90),
    s.support_normal_tolerance_deg);
  f(R(sel, "background_min_area", "m^2", "Background: planar components at least this large")
        .at_least(0),
    s.background_min_area);
  f(R(sel, "background_plane_distance", "m", "Background: inliers within this of the plane")
        .at_least(0),
    s.background_plane_distance);
  f(R(sel, "background_inlier_ratio", "", "Background: at least this share of inliers").share(),
    s.background_inlier_ratio);
  f(R(sel, "geometry", "", "Where the selection's geometry is computed (organized frames)")
        .in_paper(),
    s.geometry);
  f(R(sel, "image_normal_step", "px", "Image: offset and box size of the normals").in(1, 64),
    s.image_normal_step);
  f(R(sel, "edge_aware_normals", "", "Image: normals smoothed within their own surface"),
    s.edge_aware_normals);
  f(R(sel, "depth_step_ratio", "", "Image: a depth step over this share of the depth is an edge")
        .above(0),
    s.depth_step_ratio);
  f(R(sel, "concavity_step", "px", "Image: offset of the normals the crease test compares")
        .in(1, 64),
    s.concavity_step);
  f(R(sel, "crease_tolerance_deg", "deg", "Image: normals turning more are a crease").in(0, 180),
    s.crease_tolerance_deg);
  f(R(sel, "sensor_noise_at_1m", "m", "Image: the sensor's depth noise at 1 m (x z^2 elsewhere)")
        .at_least(0),
    s.sensor_noise_at_1m);
  f(R(sel, "plane_band_sigmas", "", "Image: the support plane's band in noise deviations")
        .at_least(0),
    s.plane_band_sigmas);
  f(R(sel, "plane_band_min", "m", "Image: the support plane's band is never narrower").at_least(0),
    s.plane_band_min);
  f(R(sel, "plane_flat_sigmas", "", "Image: candidate pixels this flat on the plane go to it")
        .at_least(0),
    s.plane_flat_sigmas);
  f(R(sel, "merge_links", "", "Image: components merge across gaps and short depth steps"),
    s.merge_links);
  f(R(sel, "merge_window", "px", "Image: most pixels between two linked pixels").in(1, 32),
    s.merge_window);
  f(R(sel, "merge_min_links", "", "Image: fewest links of a merge").at_least(1), s.merge_min_links);
  f(R(sel, "bridge_window", "px", "Image: widest band of missing pixels a link crosses").in(0, 64),
    s.bridge_window);
  f(R(sel, "bridge_tolerance", "m", "Image: farthest ends of a link across missing pixels")
        .at_least(0),
    s.bridge_tolerance);
  f(R(sel, "merge_min_agreement", "", "Image: share of links within one label (0 = unused)")
        .share(),
    s.merge_min_agreement);
  f(R(sel, "island_missing_share", "", "Image: components this much beside missing pixels join")
        .share(),
    s.island_missing_share);
  f(R(sel, "join_occluded", "", "Image: join pieces of an object cut apart by one in front")
        .in_paper(),
    s.join_occluded);
  f(R(sel, "occlusion_window", "px", "Occlusion: longest ray between two pieces").in(1, 10000),
    s.occlusion_window);
  f(R(sel, "occlusion_min_rays", "", "Occlusion: fewest rays ending on one surface").at_least(1),
    s.occlusion_min_rays);
  f(R(sel, "occlusion_min_share", "", "Occlusion: share of the rays ending on one surface").share(),
    s.occlusion_min_share);
  f(R(sel, "occlusion_normal_tolerance_deg", "deg", "Occlusion: one face within this angle")
        .in(0, 180),
    s.occlusion_normal_tolerance_deg);
  f(R(sel, "occlusion_surface_tolerance", "m", "Occlusion: one face within this distance")
        .at_least(0),
    s.occlusion_surface_tolerance);
  f(R(sel, "occlusion_min_colour", "", "Occlusion: fewest colour histogram intersection").share(),
    s.occlusion_min_colour);
  f(R(sel, "occlusion_min_face_rays", "", "Occlusion: or this many rays continuing one face")
        .at_least(1),
    s.occlusion_min_face_rays);
  f(R(sel, "occlusion_min_face_colour", "", "Occlusion: with this histogram intersection").share(),
    s.occlusion_min_face_colour);
  f(R(sel, "join_containers", "", "Image: join the inside and outside of a container").in_paper(),
    s.join_containers);
  f(R(sel, "container_min_radius", "m", "Containers: smallest rim radius").at_least(0),
    s.container_min_radius);
  f(R(sel, "container_max_radius", "m", "Containers: largest rim radius (>= the smallest)")
        .at_least(0),
    s.container_max_radius);
  f(R(sel, "container_circle_rms", "", "Containers: rim RMS off the circle, share of the radius")
        .at_least(0),
    s.container_circle_rms);
  f(R(sel, "container_rim_tolerance", "m", "Containers: the inside within this of the rim")
        .at_least(0),
    s.container_rim_tolerance);
  f(R(sel, "container_min_depth", "m", "Containers: the inside at least this deep").at_least(0),
    s.container_min_depth);
}

// Recognition [3.4, Algorithms 2-3] and its extensions (docs/method.md, "Recognition").
// Long: the table itself, one row per parameter in the order of docs/parameters.md.
template <class P, class F>
void recognition_fields(P& p, F&& f) {
  using R = Row;
  const char* reg = "registration";
  auto& r = p.registration;
  f(R(reg, "multi_radius", "", "Several FPFH radii: one descriptor, or the best RANSAC of each"),
    r.multi_radius);
  f(R(reg, "ransac_iterations", "", "RANSAC hypotheses per view (that pass the edge test)")
        .in(1, 1e7)
        .cli("ransac-iterations")
        .paper_says("100-200"),
    r.ransac_iterations);
  f(R(reg, "ransac_distance", "m", "RANSAC inlier distance").above(0), r.ransac_distance);
  f(R(reg, "edge_similarity", "", "RANSAC pre-rejection: edge-length ratio").at_least(0).below(1),
    r.edge_similarity);
  f(R(reg, "normal_tolerance_deg", "deg", "RANSAC pre-rejection: point-pair feature angles")
        .above(0)
        .at_most(180),
    r.normal_tolerance_deg);
  f(R(reg, "ransac_candidates", "", "Best distinct hypotheses re-judged by their overlap")
        .in(1, 1000),
    r.ransac_candidates);
  f(R(reg, "mutual_filter", "", "Keep only mutually nearest feature pairs"), r.mutual_filter);
  f(R(reg, "max_points", "", "Candidate points used for matching and ICP (0 = all)").at_least(0),
    r.max_points);
  f(R(reg, "icp_iterations", "", "Most ICP iterations per view")
        .in(0, 100000)
        .cli("icp-iterations")
        .paper_says("100-200"),
    r.icp_iterations);
  f(R(reg, "icp_starts", "", "ICP runs from this many best RANSAC hypotheses").in(1, 100),
    r.icp_starts);
  f(R(reg, "icp_distance", "m", "ICP ignores correspondences farther than this").above(0),
    r.icp_distance);
  f(R(reg, "point_to_plane", "", "Point-to-plane ICP instead of point-to-point")
        .cli("point-to-plane")
        .paper_says("false"),
    r.point_to_plane);
  f(R(reg, "fitness_distance", "m", "delta_th of eq. 4: a point is explained within this")
        .above(0)
        .cli("fitness-distance"),
    r.fitness_distance);
  f(R(reg, "score_distance", "m", "The ranking score's distance (tighter than delta_th)").above(0),
    r.score_distance);
  f(R(reg, "coverage_outside_weight", "", "Ranking: weight of view points outside the candidate")
        .share(),
    r.coverage_outside_weight);
  f(R(reg, "colour_compare", "", "The colour term compares points, histograms or the best"),
    r.colour_compare);
  f(R(reg, "colour_alignment", "", "Rank RANSAC and ICP poses by colour agreement too"),
    r.colour_alignment);
  f(R(reg, "brightness_sigma", "", "Colour agreement: sigma of the log brightness ratio (0 = off)")
        .at_least(0),
    r.brightness_sigma);
  f(R("", "score", "", "Ranking score: colour, symmetric (geometry) or fitness (eq. 5)")
        .cli("score")
        .paper_says("fitness"),
    p.score);
  f(R("", "min_score", "", "Below this best score the answer is \"unknown\"")
        .share()
        .cli("min-score"),
    p.min_score);
  f(R("", "min_margin", "", "Below this lead over the runner-up the answer is \"unknown\"")
        .share()
        .cli("min-margin"),
    p.min_margin);
  f(R("", "confident_score", "", "At or above this best score the margin is not asked for")
        .share()
        .cli("confident-score"),
    p.confident_score);
  f(R("", "shortlist", "", "Views aligned per candidate, nearest by signature (0 = every view)")
        .at_least(0)
        .cli("shortlist")
        .paper_says("0"),
    p.shortlist);
  f(R("", "shortlist_parts", "", "Compare also with the signatures of parts of each view"),
    p.shortlist_parts);
  f(R("", "trial_shortlist", "", "Views per split or merge trial (0 = all of the objects')")
        .at_least(0),
    p.trial_shortlist);
  f(R("", "early_exit", "", "Stop after the batch of 8 views in which one reached this (0 = off)")
        .share()
        .cli("early-exit"),
    p.early_exit);
  f(R("", "early_reject", "", "Stop after a batch of 8 views when none reached this rank (0 = off)")
        .share()
        .cli("early-reject"),
    p.early_reject);
  f(R("", "lone_score", "", "A lone match at least this still names the object (0 = off)")
        .share()
        .cli("lone-score"),
    p.lone_score);
  f(R("", "lone_ratio", "", "A lone match: the runner-up's largest share of the best score")
        .share()
        .cli("lone-ratio"),
    p.lone_ratio);
  f(R("", "lookalike_share", "", "Look-alikes: share of the colour votes that names one (0 = off)")
        .above(0.5)
        .at_most(1)
        .or_zero()
        .cli("lookalike-share"),
    p.lookalike_share);
  f(R("", "lookalike_agreement", "", "Look-alikes: the voters' mean colour agreement").share(),
    p.lookalike_agreement);
  f(R("", "lookalike_shape", "", "Look-alikes: both views' symmetric score at least").share(),
    p.lookalike_shape);
  f(R("", "split_fitness", "", "Split a named candidate whose fitness is under this (0 = never)")
        .share()
        .cli("split-fitness"),
    p.split_fitness);
  f(R("", "merge_distance", "m", "Merge pieces this close when their union scores better (0 = off)")
        .share()
        .cli("merge-distance"),
    p.merge_distance);
  f(R("", "merge_unnamed", "", "Merge also two unnamed pieces whose best views show one object"),
    p.merge_unnamed);
  f(R("", "min_part_points", "", "Fewest points of each part of a split").at_least(1),
    p.min_part_points);
  f(R("", "free_space_tolerance", "m",
      "Scenes: a model this far in front of the measured depth scores less (0 = off)")
        .at_least(0)
        .cli("free-space"),
    p.free_space_tolerance);
  f(R("", "seed", "", "Seed of the RANSAC samples").cli("seed"), p.seed);
  f(R("", "threads", "", "Worker threads, 0 = all cores; the answer does not depend on it")
        .in(0, 1024),
    p.threads);
}

}  // namespace proxseg::detail
