// The recognition peers of bench/peers_rec.hpp: Open3D (RANSAC, FGR) and PCL registration on
// proxseg's clouds. The PPF peer (OpenCV contrib) is in bench/peers_ppf.cpp.
// GCC 12 reports a false -Warray-bounds inside Eigen::umeyama<float> (a 3-vector stored into a
// 4x4 block with a 4-wide packet load), instantiated here by PCL's TransformationEstimationSVD.
#pragma GCC diagnostic ignored "-Warray-bounds"

#include "peers_rec.hpp"

#include <omp.h>

#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/CorrespondenceChecker.h>
#include <open3d/pipelines/registration/FastGlobalRegistration.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/utility/Logging.h>
#include <open3d/utility/Random.h>
#include <pcl/console/print.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/sample_consensus_prerejective.h>
#include <chrono>
#include <cstdlib>
#include <functional>
#include <optional>

namespace proxseg::peers {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

constexpr int kFpfhBins = 33;

namespace o3reg = open3d::pipelines::registration;

struct Open3dCloud {
  open3d::geometry::PointCloud points;
  o3reg::Feature features;
};

Open3dCloud to_open3d(const Cloud& c) {
  Open3dCloud o;
  o.points.points_ = c.points;
  o.points.normals_ = c.normals;
  o.features.data_ = c.features;  // same layout: one column per point
  return o;
}

using PclCloud = pcl::PointCloud<pcl::PointNormal>;
using PclFeatures = pcl::PointCloud<pcl::FPFHSignature33>;

PclCloud::Ptr to_pcl_points(const Cloud& c) {
  auto out = std::make_shared<PclCloud>();
  out->resize(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    pcl::PointNormal& p = (*out)[i];
    p.getVector3fMap() = c.points[i].cast<float>();
    p.getNormalVector3fMap() = c.normals[i].cast<float>();
    p.curvature = 0;
  }
  return out;
}

PclFeatures::Ptr to_pcl_features(const Cloud& c) {
  auto out = std::make_shared<PclFeatures>();
  out->resize(c.size());
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int b = 0; b < kFpfhBins; ++b)
      (*out)[i].histogram[b] = static_cast<float>(c.features(b, static_cast<Eigen::Index>(i)));
  return out;
}

}  // namespace

// --- Open3D and Open3D FGR ---------------------------------------------------------------------

namespace {

// The database's views as Open3D clouds, for both Open3D peers.
std::vector<Open3dCloud> open3d_views(const Database& db) {
  // Open3D warns on stdout; the benchmark's stdout is its table.
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
  std::vector<Open3dCloud> views;
  for (const ModelView& v : db.views) views.push_back(to_open3d(v.cloud()));
  return views;
}

// Every view aligned to the target: `coarse(view)` gives the first pose (none: no hypothesis),
// timed as the coarse stage, then point-to-point ICP refines it.
template <class Coarse>
std::vector<PeerAlignment> align_views(const std::vector<Open3dCloud>& views,
                                       const Open3dCloud& target, int threads, double icp_distance,
                                       int icp_iterations, const Coarse& coarse) {
  const int n = static_cast<int>(views.size());
  std::vector<PeerAlignment> out(n);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int v = 0; v < n; ++v) {
    const Open3dCloud& source = views[v];
    auto t0 = Clock::now();
    const std::optional<Eigen::Matrix4d> first = coarse(source);
    out[v].ransac_ms = ms_since(t0);
    out[v].found = first.has_value();
    if (!out[v].found) continue;
    t0 = Clock::now();
    const o3reg::RegistrationResult fine =
        o3reg::RegistrationICP(source.points, target.points, icp_distance, *first,
                               o3reg::TransformationEstimationPointToPoint(false),
                               o3reg::ICPConvergenceCriteria(1e-6, 1e-6, icp_iterations));
    out[v].icp_ms = ms_since(t0);
    out[v].pose = fine.transformation_;
  }
  return out;
}

}  // namespace

struct Open3dPeer::Impl {
  Open3dParams params;
  int threads = 0;
  std::vector<Open3dCloud> views;
};

Open3dPeer::Open3dPeer(const Database& db, const Open3dParams& params, int threads)
    : impl_(std::make_unique<Impl>()) {
  impl_->params = params;
  impl_->threads = threads > 0 ? threads : omp_get_max_threads();
  impl_->views = open3d_views(db);
}

Open3dPeer::~Open3dPeer() = default;

std::vector<PeerAlignment> Open3dPeer::align(const Cloud& candidate, int seed) const {
  const Open3dParams& p = impl_->params;
  open3d::utility::random::Seed(seed);
  const Open3dCloud target = to_open3d(candidate);
  const o3reg::CorrespondenceCheckerBasedOnEdgeLength edge(p.edge_length_similarity);
  const o3reg::CorrespondenceCheckerBasedOnDistance distance(p.checker_distance);
  const std::vector<std::reference_wrapper<const o3reg::CorrespondenceChecker>> checkers = {
      edge, distance};
  const auto ransac = [&](const Open3dCloud& source) -> std::optional<Eigen::Matrix4d> {
    const o3reg::RegistrationResult coarse = o3reg::RegistrationRANSACBasedOnFeatureMatching(
        source.points, target.points, source.features, target.features, false,
        p.max_correspondence_distance, o3reg::TransformationEstimationPointToPoint(false), 3,
        checkers, o3reg::RANSACConvergenceCriteria(p.ransac_iterations, p.ransac_confidence));
    // Open3D returns the identity with fitness 0 when no hypothesis passed the checkers.
    if (!(coarse.fitness_ > 0)) return std::nullopt;
    return coarse.transformation_;
  };
  return align_views(impl_->views, target, impl_->threads, p.icp_distance, p.icp_iterations,
                     ransac);
}

