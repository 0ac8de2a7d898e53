// Point normals for the shape feature [paper 3.1] and the selection: on organized frames central
// differences over a box-filtered (optionally edge-aware) point image; otherwise PCA over the k
// nearest points, as Open3D's EstimateNormals.
#include <proxseg/core/features.hpp>

#include "util/moments.hpp"
#include "util/nearest_points.hpp"
#include "util/parallel_for.hpp"
#include "util/pca_normal.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace proxseg {

namespace {

// The box filter of point_normals restricted to each pixel's own surface: where the s x s window
// holds a depth step between neighbouring pixels (more than ratio x the depth) or a missing
// pixel, the mean of the valid pixels whose depth lies within ratio x (pixels apart) x the
// centre's depth of it (the image grid's depth-step test); elsewhere (most pixels) the plain
// box filter's mean. A plain box filter mixes an object's silhouette with the table a few
// centimetres behind it, and the bent normals read as a concave crease.
void edge_aware_smooth(const cv::Mat& xyz, const cv::Mat& mask, int s, float ratio, int threads,
                       cv::Mat& out) {
  const int w = xyz.cols, h = xyz.rows, lo = -(s / 2), hi = (s - 1) / 2;  // boxFilter's anchor
  cv::Mat sm, step(h, w, CV_8U), near_step;
  cv::boxFilter(xyz, out, -1, cv::Size(s, s), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  cv::boxFilter(mask, sm, -1, cv::Size(s, s), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  const auto* p = xyz.ptr<cv::Vec3f>(0);  // continuous: made whole by point_normals
  const float* m = mask.ptr<float>(0);
  auto z = [&](int i) { return std::abs(p[i][2]); };
  // A pixel that is missing or steps to its right or lower neighbour.
  auto steps = [&](int i, int j) { return std::abs(z(i) - z(j)) > ratio * std::min(z(i), z(j)); };
  detail::parallel_for(h, threads, [&](int v) {
    auto* row = step.ptr<std::uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      const int i = v * w + u;
      row[u] = !(m[i] > 0) || (u + 1 < w && steps(i, i + 1)) || (v + 1 < h && steps(i, i + w));
    }
  });
  cv::dilate(step, near_step, cv::Mat::ones(s, s, CV_8U));
  auto* o = out.ptr<cv::Vec3f>(0);
  const float* count = sm.ptr<float>(0);
  detail::parallel_for(h, threads, [&](int v) {
    const auto* near = near_step.ptr<std::uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      const int i = v * w + u;
      if (!(m[i] > 0)) continue;
      if (!near[u]) {
        o[i] /= count[i];
        continue;
      }
      const float zc = z(i);
      cv::Vec3f sum(0, 0, 0);
      int n = 0;
      for (int dv = lo; dv <= hi; ++dv) {
        const int vv = v + dv;
        if (vv < 0 || vv >= h) continue;
        for (int du = lo; du <= hi; ++du) {
          const int uu = u + du, j = vv * w + uu;
          if (uu < 0 || uu >= w || !(m[j] > 0)) continue;
          if (std::abs(z(j) - zc) > ratio * std::max(std::abs(du), std::abs(dv)) * zc) continue;
          sum += p[j];
          ++n;
        }
      }
      o[i] = sum / static_cast<float>(n);
    }
  });
}

// Normals of row v of an organized w x h frame from the smoothed points (valid where mask > 0):
// central differences s pixels apart, skipping neighbours across a depth step.
void normals_row(const Eigen::Vector3f* xyz, const float* mask, const Eigen::Vector3f* smooth,
                 int w, int h, int s, int v, Eigen::Vector3f* normals) {
  const bool up = v - s >= 0, down = v + s < h;
  for (int u = 0; u < w; ++u) {
    const int i = v * w + u;
    if (!(mask[i] > 0)) continue;
    const Eigen::Vector3f c = smooth[i];
    // Beyond this depth step a neighbour is another surface (|z|: some clouds look down -z).
    const float jump = 0.05f * std::abs(c.z());
    auto usable = [&](bool inside, int j) {
      return inside && mask[j] > 0 && std::abs(smooth[j].z() - c.z()) < jump;
    };
    const bool hl = usable(u - s >= 0, i - s), hr = usable(u + s < w, i + s);
    const bool ht = usable(up, i - s * w), hb = usable(down, i + s * w);
    if (!(hl || hr) || !(ht || hb)) continue;
    const Eigen::Vector3f du = (hr ? smooth[i + s] : c) - (hl ? smooth[i - s] : c);
    const Eigen::Vector3f dv = (hb ? smooth[i + s * w] : c) - (ht ? smooth[i - s * w] : c);
    Eigen::Vector3f n = du.cross(dv);
    const float len = n.norm();
    if (!(len > 0)) continue;
    n /= len;
    if (n.dot(xyz[i]) > 0) n = -n;  // towards the sensor
    normals[i] = n;
  }
}

// Unorganized: PCA normals over the k nearest valid points (the point itself among them), as
// Open3D's EstimateNormals computes them (the covariance from the neighbours' moments, the
// eigenvector of its smallest eigenvalue), oriented towards the sensor origin.
void unorganized_normals(const Frame& frame, int k, int threads,
                         std::vector<Eigen::Vector3f>& normals) {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.valid(i)) {
      points.push_back(frame.xyz[i].cast<double>());
      index.push_back(i);
    }
  if (points.size() < 3) return;
  const detail::NearestPoints nearest(points);
  const int nthreads = detail::thread_count(threads);
  detail::parallel_for(
      static_cast<int>(points.size()), nthreads,
      [&](int j) {
        const auto neighbours = nearest.nearest(points[j], k);
        Eigen::Vector3d normal(0, 0, 1);
        if (neighbours.size() >= 3) normal = detail::pca_normal(points, neighbours);
        if (normal.dot(points[j]) > 0) normal = -normal;
        normals[index[j]] = normal.cast<float>();
      },
      256);
}

}  // namespace

