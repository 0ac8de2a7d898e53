// Segmentation outputs: labelled PCD, a picture of the labels, and the JSON report.
#include <proxseg/io.hpp>
#include <proxseg/output.hpp>
#include <proxseg/params.hpp>
#include <proxseg/version.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <opencv2/imgproc.hpp>

#include "image_io.hpp"
#include "run_beside.hpp"

namespace proxseg {
namespace {

// A distinct, reproducible colour per label (golden-ratio hue steps); label 0 is black.
cv::Vec3b label_colour(std::uint32_t label) {
  if (label == 0) return {0, 0, 0};
  const double hue = std::fmod(label * 0.618033988749895, 1.0) * 180.0;
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, 200 + 55 * (label % 2), 230));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  return bgr.at<cv::Vec3b>(0, 0);
}

// The colour of a label, converted once per label and image: label_colour's one-pixel OpenCV
// conversion per point cost more than the whole segmentation.
class LabelColours {
 public:
  const cv::Vec3b& operator()(std::uint32_t label) {
    auto it = cache_.find(label);
    if (it == cache_.end()) it = cache_.emplace(label, label_colour(label)).first;
    return it->second;
  }

 private:
  std::map<std::uint32_t, cv::Vec3b> cache_;
};

cv::Vec3b blend(const Rgb& rgb, std::uint32_t label, LabelColours& colours) {
  const cv::Vec3b c = colours(label);
  return {static_cast<uchar>((rgb[2] + c[0]) / 2), static_cast<uchar>((rgb[1] + c[1]) / 2),
          static_cast<uchar>((rgb[0] + c[2]) / 2)};
}

// Unorganized clouds: points splatted into a 640x480 view from the sensor origin (pinhole, fitted
// to the cloud), or orthographically along z when the cloud is not in front of the origin.
cv::Mat render_points(const Frame& frame, const std::vector<std::uint32_t>& labels) {
  const int w = 640, h = 480;
  LabelColours colours;
  cv::Mat image(h, w, CV_8UC3, cv::Scalar(40, 40, 40));
  std::vector<float> depth(w * h, std::numeric_limits<float>::infinity());
  std::size_t in_front = 0, valid = 0;
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.valid(i)) ++valid, in_front += frame.xyz[i].z() > 0;
  const bool perspective = in_front >= valid * 9 / 10;
  auto plane = [&](const Eigen::Vector3f& p) {
    return perspective ? Eigen::Vector2f(p.x() / p.z(), p.y() / p.z())
                       : Eigen::Vector2f(p.x(), p.y());
  };
  Eigen::Vector2f lo = Eigen::Vector2f::Constant(INFINITY), hi = -lo;
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.valid(i) && (!perspective || frame.xyz[i].z() > 0)) {
      lo = lo.cwiseMin(plane(frame.xyz[i]));
      hi = hi.cwiseMax(plane(frame.xyz[i]));
    }
  const Eigen::Vector2f span = (hi - lo).cwiseMax(1e-9f);
  const float scale = 0.9f * std::min(w / span.x(), h / span.y());
  const Eigen::Vector2f offset = Eigen::Vector2f(w, h) / 2 - scale * (lo + hi) / 2;
  const int r =
      std::clamp(static_cast<int>(std::sqrt(w * h / std::max<double>(valid, 1.0)) / 2), 1, 4);
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (!frame.valid(i) || (perspective && frame.xyz[i].z() <= 0)) continue;
    const Eigen::Vector2f q = scale * plane(frame.xyz[i]) + offset;
    const float z = frame.xyz[i].z();
    for (int dv = -r; dv <= r; ++dv)
      for (int du = -r; du <= r; ++du) {
        const int u = static_cast<int>(q.x()) + du, v = static_cast<int>(q.y()) + dv;
        if (u < 0 || v < 0 || u >= w || v >= h || z >= depth[v * w + u]) continue;
        depth[v * w + u] = z;
        image.at<cv::Vec3b>(v, u) = blend(frame.rgb[i], labels[i], colours);
      }
  }
  return image;
}

