// Registration [paper 3.4, Algorithm 2]: align a model view to a candidate object (centroid
// shift, FPFH, RANSAC on feature correspondences, ICP) and score the alignment (eq. 4-5).
#pragma once
#include <proxseg/core/frame.hpp>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
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

// How the colour term compares the candidate's colours with the aligned view's [extension,
// docs/method.md "Colour in recognition"].
enum class ColourCompare {
  kPoints,     // each explained candidate point with the view point that explains it
  kHistogram,  // the chromaticity distributions of the explained candidate points and of the
               // view points the candidate explains: which colours in which shares, wherever
               // they are, so that a round object turned about its axis still agrees
  kBest,       // the larger of the two
};

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
  int icp_starts = 2;              // ICP runs from the best this many RANSAC hypotheses
  double icp_distance = 0.015;     // ICP correspondences farther than this are ignored
  bool point_to_plane = false;     // the paper's ICP is point-to-point
  double fitness_distance = 0.01;  // delta_th of eq. 4 (a distance, not a squared distance)
  // The ranking score's distance (recognition.hpp, Score::kSymmetric): tighter than delta_th, so
  // that a box face is not explained by the flat top of a can of about the same size.
  double score_distance = 0.005;
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
// Distance of two signatures: the L1 distances of the shape and colour histograms (each in
// [0, 1]; the colour term is left out when either has no colour) plus |log| of the spreads'
// ratio. 0 for equal signatures.
double signature_distance(const Signature& a, const Signature& b);
// How far a candidate is from a database view for the shortlist: the least signature_distance()
// to the view's signature or to one of its parts, so that a partly hidden object is near the
// views it is part of.
double view_distance(const Signature& candidate, const Signature& view);

// A cloud ready for registration: voxel-filtered points in its own frame, normals oriented to
// its viewpoint, FPFH features (one column per point) and search indexes.
struct SearchIndex;  // point grid and feature matrices (src/registration.cpp)
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

// The deterministic voxel-grid filter: one point (the mean) per occupied cell, in cell order;
// non-finite points are dropped. With colours, out_colours gets each cell's mean colour.
std::vector<Eigen::Vector3d> voxel_filter(const std::vector<Eigen::Vector3d>& points,
                                          double voxel_size,
                                          const std::vector<Rgb>* colours = nullptr,
                                          std::vector<Rgb>* out_colours = nullptr);
// Filters, then describe_filtered(). With colours (one per point), the cloud keeps each voxel's
// mean colour.
Cloud describe(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& viewpoint,
               const DescriptorParams& params, const std::vector<Rgb>* colours = nullptr);
// Estimates normals (oriented towards viewpoint; away from the centroid when the viewpoint is not
// finite, for full models), computes FPFH and builds the indexes. The database stores points,
// normals and features as floats, so a cloud restored from it equals this one to float precision.
// Throws InputError when there are fewer than 10 points. colours: one per point, or empty.
Cloud describe_filtered(const std::vector<Eigen::Vector3d>& points,
                        const Eigen::Vector3d& viewpoint, const DescriptorParams& params,
                        std::vector<Rgb> colours = {});
// Rebuilds a described cloud from stored points, normals and features (database cache).
Cloud restore(std::vector<Eigen::Vector3d> points, std::vector<Eigen::Vector3d> normals,
              Eigen::MatrixXd features, const Eigen::Vector3d& viewpoint,
              std::vector<Rgb> colours = {});
// Fills the view's Signature::parts: 24 parts, each the view without the 15, 30 or 45 % of its
// points nearest to one of 8 centres spread over it (farthest-point sampling); none for a view of
// under 16 points. What a view needs to enter a database (io add_view() and load_database(),
// captured_database(), rec_eval's databases call it); describe() and restore() leave parts empty.
void add_part_signatures(Cloud& view);

// The result of aligning one model view to one candidate.
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
  int correspondences = 0, ransac_inliers = 0, icp_iterations = 0;
  double ransac_ms = 0, icp_ms = 0, score_ms = 0;
};

