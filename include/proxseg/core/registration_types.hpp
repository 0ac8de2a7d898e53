// The plain data of registration [paper 3.4, Algorithm 2]: how clouds are described, the
// options of an alignment, a described cloud and an alignment's result. The functions that make
// and compare them are in the recognition library (proxseg/recognition/registration.hpp), the
// only part of proxseg that needs Open3D; segmentation and file I/O use these types alone.
#pragma once
#include <proxseg/core/frame.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace proxseg {

// How clouds are described. Fixed per model database: a candidate must be described exactly as
// the views it is compared with, so these live in the database index.
struct DescriptorParams {
  double voxel_size = 0.005;  // voxel-grid filter before everything else [3.4], metres
  double normal_radius = 0.01;
  // FPFH support radii (the paper lists several per run, 3-50 mm). Each radius gives 33 bins;
  // how they combine is RegistrationParams::multi_radius (docs/method.md, "Recognition").
  std::vector<double> fpfh_radii = {0.015, 0.03};
};

enum class MultiRadius {
  kConcatenate,  // one descriptor of 33 x radii bins, one RANSAC
  kBestOf,       // one RANSAC per radius, the best of them goes on to ICP
};
// The names of its values, in its order: how the CLI, JSON configs and Python spell them.
inline std::vector<std::string> value_names(MultiRadius) {
  return {"concatenate", "best_of"};
}

// How the colour term compares the candidate's colours with the aligned view's [extension,
// docs/method.md "Colour in recognition"].
enum class ColourCompare {
  kPoints,     // each explained candidate point with the view point that explains it
  kHistogram,  // the chromaticity distributions of the explained candidate points and of the
               // view points the candidate explains: which colours in which shares, wherever
               // they are, so that a round object turned about its axis still agrees
  kBest,       // the larger of the two
};
// The names of its values, in its order: how the CLI, JSON configs and Python spell them.
inline std::vector<std::string> value_names(ColourCompare) {
  return {"points", "histogram", "best"};
}

struct RegistrationParams {
  MultiRadius multi_radius = MultiRadius::kConcatenate;
  int ransac_iterations = 1000;      // hypotheses that pass the edge test (paper: 100 / 200)
  double ransac_distance = 0.01;     // inlier distance of a correspondence under a hypothesis
  double edge_similarity = 0.9;      // sample pre-rejection: edge-length ratio between the clouds
  double normal_tolerance_deg = 15;  // sample pre-rejection: angles of the point-pair feature
  int ransac_candidates = 45;        // best distinct hypotheses re-judged by their true overlap
  bool mutual_filter = false;        // keep only mutually nearest feature pairs
  // Candidate points used for matching, RANSAC and ICP (evenly sampled; fitness and coverage
  // use all of them). Matching costs candidate x view points per view.
  int max_points = 300;
  int icp_iterations = 30;         // upper bound; stops earlier when converged (paper: 100-200)
  int icp_starts = 3;              // ICP runs from the best this many RANSAC hypotheses
  double icp_distance = 0.015;     // ICP correspondences farther than this are ignored
  bool point_to_plane = false;     // the paper's ICP is point-to-point
  double fitness_distance = 0.01;  // delta_th of eq. 4 (a distance, not a squared distance)
  // The ranking score's distance (recognition.hpp, Score::kSymmetric): tighter than delta_th, so
  // that a box face is not explained by the flat top of a can of about the same size.
  double score_distance = 0.005;
  // A real sensor's error grows with range [extension, docs/method.md "Real sensors"]: > 0 scores
  // a candidate at range r with max(score_distance, score_distance_slope x r). Off: on the real
  // scenes the wider distance let distant clutter fit thin models (docs/method.md, "Real
  // sensors", has the figures).
  double score_distance_slope = 0;
  // Weight of the visible view points that fall outside the candidate's silhouette in the
  // coverage that ranks the views (Alignment::occluded_coverage) [extension, docs/method.md "A
  // database that scales"]: an occlusion removes a region of the object that its model still
  // predicts, and nothing in a candidate tells that region hidden from absent. The score that
  // the minimum score, the margin and the confident score judge keeps every visible point
  // (Alignment::coverage). 1 = no allowance (the ranking before).
  double coverage_outside_weight = 0.5;
  ColourCompare colour_compare = ColourCompare::kPoints;
  // Colour during alignment [extension]: the RANSAC hypotheses and the ICP starts are ranked by
  // their overlap x the colour agreement of the explained points (when both clouds have colour),
  // so that among the poses a symmetric shape allows (a box turned over, a can turned about its
  // axis) the one whose colours agree is kept.
  bool colour_alignment = true;
  // > 0: the point colour agreement also compares brightness, as a Gaussian of the log of the
  // two brightnesses' ratio with this sigma (wide: shading and exposure change brightness, but
  // a black object is not a white one, while their chromaticities agree). 1.1 = ln 3: a factor
  // of 2 keeps 0.82, a factor of 5 0.28 (docs/method.md "Recognition that generalises"). 0 =
  // chromaticity only.
  double brightness_sigma = 1.1;
};