// Maps a point in the sensor frame to the picture: for organized frames a pinhole fitted to the
// cloud by least squares (u = fx x/z + cx, v = fy y/z + cy), else the view of render_points.
// Some sensors' clouds look down -z (e.g. the PCL milk scene): zsign is the side the scene is on.
struct Projection {
  double fx = 525, fy = 525, cx = 319.5, cy = 239.5, zsign = 1;
  bool ok = false;
  bool in_front(const Eigen::Vector3d& p) const { return p.z() * zsign > 1e-6; }
  Eigen::Vector2d operator()(const Eigen::Vector3d& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
};

Projection fit_projection(const Frame& frame) {
  Projection pr;
  // Normal equations of the two independent line fits.
  double su = 0, sx = 0, sxx = 0, sxu = 0, sv = 0, sy = 0, syy = 0, syv = 0, n = 0, front = 0;
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.valid(i)) front += frame.xyz[i].z() > 0 ? 1 : -1;
  pr.zsign = front >= 0 ? 1 : -1;
  for (int v = 0; v < frame.height; ++v)
    for (int u = 0; u < frame.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * frame.width + u;
      if (!frame.valid(i) || !pr.in_front(frame.xyz[i].cast<double>())) continue;
      const double x = frame.xyz[i].x() / frame.xyz[i].z(), y = frame.xyz[i].y() / frame.xyz[i].z();
      su += u, sx += x, sxx += x * x, sxu += x * u;
      sv += v, sy += y, syy += y * y, syv += y * v;
      ++n;
    }
  const double dx = n * sxx - sx * sx, dy = n * syy - sy * sy;
  if (n < 10 || !(dx > 0) || !(dy > 0)) return pr;
  pr.fx = (n * sxu - sx * su) / dx;
  pr.cx = (su - pr.fx * sx) / n;
  pr.fy = (n * syv - sy * sv) / dy;
  pr.cy = (sv - pr.fy * sy) / n;
  pr.ok = std::isfinite(pr.fx) && std::isfinite(pr.fy) && pr.fx != 0 && pr.fy != 0;
  return pr;
}

}  // namespace

std::string label_image_png(const Frame& frame, const std::vector<std::uint32_t>& labels) {
  cv::Mat image;
  LabelColours colours;
  if (frame.organized()) {
    const int w = frame.width, h = frame.height;
    image.create(h, w, CV_8UC3);
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const int i = v * w + u;
        const Rgb& c = frame.rgb[i];
        // Invalid or unlabelled pixels are shown dimmed, labelled ones blended with their label.
        image.at<cv::Vec3b>(v, u) =
            labels[i] ? blend(c, labels[i], colours) : cv::Vec3b(c[2] / 3, c[1] / 3, c[0] / 3);
      }
    // Label boundaries in white.
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const std::uint32_t l = labels[v * w + u];
        if (!l) continue;
        const bool edge = (u + 1 < w && labels[v * w + u + 1] && labels[v * w + u + 1] != l) ||
                          (v + 1 < h && labels[(v + 1) * w + u] && labels[(v + 1) * w + u] != l);
        if (edge) image.at<cv::Vec3b>(v, u) = {255, 255, 255};
      }
  } else {
    image = render_points(frame, labels);
  }
  return detail::encode_png(image);
}