// Algorithm 2 for one (candidate, view) pair; `seed` drives the RANSAC samples, so the result
// depends only on the inputs and the seed.
Alignment align(const Cloud& candidate, const Cloud& view, const RegistrationParams& params,
                std::uint64_t seed);
// The same with the candidate's sample (subsample(candidate, params.max_points)) made once by
// the caller, when one candidate meets many views.
Alignment align(const Cloud& candidate, const Cloud& sample, const Cloud& view,
                const RegistrationParams& params, std::uint64_t seed);
// At most max_points points of the cloud, evenly spaced in its order (the cloud itself if it
// has no more; max_points <= 0: all).
Cloud subsample(const Cloud& cloud, int max_points);

// The symmetric overlap of a pose: sqrt(fitness x coverage), high only when the view explains
// the candidate and the candidate explains the visible view. One rule ranks RANSAC hypotheses
// (within ransac_distance), ICP starts and views (Score::kSymmetric, within score_distance).
inline double symmetric_overlap(double fitness, double coverage) {
  return std::sqrt(fitness * coverage);
}

// The scores of a given pose (candidate <- model): fitness (eq. 5), close_fitness, coverage,
// occluded_coverage and rmse, as align() scores its own result (used to judge other
// registrations the same way).
Alignment score_pose(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose,
                     const RegistrationParams& params);

// Eq. 4-5 and the model-side term for a given pose (candidate <- model).
double fitness(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose, double delta,
               double* rmse = nullptr);
// coverage()'s counts: of the posed view's points visible from the candidate's viewpoint, those
// inside and outside the candidate's silhouette (the coverage grid's cells that hold a candidate
// point), and those with a candidate point within delta.
struct CoverageCounts {
  int inside = 0, outside = 0, explained = 0;
};
CoverageCounts coverage_counts(const Cloud& candidate, const Cloud& view,
                               const Eigen::Matrix4d& pose, double delta);
// explained / (inside + outside_weight x outside), at most 1; outside_weight 1 (the model-side
// term of the score as it was) needs no silhouette.
double coverage(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose,
                double delta, double outside_weight = 1);
// The colour term [extension, docs/method.md "Colour in recognition"]: the mean agreement, over
// the candidate points within delta of the posed view, of their chromaticity with that of the
// nearest view point (chromaticity_agreement()); 1 when either cloud has no colour.
double colour_agreement(const Cloud& candidate, const Cloud& view, const Eigen::Matrix4d& pose,
                        double delta);
// Agreement of two colours in [0, 1]: a Gaussian of the distance between their chromaticities
// (rgb / (r + g + b)), wider for dark colours, whose chromaticity is mostly sensor noise.
// Chromaticity ignores brightness, so shading and exposure differences between the database and
// the scene do not count, while hue and saturation do.
double chromaticity_agreement(const Rgb& a, const Rgb& b);
// chromaticity_agreement() times, when brightness_sigma > 0, a Gaussian of the log of the two
// brightnesses' ratio with that sigma (RegistrationParams::brightness_sigma): how well one
// candidate point's colour agrees with the view point that explains it.
double point_colour_agreement(const Rgb& a, const Rgb& b, double brightness_sigma);
// Per candidate point: the nearest point of the view put in place by pose (candidate <- model)
// within delta, -1 when there is none.
std::vector<int> nearest_view_points(const Cloud& candidate, const Cloud& view,
                                     const Eigen::Matrix4d& pose, double delta);
// Agreement of two colour distributions in [0, 1]: the Bhattacharyya coefficient of their
// chromaticity histograms, each colour spread over the cells as chromaticity_agreement() would
// blur it (wider for dark colours), to the 4th power, which puts two single colours on
// chromaticity_agreement()'s scale. 1 for equal distributions; 0 when either is empty.
double chromaticity_histogram_agreement(const std::vector<Rgb>& a, const std::vector<Rgb>& b);

// Per point (sensor frame): whether the view, put in place by pose (candidate <- model), has a
// point within delta of it; the points that eq. 4 counts as explained.
std::vector<char> explained(const std::vector<Eigen::Vector3d>& points, const Cloud& view,
                            const Eigen::Matrix4d& pose, double delta);

}  // namespace proxseg
