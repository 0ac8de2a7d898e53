// Segmentation outputs: labelled PCD, a picture of the labels, and the JSON report.
#include <proxseg/core/version.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "image_io.hpp"
#include "util/parallel_for.hpp"

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

// What the pictures show of each point itself: its colour, or on a frame without colours a grey
// from its depth (nearer is lighter, invalid points black), so that the shapes still read under
// the labels.
class SceneShade {
 public:
  explicit SceneShade(const Frame& frame) : frame_(frame) {
    if (frame.coloured()) return;
    for (std::size_t i = 0; i < frame.size(); ++i)
      if (frame.valid(i)) {
        const float d = std::abs(frame.xyz[i].z());  // |z|: some clouds look down -z
        near_ = std::min(near_, d);
        far_ = std::max(far_, d);
      }
  }
  Rgb operator()(std::size_t i) const {
    if (frame_.coloured()) return frame_.rgb[i];
    if (!frame_.valid(i)) return {0, 0, 0};
    const float span = far_ - near_;
    const float t = span > 0 ? (far_ - std::abs(frame_.xyz[i].z())) / span : 0.5f;
    const auto v = static_cast<std::uint8_t>(std::lround(64 + 160 * std::clamp(t, 0.f, 1.f)));
    return {v, v, v};
  }

 private:
  const Frame& frame_;
  float near_ = std::numeric_limits<float>::infinity(), far_ = 0;
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
  const SceneShade shade(frame);
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
        image.at<cv::Vec3b>(v, u) = blend(shade(i), labels[i], colours);
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

std::string label_png(const Frame& frame, const std::vector<std::uint32_t>& labels) {
  const std::size_t n = frame.size();
  if (labels.size() != n)
    throw std::invalid_argument("label_png: " + std::to_string(labels.size()) + " labels for " +
                                std::to_string(n) + " points");
  if (n == 0 || frame.width < 1 || frame.height < 1 ||
      static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height) != n)
    throw std::invalid_argument("label_png: frame is " + std::to_string(frame.width) + "x" +
                                std::to_string(frame.height) + " with " + std::to_string(n) +
                                " points (expected a non-empty frame of width*height points)");
  const std::uint32_t largest = *std::max_element(labels.begin(), labels.end());
  if (largest > std::numeric_limits<std::uint16_t>::max())
    throw InputError("label " + std::to_string(largest) +
                     " does not fit a 16-bit PNG (expected labels 0..65535)");
  cv::Mat image(frame.height, frame.width, CV_16UC1);
  auto* px = image.ptr<std::uint16_t>(0);  // a new Mat is continuous
  for (std::size_t i = 0; i < n; ++i) px[i] = static_cast<std::uint16_t>(labels[i]);
  return detail::encode_png16(image);
}

