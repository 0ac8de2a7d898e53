// The parameter table (parameters.hpp). Every parameter of SegmentParams and RecognitionParams is
// one line of segment_fields() or recognition_fields(): the row (name, unit, help, range, flag)
// and the member it describes. Type, default and the paper preset's value are read from the
// member itself, so that they cannot disagree with the structs.
#include <proxseg/core/parameters.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>
#include <type_traits>

namespace proxseg {
namespace {

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

template <class T>
constexpr bool kIsEnum = std::is_enum_v<T>;

template <class T>
ParamType type_of() {
  if constexpr (std::is_same_v<T, bool>) return ParamType::kBool;
  if constexpr (std::is_same_v<T, int>) return ParamType::kInt;
  if constexpr (std::is_same_v<T, std::uint64_t>) return ParamType::kUnsigned;
  if constexpr (std::is_same_v<T, double>) return ParamType::kReal;
  return ParamType::kChoice;
}

template <class T>
ParamValue value_of(const T& v) {
  if constexpr (kIsEnum<T>)
    return std::string(Names<T>::v[static_cast<int>(v)]);
  else
    return v;
}

std::string type_expected(const Parameter& row) {
  switch (row.type) {
    case ParamType::kBool:
      return "true or false";
    case ParamType::kInt:
      return "an integer";
    case ParamType::kUnsigned:
      return "a non-negative integer";
    case ParamType::kReal:
      return "a number";
    case ParamType::kChoice:
      break;
  }
  std::string s;
  for (std::size_t i = 0; i < row.choices.size(); ++i)
    s += (i == 0                        ? ""
          : i + 1 == row.choices.size() ? " or "
                                        : ", ") +
         ("\"" + row.choices[i] + "\"");
  return s;
}

[[noreturn]] void wrong_value(const Parameter& row, const ParamValue& value) {
  std::string got = format_parameter(value);
  if (std::holds_alternative<std::string>(value)) got = "\"" + got + "\"";
  throw InputError("field " + row.key() + ": expected " + type_expected(row) + ", got " + got);
}

template <class T>
void assign(const Parameter& row, T& out, const ParamValue& value) {
  if constexpr (std::is_same_v<T, bool>) {
    if (!std::holds_alternative<bool>(value)) wrong_value(row, value);
    out = std::get<bool>(value);
  } else if constexpr (std::is_same_v<T, int>) {
    long long v = 0;
    if (const int* i = std::get_if<int>(&value))
      v = *i;
    else if (const std::uint64_t* u = std::get_if<std::uint64_t>(&value); u && *u <= 1u << 30)
      v = static_cast<long long>(*u);
    else
      wrong_value(row, value);
    out = static_cast<int>(v);
  } else if constexpr (std::is_same_v<T, std::uint64_t>) {
    if (const std::uint64_t* u = std::get_if<std::uint64_t>(&value))
      out = *u;
    else if (const int* i = std::get_if<int>(&value); i && *i >= 0)
      out = static_cast<std::uint64_t>(*i);
    else
      wrong_value(row, value);
  } else if constexpr (std::is_same_v<T, double>) {
    if (const double* d = std::get_if<double>(&value))
      out = *d;
    else if (const int* i = std::get_if<int>(&value))
      out = *i;
    else if (const std::uint64_t* u = std::get_if<std::uint64_t>(&value))
      out = static_cast<double>(*u);
    else
      wrong_value(row, value);
  } else {
    const std::string* s = std::get_if<std::string>(&value);
    if (!s) wrong_value(row, value);
    const auto& names = Names<T>::v;
    const auto* it =
        std::find_if(std::begin(names), std::end(names), [&](const char* n) { return *s == n; });
    if (it == std::end(names)) wrong_value(row, value);
    out = static_cast<T>(it - std::begin(names));
  }
}

// The rows of fields(params), with type and default from params and the paper's value from
// paper (when given).
template <class P, class Fields>
std::vector<Parameter> make_table(Fields fields, const P* paper) {
  std::vector<Parameter> table;
  P defaults{};
  fields(defaults, [&](const Row& r, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    Parameter row;
    row.section = r.section;
    row.name = r.name;
    row.type = type_of<T>();
    if constexpr (kIsEnum<T>) row.choices.assign(std::begin(Names<T>::v), std::end(Names<T>::v));
    row.min = r.min;
    row.max = r.max;
    row.min_open = r.min_open;
    row.max_open = r.max_open;
    row.zero_off = r.zero_off;
    if constexpr (std::is_same_v<T, std::uint64_t>) row.min = 0;
    row.unit = r.unit;
    row.help = r.help;
    row.flag = r.flag;
    if (*r.alias) row.aliases.push_back(r.alias);
    row.default_value = value_of(value);
    row.paper = r.paper;
    table.push_back(std::move(row));
  });
  if (paper) {
    std::size_t i = 0;
    P copy = *paper;
    fields(copy, [&](const Row& r, const auto& value) {
      if (r.paper_preset) table[i].paper = format_parameter(value_of(value));
      ++i;
    });
  }
  return table;
}

const auto kSegmentFields = [](auto& p, auto&& f) { segment_fields(p, f); };
const auto kRecognitionFields = [](auto& p, auto&& f) { recognition_fields(p, f); };

std::pair<std::string, std::string> split_key(const Parameter& row) {
  return {row.section, row.name};
}

template <class P, class Fields>
ParamValue get_with(const std::vector<Parameter>& table, const P& params, const std::string& key,
                    Fields fields) {
  const auto [section, name] = split_key(require_parameter(table, key));
  ParamValue out;
  P& p = const_cast<P&>(params);  // fields() takes members by reference; nothing is written
  fields(p, [&](const Row& r, const auto& value) {
    if (r.is(section.c_str(), name.c_str())) out = value_of(value);
  });
  return out;
}

template <class P, class Fields>
void set_with(const std::vector<Parameter>& table, P& params, const std::string& key,
              const ParamValue& value, Fields fields) {
  const Parameter& row = require_parameter(table, key);
  fields(params, [&](const Row& r, auto& member) {
    if (r.is(row.section.c_str(), row.name.c_str())) assign(row, member, value);
  });
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string number_text(double v) {
  std::ostringstream s;
  s.precision(15);
  s << v;
  return s.str();
}

}  // namespace

std::string Parameter::key() const {
  return section.empty() ? name : section + "." + name;
}

std::string Parameter::type_name() const {
  switch (type) {
    case ParamType::kBool:
      return "bool";
    case ParamType::kInt:
      return "int";
    case ParamType::kUnsigned:
      return "uint64";
    case ParamType::kReal:
      return "real";
    case ParamType::kChoice:
      return "choice";
  }
  return "";
}

std::string Parameter::range_text() const {
  if (type == ParamType::kBool) return "true | false";
  if (type == ParamType::kChoice) {
    std::string s;
    for (const std::string& c : choices) s += (s.empty() ? "" : " | ") + c;
    return s;
  }
  const std::string u = unit.empty() ? "" : " " + unit;
  std::string s;
  const bool low = std::isfinite(min), high = std::isfinite(max);
  if (low && high && !min_open && !max_open && (min != 0 || max != 1 || !unit.empty()))
    s = number_text(min) + " .. " + number_text(max) + u;
  else if (low && high)
    s = std::string("in ") + (min_open ? "(" : "[") + number_text(min) + ", " + number_text(max) +
        (max_open ? ")" : "]") + u;
  else if (low)
    s = (min_open ? "> " : ">= ") + number_text(min) + u;
  else if (high)
    s = (max_open ? "< " : "<= ") + number_text(max) + u;
  else
    s = "any";
  return zero_off ? "0 (off) or " + s : s;
}

const std::vector<Parameter>& segment_parameters() {
  static const std::vector<Parameter> table = [] {
    const SegmentParams paper = preset("paper");
    return make_table<SegmentParams>(kSegmentFields, &paper);
  }();
  return table;
}

const std::vector<Parameter>& recognition_parameters() {
  static const std::vector<Parameter> table =
      make_table<RecognitionParams>(kRecognitionFields, nullptr);
  return table;
}

const Parameter* find_parameter(const std::vector<Parameter>& table, const std::string& key) {
  const Parameter* bare = nullptr;
  int bare_count = 0;
  for (const Parameter& row : table) {
    if (row.key() == key) return &row;
    if (row.name == key) bare = &row, ++bare_count;
  }
  return bare_count == 1 ? bare : nullptr;
}

const Parameter& require_parameter(const std::vector<Parameter>& table, const std::string& key) {
  if (const Parameter* row = find_parameter(table, key)) return *row;
  std::string owners;
  for (const Parameter& row : table)
    if (row.name == key) owners += (owners.empty() ? "" : ", ") + row.key();
  if (!owners.empty())
    throw InputError("parameter " + key + " is in several sections: give one of " + owners);
  const std::string near = nearest_parameter(table, key);
  throw InputError("unknown parameter " + key +
                   (near.empty() ? "" : " (did you mean " + near + "?)"));
}

std::string nearest_parameter(const std::vector<Parameter>& table, const std::string& key) {
  std::vector<std::string> keys;
  for (const Parameter& row : table) keys.push_back(row.key());
  if (std::string near = closest_name(key, keys); !near.empty()) return near;
  // The name in the wrong section ("mrf.voxel_size"), or at the top level without its section.
  const std::string bare = key.substr(key.rfind('.') == std::string::npos ? 0 : key.rfind('.') + 1);
  for (const Parameter& row : table)
    if (row.name == bare) return row.key();
  return "";
}

ParamValue get_parameter(const SegmentParams& params, const std::string& key) {
  return get_with(segment_parameters(), params, key, kSegmentFields);
}
ParamValue get_parameter(const RecognitionParams& params, const std::string& key) {
  return get_with(recognition_parameters(), params, key, kRecognitionFields);
}
void set_parameter(SegmentParams& params, const std::string& key, const ParamValue& value) {
  set_with(segment_parameters(), params, key, value, kSegmentFields);
}
void set_parameter(RecognitionParams& params, const std::string& key, const ParamValue& value) {
  set_with(recognition_parameters(), params, key, value, kRecognitionFields);
}

std::string format_parameter(const ParamValue& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>)
          return v ? "true" : "false";
        else if constexpr (std::is_same_v<T, std::string>)
          return v;
        else if constexpr (std::is_same_v<T, double>)
          return number_text(v);
        else
          return std::to_string(v);
      },
      value);
}

