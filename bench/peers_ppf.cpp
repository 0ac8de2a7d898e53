// The OpenCV point-pair-feature peer of bench/peers_rec.hpp (PpfPeer): opencv_contrib's
// surface_matching module, linked into the benchmarks only.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <opencv2/core.hpp>
#include <opencv2/surface_matching.hpp>

#include "peers_rec.hpp"

namespace proxseg::peers {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

namespace ppf = cv::ppf_match_3d;

constexpr double kRadiansPerDegree = 3.14159265358979323846 / 180;

// OpenCV's layout: one row per point, x y z nx ny nz as floats.
cv::Mat to_opencv(const Cloud& c) {
  cv::Mat m(static_cast<int>(c.size()), 6, CV_32F);
  for (int i = 0; i < m.rows; ++i) {
    float* row = m.ptr<float>(i);
    for (int k = 0; k < 3; ++k) {
      row[k] = static_cast<float>(c.points[i][k]);
      row[3 + k] = static_cast<float>(c.normals[i][k]);
    }
  }
  return m;
}

// OpenCV's samplers divide by the extent of the cloud's box along each axis: a cloud without
// depth along one (a single flat face seen head-on) would index cells with NaN. Such a cloud
// is neither trained nor matched.
bool has_volume(const Cloud& c) {
  if (c.size() < 3) return false;
  Eigen::Vector3d lo = c.points.front(), hi = lo;
  for (const Eigen::Vector3d& p : c.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return ((hi - lo).array() > 1e-6).all();
}

Eigen::Matrix4d to_eigen(const cv::Matx44d& m) {
  Eigen::Matrix4d e;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) e(r, c) = m(r, c);
  return e;
}

}  // namespace

struct PpfPeer::Impl {
  PpfParams params;
  int threads = 0;
  double train_ms = 0;
  std::vector<cv::Mat> views;  // each view's points and normals, for ICP
  // match() is not const in OpenCV (it keeps the scene step): align() uses each detector from
  // one thread at a time.
  std::vector<std::unique_ptr<ppf::PPF3DDetector>> detectors;  // null: untrainable view
};

PpfPeer::PpfPeer(const Database& db, const PpfParams& params, int threads)
    : impl_(std::make_unique<Impl>()) {
  impl_->params = params;
  impl_->threads = threads > 0 ? threads : omp_get_max_threads();
  const int n = static_cast<int>(db.views.size());
  impl_->views.resize(n);
  impl_->detectors.resize(n);
  const auto t0 = Clock::now();
#pragma omp parallel for schedule(dynamic, 1) num_threads(impl_->threads)
  for (int v = 0; v < n; ++v) {
    const Cloud& c = db.views[v].cloud();
    impl_->views[v] = to_opencv(c);
    if (!has_volume(c)) continue;
    auto d = std::make_unique<ppf::PPF3DDetector>(params.sampling_step, params.distance_step,
                                                  params.num_angles);
    d->setSearchParams(params.position_threshold,
                       params.rotation_threshold_deg * kRadiansPerDegree);
    d->trainModel(impl_->views[v]);
    impl_->detectors[v] = std::move(d);
  }
  impl_->train_ms = ms_since(t0);
}

PpfPeer::~PpfPeer() = default;

double PpfPeer::train_ms() const {
  return impl_->train_ms;
}

std::vector<PeerAlignment> PpfPeer::align(const Cloud& candidate, int /*seed*/) const {
  const PpfParams& p = impl_->params;
  const int n = static_cast<int>(impl_->views.size());
  std::vector<PeerAlignment> out(n);
  if (!has_volume(candidate)) return out;
  const cv::Mat scene = to_opencv(candidate);
#pragma omp parallel for schedule(dynamic, 1) num_threads(impl_->threads)
  for (int v = 0; v < n; ++v) {
    if (!impl_->detectors[v]) continue;
    auto t0 = Clock::now();
    std::vector<ppf::Pose3DPtr> results;
    impl_->detectors[v]->match(scene, results, p.scene_sample_step, p.scene_distance);
    out[v].ransac_ms = ms_since(t0);
    if (results.empty()) continue;
    // Clusters come sorted by votes; ICP moves the view's points onto the candidate from each
    // of the best `refine` and reports its residual, the lowest of which wins.
    results.resize(std::min<std::size_t>(results.size(), std::max(p.refine, 1)));
    t0 = Clock::now();
    ppf::ICP icp(p.icp_iterations, p.icp_tolerance, p.icp_rejection_scale, p.icp_levels);
    icp.registerModelToScene(impl_->views[v], scene, results);
    out[v].icp_ms = ms_since(t0);
    const auto best = std::min_element(
        results.begin(), results.end(),
        [](const ppf::Pose3DPtr& a, const ppf::Pose3DPtr& b) { return a->residual < b->residual; });
    out[v].found = true;
    out[v].pose = to_eigen((*best)->pose);  // candidate frame <- model frame
  }
  return out;
}

}  // namespace proxseg::peers