std::string label_image_png(const Frame& frame, const std::vector<std::uint32_t>& labels) {
  cv::Mat image;
  LabelColours colours;
  if (frame.organized()) {
    const int w = frame.width, h = frame.height;
    const SceneShade shade(frame);
    image.create(h, w, CV_8UC3);
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const int i = v * w + u;
        const Rgb c = shade(i);
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
  // invalid ones; counted so that they are not dropped silently.
  const std::size_t valid = r.voxels.valid_points;
  const std::size_t out_of_range = valid - r.voxels.voxelised_points;
  j["input"] = {{"width", frame.width},
                {"height", frame.height},
                {"organized", frame.organized()},
                {"colour", frame.coloured()},
                {"points", frame.size()},
                {"valid_points", valid},
                {"out_of_range_points", out_of_range}};
  // The blocks computed, which "parameters" alone does not tell: the input can take some off.
  j["features"] = {
      {"colour", r.blocks.colour}, {"texture", r.blocks.texture}, {"shape", r.blocks.shape}};
  if (const std::string off = colourless_note(frame, params.features); !off.empty())
    j["features"]["note"] = "the input has no colour: " + off;
  nlohmann::json times = nlohmann::json::object();
  for (const auto& [stage, ms] : r.times_ms) times[stage] = ms;
  times["total"] = r.total_ms;  // wall time of segment()
  j["times_ms"] = times;
  // Stages on a thread of their own beside the sequence above (not part of the total).
  nlohmann::json concurrent = nlohmann::json::object();
  for (const auto& [stage, ms] : r.concurrent_ms) concurrent[stage] = ms;
  j["concurrent_times_ms"] = concurrent;
  // Where the image-grid stages' time goes: "stage/step" (part of the stages above).
  nlohmann::json steps = nlohmann::json::object();
  for (const auto& [step, ms] : r.steps_ms) steps[step] = ms;
  j["step_times_ms"] = steps;
  j["voxels"] = {{"count", r.voxels.size()}, {"clustered", r.clustered.size()}};
  j["initial_centroids"] = r.initial_centroids.size();
  // Whether stages 2-6 ran (needs_paper_labels); without them "labels" are the image-grid
  // surfaces and k is 0.
  j["paper_labels"] = r.paper_labels;
  j["k"] = r.k();
  j["kmeans_iterations"] = r.kmeans_iterations;
  j["mrf"] = {{"enabled", params.mrf.enabled},
              {"energy_before", r.energy_before},
              {"energy_after", r.energy_after},
              {"cycles", r.mrf_cycles}};
  nlohmann::json labels = nlohmann::json::array();
  for (std::size_t label = 1; label < r.label_sizes.size(); ++label)
    if (r.label_sizes[label])
      labels.push_back({{"label", label}, {"points", r.label_sizes[label]}});
  j["labels"] = labels;
  const Selection& sel = r.selection;
  // "candidates" are the objects selection picked out ("selection.candidates" counts them);
  // "background" the large planes it reported beside them. Both keep the instance ids of the
  // instance image.
  nlohmann::json candidates = nlohmann::json::array(), background = nlohmann::json::array();
  for (const Candidate& c : sel.components) {
    auto vec = [](const Eigen::Vector3d& v) { return std::vector<double>{v.x(), v.y(), v.z()}; };
    std::vector<std::vector<double>> axes;
    for (int a = 0; a < 3; ++a) axes.push_back(vec(c.box.axes.col(a)));
    (c.background ? background : candidates)
        .push_back(
            {{"id", c.instance},
             {"label", c.label},
             {"points", c.points.size()},
             {"centroid", vec(c.centroid)},
             {"box",
              {{"centre", vec(c.box.centre)}, {"axes", axes}, {"extent", vec(c.box.extent)}}},
             {"background", c.background}});
  }
  j["selection"] = {{"clusters", sel.clusters},
                    {"weak_points", sel.weak_points},
                    {"instances", sel.components.size()},
                    {"candidates", candidates.size()}};
  j["candidates"] = candidates;
  j["background"] = background;
  return j;
}

std::string colourless_note(const Frame& frame, const FeatureParams& features) {
  if (frame.coloured()) return "";
  const FeatureBlocks asked = feature_blocks(features, true, frame.organized());
  const FeatureBlocks got = feature_blocks(features, false, frame.organized());
  const bool colour = asked.colour != got.colour, texture = asked.texture != got.texture;
  if (colour && texture) return "the colour and texture blocks are off";
  if (colour) return "the colour block is off";
  if (texture) return "the texture block is off";
  return "";
}

nlohmann::json build_info() {
  return {{"version", version()}, {"commit", git_commit()}};
}

OutputSet parse_outputs(const std::string& list, const std::string& field) {
  if (list.empty())
    throw InputError(field + ": no outputs (expected labels, pcd, png, json or all)");
  OutputSet o{false, false, false, false};
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t end = std::min(list.find(',', start), list.size());
    const std::string word = list.substr(start, end - start);
    start = end + 1;
    if (word == "labels")
      o.labels = true;
    else if (word == "pcd")
      o.pcd = true;
    else if (word == "png")
      o.png = true;
    else if (word == "json")
      o.json = true;
    else if (word == "all")
      o = OutputSet{true, true, true, true};
    else
      throw InputError(field + ": unknown output \"" + word +
                       "\" (expected labels, pcd, png, json or all, comma-separated)");
  }
  return o;
}