ParamValue parse_parameter(const Parameter& row, const std::string& text) {
  auto fail = [&]() -> ParamValue {
    throw InputError(row.key() + ": expected " + type_expected(row) + ", got \"" + text + "\"");
  };
  switch (row.type) {
    case ParamType::kBool:
      if (text == "true" || text == "1" || text == "on" || text == "yes") return true;
      if (text == "false" || text == "0" || text == "off" || text == "no") return false;
      return fail();
    case ParamType::kInt:
    case ParamType::kUnsigned: {
      if (text.empty() || (row.type == ParamType::kUnsigned && text[0] == '-')) return fail();
      errno = 0;
      char* end = nullptr;
      if (row.type == ParamType::kUnsigned) {
        const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
        if (errno || *end) return fail();
        return static_cast<std::uint64_t>(v);
      }
      const long long v = std::strtoll(text.c_str(), &end, 10);
      if (errno || *end || v < std::numeric_limits<int>::min() ||
          v > std::numeric_limits<int>::max())
        return fail();
      return static_cast<int>(v);
    }
    case ParamType::kReal: {
      errno = 0;
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (text.empty() || errno || *end || !std::isfinite(v)) return fail();
      return v;
    }
    case ParamType::kChoice:
      if (std::find(row.choices.begin(), row.choices.end(), text) == row.choices.end()) {
        const std::string near = closest_name(text, row.choices);
        throw InputError(row.key() + ": expected " + type_expected(row) + ", got \"" + text + "\"" +
                         (near.empty() ? "" : " (did you mean " + near + "?)"));
      }
      return text;
  }
  return fail();
}

bool in_range(const Parameter& row, const ParamValue& value) {
  if (row.type == ParamType::kBool || row.type == ParamType::kChoice) return true;
  double v = 0;
  if (const int* i = std::get_if<int>(&value)) v = *i;
  if (const std::uint64_t* u = std::get_if<std::uint64_t>(&value)) v = static_cast<double>(*u);
  if (const double* d = std::get_if<double>(&value)) v = *d;
  if (!std::isfinite(v)) return false;
  if (row.zero_off && v == 0) return true;
  const bool low = row.min_open ? v > row.min : v >= row.min;
  const bool high = row.max_open ? v < row.max : v <= row.max;
  return low && high;
}

std::string closest_name(const std::string& name, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (const std::string& c : candidates) {
    const std::size_t d = edit_distance(name, c);
    if (d < best_distance) best_distance = d, best = c;
  }
  // A likely typo: at most a third of the letters, or the one name that contains the other.
  if (best_distance <= std::max<std::size_t>(1, name.size() / 3)) return best;
  for (const std::string& c : candidates)
    if (name.size() >= 4 && c.find(name) != std::string::npos) return c;
  return "";
}

}  // namespace proxseg