nlohmann::json segmentation_report(const Frame& frame, const SegmentParams& params,
                                   const SegmentResult& r) {
  nlohmann::json j;
  j["proxseg"] = build_info();
  j["parameters"] = to_json(params);
  // Finite points too far out to voxelise (|x| / voxel size beyond 1e9) are left unlabelled like
  // invalid ones; counted here so that they are not dropped silently.
  std::size_t out_of_range = 0;
  for (std::size_t i = 0; i < frame.size() && i < r.voxels.voxel_of_point.size(); ++i)
    out_of_range += frame.valid(i) && r.voxels.voxel_of_point[i] < 0;
  j["input"] = {{"width", frame.width},
                {"height", frame.height},
                {"organized", frame.organized()},
                {"points", frame.size()},
                {"valid_points", frame.valid_count()},
                {"out_of_range_points", out_of_range}};
  nlohmann::json times = nlohmann::json::object();
  for (const auto& [stage, ms] : r.times_ms) times[stage] = ms;
  times["total"] = r.total_ms;  // wall time of segment()
  j["times_ms"] = times;
  // Stages on a thread of their own beside the sequence above (not part of the total).
  nlohmann::json concurrent = nlohmann::json::object();
  for (const auto& [stage, ms] : r.concurrent_ms) concurrent[stage] = ms;
  j["concurrent_times_ms"] = concurrent;
  j["voxels"] = {{"count", r.voxels.size()}, {"clustered", r.clustered.size()}};
  j["initial_centroids"] = r.initial_centroids.size();
  j["k"] = r.k();
  j["kmeans_iterations"] = r.kmeans_iterations;
  j["mrf"] = {{"enabled", params.mrf.enabled},
              {"energy_before", r.energy_before},
              {"energy_after", r.energy_after},
              {"cycles", r.mrf_cycles}};
  std::map<std::uint32_t, std::size_t> sizes;
  for (std::uint32_t l : r.point_labels)
    if (l) ++sizes[l];
  nlohmann::json labels = nlohmann::json::array();
  for (const auto& [label, points] : sizes)
    labels.push_back({{"label", label}, {"points", points}});
  j["labels"] = labels;
  const Selection& sel = r.selection;
  nlohmann::json candidates = nlohmann::json::array();
  int objects = 0;
  for (const Candidate& c : sel.components) {
    objects += !c.background;
    auto vec = [](const Eigen::Vector3d& v) { return std::vector<double>{v.x(), v.y(), v.z()}; };
    std::vector<std::vector<double>> axes;
    for (int a = 0; a < 3; ++a) axes.push_back(vec(c.box.axes.col(a)));
    candidates.push_back(
        {{"id", c.instance},
         {"label", c.label},
         {"points", c.points.size()},
         {"centroid", vec(c.centroid)},
         {"box", {{"centre", vec(c.box.centre)}, {"axes", axes}, {"extent", vec(c.box.extent)}}},
         {"background", c.background}});
  }
  j["selection"] = {{"clusters", sel.clusters},
                    {"weak_points", sel.weak_points},
                    {"instances", sel.components.size()},
                    {"candidates", objects}};
  j["candidates"] = candidates;
  return j;
}

nlohmann::json build_info() {
  return {{"version", version()}, {"commit", git_commit()}};
}

nlohmann::json write_segmentation(const std::string& prefix, const Frame& frame,
                                  const SegmentParams& params, const SegmentResult& result) {
  // The picture (three quarters of the work: building and compressing it) is made beside the
  // report and the PCD. A failure anywhere removes the files already written: never a partial set.
  std::string png;
  nlohmann::json report;
  std::vector<std::string> written;
  try {
    detail::run_beside(
        params.threads != 1, [&] { png = label_image_png(frame, result.selection.instance); },
        [&] {
          report = segmentation_report(frame, params, result);
          write_pcd(prefix + ".pcd", frame,
                    {{"label", result.point_labels}, {"instance", result.selection.instance}});
          written.push_back(prefix + ".pcd");
        });
    write_file_atomic(prefix + ".png", png);
    written.push_back(prefix + ".png");
    write_file_atomic(prefix + ".json", report.dump(2) + "\n");
  } catch (...) {
    std::error_code ec;
    for (const auto& f : written) std::filesystem::remove(f, ec);
    throw;
  }
  return report;
}

nlohmann::json recognition_json(const RecognizedObject& o, const Database& db) {
  const Recognition& r = o.recognition;
  const auto rows = [](const Eigen::Matrix4d& m) {
    std::vector<std::vector<double>> out(4, std::vector<double>(4));
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) out[i][j] = m(i, j);
    return out;
  };
  const auto match = [&](const Match& m) -> nlohmann::json {
    if (m.view < 0) return nullptr;
    return {{"name", m.object},     {"view", db.views[m.view].file}, {"score", m.score},
            {"fitness", m.fitness}, {"coverage", m.coverage},        {"colour", m.colour},
            {"rmse", m.rmse},       {"pose", rows(m.pose)}};
  };
  nlohmann::json j = {{"id", o.id},
                      {"instances", o.instances},
                      {"origin", o.origin},
                      {"points", o.points},
                      {"centroid", {o.centroid.x(), o.centroid.y(), o.centroid.z()}},
                      {"name", r.name},
                      {"best", match(r.best)},
                      {"runner_up", match(r.runner_up)},
                      {"views_aligned", r.views_aligned},
                      {"times_ms", {{"describe", r.describe_ms}, {"align", r.align_ms}}}};
  if (r.best.view >= 0) {
    j["score"] = r.best.score;
    j["fitness"] = r.best.fitness;
    j["coverage"] = r.best.coverage;
    j["colour"] = r.best.colour;
    j["pose"] = rows(r.best.pose);
  }
  return j;
}