// A cloud's summary, compared before any registration to shortlist the database views worth
// aligning [extension, docs/method.md "A database that scales"]: cheap to compare, and about the
// same for two views of one object from nearby directions.
struct Signature {
  Eigen::VectorXf shape;   // mean FPFH over the points, each radius block normalised to sum 1
  Eigen::VectorXf colour;  // chromaticity histogram, sums to 1; empty when the cloud has no colour
  double spread = 0;       // root mean square distance of the points to their centroid, metres
  // The same for parts of the cloud: the cloud without the points nearest to one of several
  // centres, as an occlusion would leave it (add_part_signatures()); their own parts empty.
  // Database views only: a candidate is compared with them, not they with it.
  std::vector<Signature> parts;
};
// Several signatures' sketches (sketch_of(), registration.hpp) as a database view keeps its
// parts' in memory: 16 bits per bin (the bin's value x 65535, rounded; every bin lies in [0, 1])
// and the spread.
struct SketchSet {
  Eigen::Matrix<std::uint16_t, Eigen::Dynamic, Eigen::Dynamic> bins;  // one column per signature
  Eigen::VectorXf spreads;
  Eigen::Index size() const { return spreads.size(); }
};

// A cloud ready for registration: voxel-filtered points in its own frame, normals oriented to
// its viewpoint, FPFH features (one column per point) and search indexes.
struct SearchIndex;  // point grid and feature matrices (src/recognition/search_index.hpp)
struct Cloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
  Eigen::MatrixXd features;  // (33 * radii) x points
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();  // the sensor, in the cloud's frame
  double spacing = 0;                                   // median nearest-neighbour distance
  // Per point colour (the voxel means), empty when the cloud has none (an XYZ-only scan or
  // model); recognition then judges geometry alone.
  std::vector<Rgb> colours;
  Signature signature;
  std::shared_ptr<const SearchIndex> index;
  std::size_t size() const { return points.size(); }
};

// The result of aligning one model view to one candidate.
// How a posed model stands on the scene's support plane (stance(), support.hpp).
enum class Stance {
  kStands,  // on the plane or on another object, or not judged
  kFloats,  // over the plane with nothing under it
  kSinks,   // through the plane
};

struct Alignment {
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  // candidate frame <- model frame
  double fitness = 0;        // eq. 5: share of candidate points within delta_th of the aligned view
  double close_fitness = 0;  // the same within score_distance
  double coverage = 0;       // share of the view's points visible from the candidate's viewpoint
                             // that have a candidate point within score_distance (model-side term)
  // The same with the visible view points outside the candidate's silhouette weighed by
  // coverage_outside_weight: allowing for an occlusion, for ranking the views.
  double occluded_coverage = 0;
  double rmse = 0;  // of the fitness inliers
  // Colour agreement of the close_fitness inliers with the view points that explain them, in
  // [0, 1] (colour_agreement()); 1 and coloured = false when either cloud has no colour.
  double colour = 1;
  bool coloured = false;
  // Share of the posed view's sensor-facing points that lie in front of what the sensor saw
  // (free_space_violation(), visibility.hpp); 0 when recognition has no depth image.
  double free_space = 0;
  // The share of the candidate's points at the image border that this view does not explain
  // (border_unexplained(), visibility.hpp); 0 when recognition has no depth image.
  double border_unexplained = 0;
  // Share of the view's visible points outside the candidate's silhouette that the frame hides
  // (something measured nearer, or no return there): left out of coverage and occluded_coverage
  // (coverage_counts() with a scene); 0 when recognition has no depth image.
  double hidden = 0;
  // Whether the posed model stands on the support plane or on another object, and the height of
  // its lowest point over the plane (stance(), support.hpp); kStands and NaN without a support.
  Stance stance = Stance::kStands;
  double bottom = std::numeric_limits<double>::quiet_NaN();
  int correspondences = 0, ransac_inliers = 0, icp_iterations = 0;
  double ransac_ms = 0, icp_ms = 0, score_ms = 0;
};

}  // namespace proxseg