std::string to_string(const OutputSet& o) {
  std::string s;
  for (const auto& [on, name] : {std::pair{o.labels, "labels"}, std::pair{o.pcd, "pcd"},
                                 std::pair{o.png, "png"}, std::pair{o.json, "json"}})
    if (on) s += (s.empty() ? "" : ",") + std::string(name);
  return s;
}

std::vector<std::string> output_files(const std::string& prefix, const OutputSet& o,
                                      bool recognition) {
  std::vector<std::string> files;
  if (o.labels) {
    if (recognition) {
      files.push_back(prefix + ".object.png");
    } else {
      files.push_back(prefix + ".label.png");
      files.push_back(prefix + ".instance.png");
    }
  }
  if (o.pcd) files.push_back(prefix + ".pcd");
  if (o.png) files.push_back(prefix + ".png");
  if (o.json) files.push_back(prefix + ".json");
  return files;
}

nlohmann::json write_segmentation(const std::string& prefix, const Frame& frame,
                                  const SegmentParams& params, const SegmentResult& result,
                                  const OutputSet& outputs) {
  const nlohmann::json report = segmentation_report(frame, params, result);
  write_segmentation(prefix, frame, result.point_labels, result.selection.instance, report, outputs,
                     params.threads);
  return report;
}

void write_segmentation(const std::string& prefix, const Frame& frame,
                        const std::vector<std::uint32_t>& point_labels,
                        const std::vector<std::uint32_t>& instances, const nlohmann::json& report,
                        const OutputSet& outputs, int threads) {
  if (point_labels.size() != frame.size() || instances.size() != frame.size())
    throw InputError(
        prefix + ": labels and instances must have one value per point of the frame (" +
        std::to_string(frame.size()) + "), got " + std::to_string(point_labels.size()) + " and " +
        std::to_string(instances.size()));
  // The picture (three quarters of the work: building and compressing it) is made beside the
  // rest, on a thread that ends with it (parallel_for: no OpenMP team left spin-waiting until the
  // process exits); then every file is written at once, so that a failure never leaves a partial
  // set.
  std::string png, pcd, label, instance;
  auto picture = [&] {
    if (outputs.png) png = label_image_png(frame, instances);
  };
  auto rest = [&] {
    if (outputs.pcd) pcd = pcd_bytes(frame, {{"label", point_labels}, {"instance", instances}});
    if (outputs.labels) {
      label = label_png(frame, point_labels);
      instance = label_png(frame, instances);
    }
  };
  if (threads != 1 && outputs.png) {
    detail::parallel_for(2, 2, [&](int i) { i == 0 ? picture() : rest(); });
  } else {
    picture();
    rest();
  }
  std::vector<std::pair<std::string, std::string>> files;
  if (outputs.labels) {
    files.emplace_back(prefix + ".label.png", std::move(label));
    files.emplace_back(prefix + ".instance.png", std::move(instance));
  }
  if (outputs.pcd) files.emplace_back(prefix + ".pcd", std::move(pcd));
  if (outputs.png) files.emplace_back(prefix + ".png", std::move(png));
  if (outputs.json) files.emplace_back(prefix + ".json", report.dump(2) + "\n");
  write_files_atomic(files);
}

namespace {

const char* origin_name(SceneObject::Origin origin) {
  switch (origin) {
    case SceneObject::Origin::kSplit:
      return "split";
    case SceneObject::Origin::kMerged:
      return "merged";
    default:
      return "candidate";
  }
}

}  // namespace

