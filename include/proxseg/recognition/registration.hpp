// Registration [paper 3.4, Algorithm 2]: align a model view to a candidate object (centroid
// shift, FPFH, RANSAC on feature correspondences, ICP) and score the alignment (eq. 4-5).
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/registration_types.hpp>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

namespace proxseg {

// Distance of two signatures: the L1 distances of the shape and colour histograms (each in
// [0, 1]; the colour term is left out when either has no colour) plus |log| of the spreads'
// ratio. 0 for equal signatures.
double signature_distance(const Signature& a, const Signature& b);
// How far a candidate is from a database view for the shortlist: the least signature_distance()
// to the view's signature or to one of its parts, so that a partly hidden object is near the
// views it is part of.
double view_distance(const Signature& candidate, const Signature& view);

// A signature's sketch: its shape histogram with neighbouring bins summed in pairs (within each
// 11-bin FPFH sub-histogram), its colour histogram over 4 x 4 cells instead of 8 x 8, then its
// spread. An L1 distance only shrinks when bins are summed, so sketch_distance() from a
// candidate's sketch to a signature's (kept quantised, SketchSet) is at most signature_distance()
// of the signatures: a bound that lets the shortlist skip reading the parts of most views
// [docs/database.md]. shape_bins: the signatures' shape histogram size; coloured: whether the
// candidate and the set's signatures have colour histograms.
Eigen::VectorXf sketch_of(const Signature& s);
SketchSet sketch_set(const std::vector<Signature>& signatures);
double sketch_distance(const Eigen::VectorXf& candidate, const SketchSet& set, Eigen::Index k,
                       Eigen::Index shape_bins, bool candidate_coloured, bool set_coloured);

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
// under 16 points. What a view needs to enter a database (make_model_view(), model_view.hpp,
// calls it for add_view(), db upgrade and the evaluation's databases; a stored view's parts are
// read from its file); describe() and restore() leave parts empty.
void add_part_signatures(Cloud& view);

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
  int hidden = 0;  // outside points the scene hides (with a scene only; in neither count above)
};
CoverageCounts coverage_counts(const Cloud& candidate, const Cloud& view,
                               const Eigen::Matrix4d& pose, double delta);
struct DepthImage;  // visibility.hpp
// The same with the frame's depths (candidate in the sensor frame): a visible point outside the
// candidate's silhouette where the sensor measured a surface more than tolerance + 0.005 z^2
// nearer (an occluder) or nothing (no return) is hidden, counted in `hidden` only: the model
// may well be there, unseen [extension, docs/method.md "Real sensors"].
CoverageCounts coverage_counts(const Cloud& candidate, const Cloud& view,
                               const Eigen::Matrix4d& pose, double delta, const DepthImage& scene,
                               double tolerance);
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