struct FgrPeer::Impl {
  FgrParams params;
  int threads = 0;
  std::vector<Open3dCloud> views;
};

FgrPeer::FgrPeer(const Database& db, const FgrParams& params, int threads)
    : impl_(std::make_unique<Impl>()) {
  impl_->params = params;
  impl_->threads = threads > 0 ? threads : omp_get_max_threads();
  impl_->views = open3d_views(db);
}

FgrPeer::~FgrPeer() = default;

std::vector<PeerAlignment> FgrPeer::align(const Cloud& candidate, int seed) const {
  const FgrParams& p = impl_->params;
  open3d::utility::random::Seed(seed);
  const Open3dCloud target = to_open3d(candidate);
  const o3reg::FastGlobalRegistrationOption option(p.division_factor, false, true,
                                                   p.max_correspondence_distance, p.iterations,
                                                   p.tuple_scale, p.max_tuples);
  const auto fgr = [&](const Open3dCloud& source) -> std::optional<Eigen::Matrix4d> {
    o3reg::RegistrationResult coarse;
    // Open3D 0.16's feature matching is an orphaned `omp for`: inside the views' loop it would
    // bind to that team and match only this thread's share of the points. A team of one gives it
    // all.
#pragma omp parallel num_threads(1)
    coarse = o3reg::FastGlobalRegistrationBasedOnFeatureMatching(
        source.points, target.points, source.features, target.features, option);
    // FGR always returns a pose (with fewer than 10 matches, the one that aligns the centroids);
    // ICP starts from it and the score judges the result.
    return coarse.transformation_;
  };
  return align_views(impl_->views, target, impl_->threads, p.icp_distance, p.icp_iterations, fgr);
}

// --- PCL ----------------------------------------------------------------------------------------

struct PclPeer::Impl {
  PclParams params;
  int threads = 0;
  std::vector<PclCloud::Ptr> points;
  std::vector<PclFeatures::Ptr> features;
};

PclPeer::PclPeer(const Database& db, const PclParams& params, int threads)
    : impl_(std::make_unique<Impl>()) {
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  impl_->params = params;
  impl_->threads = threads > 0 ? threads : omp_get_max_threads();
  for (const ModelView& v : db.views) {
    impl_->points.push_back(to_pcl_points(v.cloud()));
    impl_->features.push_back(to_pcl_features(v.cloud()));
  }
}

PclPeer::~PclPeer() = default;

std::vector<PeerAlignment> PclPeer::align(const Cloud& candidate, int seed) const {
  const PclParams& p = impl_->params;
  std::srand(static_cast<unsigned>(seed));
  const PclCloud::Ptr target = to_pcl_points(candidate);
  const PclFeatures::Ptr target_features = to_pcl_features(candidate);
  const int n = static_cast<int>(impl_->points.size());
  std::vector<PeerAlignment> out(n);
#pragma omp parallel num_threads(impl_->threads)
  {
    // One aligner per thread with the candidate as its fixed target: PCL builds the target's
    // point and feature trees on the first align() and keeps them while the target is unchanged.
    pcl::SampleConsensusPrerejective<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33>
        ransac;
    ransac.setInputTarget(target);
    ransac.setTargetFeatures(target_features);
    ransac.setMaximumIterations(p.ransac_iterations);
    ransac.setNumberOfSamples(p.samples);
    ransac.setCorrespondenceRandomness(p.correspondence_randomness);
    ransac.setSimilarityThreshold(p.similarity_threshold);
    ransac.setMaxCorrespondenceDistance(p.max_correspondence_distance);
    ransac.setInlierFraction(p.inlier_fraction);
    pcl::IterativeClosestPoint<pcl::PointNormal, pcl::PointNormal> icp;
    icp.setInputTarget(target);
    icp.setMaximumIterations(p.icp_iterations);
    icp.setMaxCorrespondenceDistance(p.icp_distance);
    PclCloud aligned;
#pragma omp for schedule(dynamic, 1)
    for (int v = 0; v < n; ++v) {
      auto t0 = Clock::now();
      ransac.setInputSource(impl_->points[v]);
      ransac.setSourceFeatures(impl_->features[v]);
      ransac.align(aligned);
      out[v].ransac_ms = ms_since(t0);
      // Without a hypothesis over the inlier fraction PCL reports the identity guess.
      out[v].found = ransac.hasConverged();
      if (!out[v].found) continue;
      const Eigen::Matrix4f coarse = ransac.getFinalTransformation();
      t0 = Clock::now();
      icp.setInputSource(impl_->points[v]);
      icp.align(aligned, coarse);
      out[v].icp_ms = ms_since(t0);
      // ICP reports no convergence when it ran out of correspondences: keep the coarse pose.
      out[v].pose = (icp.hasConverged() ? icp.getFinalTransformation() : coarse).cast<double>();
    }
  }
  return out;
}

}  // namespace proxseg::peers