nlohmann::json recognition_json(const SceneObject& o, const Database& db) {
  const Recognition& r = o.recognition;
  const auto rows = [](const Eigen::Matrix4d& m) {
    std::vector<std::vector<double>> out(4, std::vector<double>(4));
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) out[i][j] = m(i, j);
    return out;
  };
  const auto match = [&](const Match& m) -> nlohmann::json {
    if (m.view < 0) return nullptr;
    return {{"name", m.object},           {"view", db.views[m.view].name},
            {"score", m.score},           {"fitness", m.fitness},
            {"coverage", m.coverage},     {"colour", m.colour},
            {"free_space", m.free_space}, {"rmse", m.rmse},
            {"pose", rows(m.pose)}};
  };
  nlohmann::json j = {{"id", o.id},
                      {"instances", o.instances},
                      {"origin", origin_name(o.origin)},
                      {"points", o.points.size()},
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
    j["free_space"] = r.best.free_space;
    j["pose"] = rows(r.best.pose);
  }
  if (r.lookalike.compared > 0)
    j["lookalike"] = {{"compared", r.lookalike.compared},
                      {"differing", r.lookalike.differing},
                      {"votes_best", r.lookalike.first},
                      {"votes_runner_up", r.lookalike.second},
                      {"agreement_best", r.lookalike.first_agreement},
                      {"agreement_runner_up", r.lookalike.second_agreement},
                      {"decided", r.lookalike_decided}};
  return j;
}

nlohmann::json recognition_candidates_json(const std::vector<SceneObject>& objects,
                                           const Database& db) {
  const std::vector<Rgb> colours = recognition_colours(objects);
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < objects.size(); ++i) {
    list.push_back(recognition_json(objects[i], db));
    list.back()["colour"] = colours[i];
  }
  return list;
}

std::vector<Rgb> recognition_colours(const std::vector<SceneObject>& objects) {
  // Hue steps in an order that puts neighbouring ids far apart on the colour wheel.
  static constexpr int kHueOrder[10] = {0, 5, 2, 7, 4, 9, 1, 6, 3, 8};
  static constexpr int kGreyOrder[8] = {0, 4, 2, 6, 1, 5, 3, 7};
  static constexpr int kGreyShift[4] = {0, 10, 5, 15};
  std::vector<Rgb> out;
  int named = 0, unknown = 0;
  for (const SceneObject& o : objects) {
    if (o.recognition.name == "unknown" || o.recognition.best.view < 0) {
      // Greys (r = g = b) never equal a named colour (saturated): "unknown" shows at a glance.
      const int k = unknown++ % 32;
      const auto v = static_cast<std::uint8_t>(90 + 20 * kGreyOrder[k % 8] + kGreyShift[k / 8]);
      out.push_back({v, v, v});
      continue;
    }
    const int k = named++ % 30, tier = k / 10;
    const double hue = kHueOrder[k % 10] * 18 + (tier ? 9 : 0);      // OpenCV hue: 0..180
    const cv::Scalar hsv = tier == 0   ? cv::Scalar(hue, 255, 255)   // bright
                           : tier == 1 ? cv::Scalar(hue, 255, 160)   // dark
                                       : cv::Scalar(hue, 110, 255);  // pale
    cv::Mat bgr;
    cv::cvtColor(cv::Mat(1, 1, CV_8UC3, hsv), bgr, cv::COLOR_HSV2BGR);
    const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
    out.push_back({c[2], c[1], c[0]});
  }
  return out;
}

namespace {

// Per frame point the index into objects of the object that holds it, -1 for none.
std::vector<int> point_owners(const Frame& frame, const std::vector<SceneObject>& objects) {
  std::vector<int> owner(frame.size(), -1);
  for (std::size_t k = 0; k < objects.size(); ++k)
    for (int i : objects[k].points) {
      if (i < 0 || static_cast<std::size_t>(i) >= frame.size())
        throw std::invalid_argument("recognition_labels: point " + std::to_string(i) +
                                    " of object " + std::to_string(objects[k].id) +
                                    " is outside the frame");
      if (owner[i] >= 0)
        throw std::invalid_argument("recognition_labels: point " + std::to_string(i) +
                                    " is held by objects " + std::to_string(objects[owner[i]].id) +
                                    " and " + std::to_string(objects[k].id));
      owner[i] = static_cast<int>(k);
    }
  return owner;
}

cv::Scalar bgr(const Rgb& c) {
  return cv::Scalar(c[2], c[1], c[0]);
}

// Black or white, whichever reads on c.
cv::Scalar ink_on(const Rgb& c) {
  return 0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2] > 140 ? cv::Scalar(0, 0, 0)
                                                          : cv::Scalar(255, 255, 255);
}