std::string recognition_image_png(const Frame& frame, const std::vector<RecognizedObject>& objects,
                                  const Database& db) {
  cv::Mat image;
  Projection pr;
  if (frame.organized()) {
    image.create(frame.height, frame.width, CV_8UC3);
    for (int v = 0; v < frame.height; ++v)
      for (int u = 0; u < frame.width; ++u) {
        const Rgb& c = frame.rgb[static_cast<std::size_t>(v) * frame.width + u];
        image.at<cv::Vec3b>(v, u) = cv::Vec3b(c[2] / 2, c[1] / 2, c[0] / 2);
      }
    pr = fit_projection(frame);
  } else {
    // Seen from the sensor with the default Kinect-like pinhole, image centred on the cloud.
    image = cv::Mat(480, 640, CV_8UC3, cv::Scalar(40, 40, 40));
    double front = 0;
    for (std::size_t i = 0; i < frame.size(); ++i)
      if (frame.valid(i)) front += frame.xyz[i].z() > 0 ? 1 : -1;
    pr.zsign = front >= 0 ? 1 : -1;
    Eigen::Vector2d lo(INFINITY, INFINITY), hi = -lo;
    for (std::size_t i = 0; i < frame.size(); ++i)
      if (frame.valid(i) && pr.in_front(frame.xyz[i].cast<double>())) {
        const Eigen::Vector2d q(frame.xyz[i].x() / frame.xyz[i].z(),
                                frame.xyz[i].y() / frame.xyz[i].z());
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
      }
    if (lo.allFinite()) {
      const Eigen::Vector2d span = (hi - lo).cwiseMax(1e-9);
      pr.fx = pr.fy = 0.8 * std::min(640 / span.x(), 480 / span.y());
      pr.cx = 320 - pr.fx * (lo.x() + hi.x()) / 2;
      pr.cy = 240 - pr.fy * (lo.y() + hi.y()) / 2;
      pr.ok = true;
    }
    for (std::size_t i = 0; i < frame.size() && pr.ok; ++i) {
      if (!frame.valid(i) || !pr.in_front(frame.xyz[i].cast<double>())) continue;
      const Eigen::Vector2d q = pr(frame.xyz[i].cast<double>());
      const Rgb& c = frame.rgb[i];
      cv::circle(image, cv::Point(int(q.x()), int(q.y())), 1,
                 cv::Scalar(c[2] / 2, c[1] / 2, c[0] / 2), cv::FILLED);
    }
  }
  const auto objects_in_db = db.objects();
  for (const RecognizedObject& o : objects) {
    const Recognition& r = o.recognition;
    if (!pr.ok || r.best.view < 0 || r.name == "unknown") continue;
    const auto index =
        std::find(objects_in_db.begin(), objects_in_db.end(), r.name) - objects_in_db.begin();
    const cv::Vec3b c = label_colour(static_cast<std::uint32_t>(index + 1));
    const Cloud& view = db.views[r.best.view].cloud;
    for (const auto& p : view.points) {
      const Eigen::Vector3d q3 =
          r.best.pose.topLeftCorner<3, 3>() * p + r.best.pose.topRightCorner<3, 1>();
      if (!pr.in_front(q3)) continue;
      const Eigen::Vector2d q = pr(q3);
      cv::circle(image, cv::Point(int(std::lround(q.x())), int(std::lround(q.y()))), 1,
                 cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
    }
    if (pr.in_front(o.centroid)) {
      const Eigen::Vector2d q = pr(o.centroid);
      char text[160];
      std::snprintf(text, sizeof text, "%s %.2f", r.name.c_str(), r.best.score);
      const cv::Point at(int(q.x()) - 30, int(q.y()));
      cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 3);
      cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1);
    }
  }
  return detail::encode_png(image);
}

std::vector<std::string> write_candidates(const std::string& dir, const Frame& frame,
                                          const SegmentResult& result) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create candidates directory (" + ec.message() + ")");
  std::vector<std::string> written;
  try {
    for (const Candidate& c : result.selection.components) {
      if (c.background) continue;
      Frame cloud;
      cloud.width = static_cast<int>(c.points.size());
      cloud.height = 1;
      for (int p : c.points) {
        cloud.xyz.push_back(frame.xyz[p]);
        cloud.rgb.push_back(frame.rgb[p]);
      }
      const std::string path =
          (std::filesystem::path(dir) / ("candidate_" + std::to_string(c.instance) + ".pcd"))
              .string();
      write_pcd(path, cloud, {});
      written.push_back(path);
    }
  } catch (...) {
    for (const auto& f : written) std::filesystem::remove(f, ec);
    throw;
  }
  return written;
}

}  // namespace proxseg