std::vector<Eigen::Vector3f> point_normals(const Frame& frame, const FeatureParams& params,
                                           int threads) {
  const Eigen::Vector3f nan = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
  std::vector<Eigen::Vector3f> normals(frame.size(), nan);
  if (!frame.organized()) {
    unorganized_normals(frame, params.normal_knn, threads, normals);
    return normals;
  }
  // Organized: smooth the xyz image (NaN-aware box filter), then cross the central differences
  // along rows and columns, as integral-image normal estimation does; skip depth discontinuities.
  const int w = frame.width, h = frame.height, s = std::max(1, params.normal_step);
  const int nthreads = detail::thread_count(threads);
  cv::Mat xyz(h, w, CV_32FC3), mask(h, w, CV_32F);
  // Every pixel is written by one iteration: rows can go to any thread. The loops run on
  // threads that block when done (parallel_for): this is the image-grid selection's path too.
  detail::parallel_for(h, nthreads, [&](int v) {
    for (int u = 0; u < w; ++u) {
      const int i = v * w + u;
      const bool ok = frame.valid(i);
      xyz.at<cv::Vec3f>(v, u) =
          ok ? cv::Vec3f(frame.xyz[i].x(), frame.xyz[i].y(), frame.xyz[i].z()) : cv::Vec3f(0, 0, 0);
      mask.at<float>(v, u) = ok ? 1.f : 0.f;
    }
  });
  cv::Mat sx, sm;
  if (params.normal_edge_ratio > 0) {
    edge_aware_smooth(xyz, mask, s, static_cast<float>(params.normal_edge_ratio), nthreads, sx);
  } else {
    cv::boxFilter(xyz, sx, -1, cv::Size(s, s), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
    cv::boxFilter(mask, sm, -1, cv::Size(s, s), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
    // The smoothed point of every valid pixel, once (each is read by up to 5 pixels below), in
    // place: a fresh buffer would cost more in page faults than the divisions it saves.
    detail::parallel_for(h, nthreads, [&](int v) {
      for (int u = 0; u < w; ++u)
        if (mask.at<float>(v, u) > 0)
          sx.at<cv::Vec3f>(v, u) = sx.at<cv::Vec3f>(v, u) / sm.at<float>(v, u);
    });
  }
  static_assert(sizeof(cv::Vec3f) == sizeof(Eigen::Vector3f), "same layout");
  CV_Assert(sx.isContinuous() && mask.isContinuous());
  const auto* smooth = reinterpret_cast<const Eigen::Vector3f*>(sx.ptr<cv::Vec3f>(0));
  detail::parallel_for(h, nthreads, [&](int v) {
    normals_row(frame.xyz.data(), mask.ptr<float>(0), smooth, w, h, s, v, normals.data());
  });
  return normals;
}

}  // namespace proxseg