// The object's id in a box of its colour, centred at `at` and kept inside the image.
void draw_id_tag(cv::Mat& image, int id, const Rgb& colour, cv::Point at) {
  const std::string text = std::to_string(id);
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &baseline);
  const int w = size.width + 6, h = size.height + 6;
  const cv::Point corner(std::clamp(at.x - w / 2, 0, std::max(0, image.cols - w)),
                         std::clamp(at.y - h / 2, 0, std::max(0, image.rows - h)));
  const cv::Rect box(corner, cv::Size(w, h));
  cv::rectangle(image, box, bgr(colour), cv::FILLED);
  cv::rectangle(image, box, cv::Scalar(0, 0, 0), 1);
  cv::putText(image, text, corner + cv::Point(3, 3 + size.height), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              ink_on(colour), 1, cv::LINE_AA);
}

// The legend's layout: columns of rows right of the scene. Text is OpenCV's Hershey font
// (cv::putText, in imgproc, which the library links already): no font data of our own to keep,
// and every glyph a user's name may hold in ASCII.
constexpr int kLegendColumnWidth = 240, kLegendHeader = 26, kLegendRow = 18, kLegendMargin = 6;
constexpr int kSwatch = 12;
constexpr double kLegendFont = 0.42;

// "id name score", the name shortened with ".." to fit a column.
std::string legend_text(const SceneObject& o) {
  const auto text = [&](const std::string& name) {
    char score[32];
    std::snprintf(score, sizeof score, "%.2f", o.recognition.best.score);
    return std::to_string(o.id) + " " + name + " " + score;
  };
  const int room = kLegendColumnWidth - 8 - kSwatch - 6 - 4;
  const auto fits = [&](const std::string& t) {
    int baseline = 0;
    return cv::getTextSize(t, cv::FONT_HERSHEY_SIMPLEX, kLegendFont, 1, &baseline).width <= room;
  };
  std::string name = o.recognition.name;
  if (fits(text(name))) return text(name);
  while (name.size() > 1 && !fits(text(name + ".."))) name.pop_back();
  return text(name + "..");
}

// The scene (w x h, top left) and the legend beside it: per object, in order, a swatch of exactly
// its colour and "id name score".
cv::Mat with_legend(const cv::Mat& scene, const std::vector<SceneObject>& objects,
                    const std::vector<Rgb>& colours) {
  const int rows = std::max(8, (scene.rows - kLegendHeader - kLegendMargin) / kLegendRow);
  const int columns = std::max<int>(1, (objects.size() + rows - 1) / rows);
  const int height = std::max(scene.rows, kLegendHeader + rows * kLegendRow + kLegendMargin);
  cv::Mat image(height, scene.cols + columns * kLegendColumnWidth, CV_8UC3, cv::Scalar(32, 32, 32));
  scene.copyTo(image(cv::Rect(0, 0, scene.cols, scene.rows)));
  // Text off grey (r != b), so that no letter's pixels take an unknown object's grey.
  const cv::Scalar text_colour(205, 225, 235);
  cv::putText(image, objects.empty() ? "no objects" : "id name score",
              cv::Point(scene.cols + 8, 18), cv::FONT_HERSHEY_SIMPLEX, kLegendFont, text_colour, 1,
              cv::LINE_AA);
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const int column = static_cast<int>(k) / rows, row = static_cast<int>(k) % rows;
    const int x = scene.cols + column * kLegendColumnWidth + 8,
              y = kLegendHeader + row * kLegendRow;
    cv::rectangle(image, cv::Rect(x, y + 3, kSwatch, kSwatch), bgr(colours[k]), cv::FILLED);
    cv::putText(image, legend_text(objects[k]), cv::Point(x + kSwatch + 6, y + 14),
                cv::FONT_HERSHEY_SIMPLEX, kLegendFont, text_colour, 1, cv::LINE_AA);
  }
  return image;
}

// recognition_image_png's picture; the size of its scene part in scene_size.
cv::Mat recognition_image(const Frame& frame, const std::vector<SceneObject>& objects,
                          const Database& db, cv::Size& scene_size) {
  const std::vector<Rgb> colours = recognition_colours(objects);
  const std::vector<int> owner = point_owners(frame, objects);
  const SceneShade shade(frame);
  // An object's point over the scene: the scene's colour and the object's, mixed.
  const auto tint = [&](std::size_t i) {
    const Rgb c = shade(i);
    if (owner[i] < 0) return cv::Vec3b(c[2] / 2, c[1] / 2, c[0] / 2);
    const Rgb& o = colours[owner[i]];
    return cv::Vec3b((2 * c[2] + 3 * o[2]) / 5, (2 * c[1] + 3 * o[1]) / 5,
                     (2 * c[0] + 3 * o[0]) / 5);
  };
  // Where each object's id goes: the mean of its points' positions in the picture.
  std::vector<Eigen::Vector2d> at(objects.size(), Eigen::Vector2d::Zero());
  std::vector<double> seen(objects.size(), 0);
  cv::Mat image;
  Projection pr;
  if (frame.organized()) {
    const int w = frame.width, h = frame.height;
    image.create(h, w, CV_8UC3);
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        image.at<cv::Vec3b>(v, u) = tint(i);
        if (owner[i] >= 0) at[owner[i]] += Eigen::Vector2d(u, v), ++seen[owner[i]];
      }
    // Outlines in exactly the object's colour (the legend's swatch).
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        const int k = owner[i];
        if (k < 0) continue;
        const bool edge = u == 0 || v == 0 || u + 1 == w || v + 1 == h || owner[i - 1] != k ||
                          owner[i + 1] != k || owner[i - w] != k || owner[i + w] != k;
        if (edge)
          image.at<cv::Vec3b>(v, u) = cv::Vec3b(colours[k][2], colours[k][1], colours[k][0]);
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
    // The objects' points after the others, so that they are not hidden by them.
    for (const bool held : {false, true})
      for (std::size_t i = 0; i < frame.size() && pr.ok; ++i) {
        if ((owner[i] >= 0) != held || !frame.valid(i) || !pr.in_front(frame.xyz[i].cast<double>()))
          continue;
        const Eigen::Vector2d q = pr(frame.xyz[i].cast<double>());
        const cv::Vec3b c = tint(i);
        cv::circle(image, cv::Point(int(q.x()), int(q.y())), 1, cv::Scalar(c[0], c[1], c[2]),
                   cv::FILLED);
        if (held) at[owner[i]] += q, ++seen[owner[i]];
      }
  }
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const Recognition& r = objects[k].recognition;
    if (!pr.ok || r.best.view < 0 || r.name == "unknown") continue;
    // The aligned model view: where the model says the object is.
    for (const auto& p : db.views[r.best.view].cloud().points) {
      const Eigen::Vector3d q3 =
          r.best.pose.topLeftCorner<3, 3>() * p + r.best.pose.topRightCorner<3, 1>();
      if (!pr.in_front(q3)) continue;
      const Eigen::Vector2d q = pr(q3);
      cv::circle(image, cv::Point(int(std::lround(q.x())), int(std::lround(q.y()))), 1,
                 bgr(colours[k]), cv::FILLED);
    }
  }
  for (std::size_t k = 0; k < objects.size(); ++k) {
    // A cloud given with --object has no frame points: its centroid, projected.
    if (seen[k] == 0 && pr.ok && pr.in_front(objects[k].centroid))
      at[k] = pr(objects[k].centroid), seen[k] = 1;
    if (seen[k] == 0) continue;
    const Eigen::Vector2d q = at[k] / seen[k];
    draw_id_tag(image, objects[k].id, colours[k],
                cv::Point(int(std::lround(q.x())), int(std::lround(q.y()))));
  }
  scene_size = image.size();
  return with_legend(image, objects, colours);
}

}  // namespace

std::vector<std::uint32_t> recognition_labels(const Frame& frame,
                                              const std::vector<SceneObject>& objects) {
  const std::vector<int> owner = point_owners(frame, objects);
  std::vector<std::uint32_t> labels(frame.size(), 0);
  for (std::size_t i = 0; i < owner.size(); ++i)
    if (owner[i] >= 0) labels[i] = static_cast<std::uint32_t>(objects[owner[i]].id);
  return labels;
}

std::string recognition_image_png(const Frame& frame, const std::vector<SceneObject>& objects,
                                  const Database& db) {
  cv::Size scene;
  return detail::encode_png(recognition_image(frame, objects, db, scene));
}

nlohmann::json recognition_report(const std::string& input, const std::string& db_dir,
                                  const Database& db, const RecognitionParams& rec,
                                  const SegmentParams* seg,
                                  const std::vector<SceneObject>& objects) {
  nlohmann::json report;
  report["input"] = input;
  report["database"] = {{"dir", db_dir},
                        {"objects", db.objects().size()},
                        {"views", db.views.size()},
                        {"descriptor", to_json(db.descriptor)}};
  report["proxseg"] = build_info();
  report["parameters"] = {{"recognition", to_json(rec)}};
  if (seg) report["parameters"]["segmentation"] = to_json(*seg);
  report["candidates"] = recognition_candidates_json(objects, db);
  // Views whose damaged records left them out (at open, or when recognition read them): the
  // answers come from the others (`proxseg db check` lists every damaged record).
  std::vector<std::string> damaged = db.damaged;
  for (const SceneObject& o : objects)
    for (const std::string& d : o.recognition.damaged)
      if (std::find(damaged.begin(), damaged.end(), d) == damaged.end()) damaged.push_back(d);
  report["database"]["damaged_views"] = damaged;
  return report;
}

nlohmann::json write_recognition(const std::string& prefix, const Frame& frame,
                                 const std::vector<SceneObject>& objects, const Database& db,
                                 nlohmann::json report, bool scene, const OutputSet& outputs) {
  // The report names the files beside it by their file names: it stays right when the folder
  // is moved.
  const std::string stem = std::filesystem::path(prefix).filename().string();
  std::vector<std::pair<std::string, std::string>> files;
  if (scene && (outputs.pcd || outputs.labels)) {
    const std::vector<std::uint32_t> ids = recognition_labels(frame, objects);
    if (outputs.labels) files.emplace_back(prefix + ".object.png", label_png(frame, ids));
    if (outputs.pcd) files.emplace_back(prefix + ".pcd", pcd_bytes(frame, {{"object", ids}}));
    report["labels"] = {{"file", stem + (outputs.pcd ? ".pcd" : ".object.png")},
                        {"field", "object"},
                        {"none", 0},
                        {"meaning",
                         "per point of the input frame, the id (candidates[].id) of the "
                         "recognised object that holds it; 0 = no object"}};
  }
  if (outputs.png) {
    cv::Size scene_size;
    const cv::Mat picture = recognition_image(frame, objects, db, scene_size);
    report["picture"] = {{"file", stem + ".png"},
                         {"width", picture.cols},
                         {"height", picture.rows},
                         {"scene", {{"width", scene_size.width}, {"height", scene_size.height}}},
                         {"legend", "right of the scene: per object its colour, id, name, score"}};
    files.emplace_back(prefix + ".png", detail::encode_png(picture));
  }
  if (outputs.json) files.emplace_back(prefix + ".json", report.dump(2) + "\n");
  write_files_atomic(files);
  return report;
}

std::vector<std::string> write_candidates(const std::string& dir, const Frame& frame,
                                          const SegmentResult& result) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw FileError(dir + ": cannot create candidates directory (" + ec.message() + ")");
  std::vector<std::string> written;
  try {
    for (const Candidate& c : result.selection.components) {
      if (c.background) continue;
      Frame cloud;
      cloud.width = static_cast<int>(c.points.size());
      cloud.height = 1;
      for (int p : c.points) {
        cloud.xyz.push_back(frame.xyz[p]);
        // No made-up colour: a colourless candidate stays colourless (recognised by shape).
        if (frame.coloured()) cloud.rgb.push_back(frame.rgb[p]);
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
