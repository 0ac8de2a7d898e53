// The pictures of the outputs: the labels over the scene (label_image_png: blended colours and
// white boundaries, or the points splatted from the sensor origin) and the recognised objects
// (recognition_image_png: tinted and outlined points, the aligned model views, id tags and a
// legend of colour, id, name and score). The colours are reproducible: golden-ratio hues per
// label, a fixed palette per recognised object (recognition_colours).
#include <proxseg/io/output.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "io/formats/image_io.hpp"
#include "io/report/pictures.hpp"

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

std::vector<Rgb> recognition_colours(const std::vector<SceneObject>& objects) {
  // Hue steps in an order that puts neighbouring ids far apart on the colour wheel.
  static constexpr int kHueOrder[10] = {0, 5, 2, 7, 4, 9, 1, 6, 3, 8};
  static constexpr int kGreyOrder[8] = {0, 4, 2, 6, 1, 5, 3, 7};
  static constexpr int kGreyShift[4] = {0, 10, 5, 15};
  std::vector<Rgb> out;
  int named = 0, unknown = 0;
  for (const SceneObject& o : objects) {
    if (o.recognition.name == kUnknown || o.recognition.best.view < 0) {
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

namespace detail {

Rgb label_rgb(std::uint32_t label) {
  const cv::Vec3b bgr = label_colour(label);
  return {bgr[2], bgr[1], bgr[0]};
}

}  // namespace detail

namespace detail {

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

}  // namespace detail

namespace {

using detail::point_owners;

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

// An object's point over the scene: the scene's colour and the object's, mixed; a point of no
// object is darkened.
struct Tint {
  const SceneShade& shade;
  const std::vector<int>& owner;
  const std::vector<Rgb>& colours;
  cv::Vec3b operator()(std::size_t i) const {
    const Rgb c = shade(i);
    if (owner[i] < 0) return cv::Vec3b(c[2] / 2, c[1] / 2, c[0] / 2);
    const Rgb& o = colours[owner[i]];
    return cv::Vec3b((2 * c[2] + 3 * o[2]) / 5, (2 * c[1] + 3 * o[1]) / 5,
                     (2 * c[0] + 3 * o[0]) / 5);
  }
};

// Where each object's id goes: the mean of its points' positions in the picture (the sum of
// `at` over `seen` points).
struct TagPlaces {
  std::vector<Eigen::Vector2d> at;
  std::vector<double> seen;
  explicit TagPlaces(std::size_t objects)
      : at(objects, Eigen::Vector2d::Zero()), seen(objects, 0) {}
};

// An organized frame: the image of its pixels tinted, each object outlined in exactly its colour
// (the legend's swatch).
cv::Mat draw_organized(const Frame& frame, const std::vector<int>& owner,
                       const std::vector<Rgb>& colours, const Tint& tint, TagPlaces& tags) {
  cv::Mat image;
  const int w = frame.width, h = frame.height;
  image.create(h, w, CV_8UC3);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      image.at<cv::Vec3b>(v, u) = tint(i);
      if (owner[i] >= 0) tags.at[owner[i]] += Eigen::Vector2d(u, v), ++tags.seen[owner[i]];
    }
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      const int k = owner[i];
      if (k < 0) continue;
      const bool edge = u == 0 || v == 0 || u + 1 == w || v + 1 == h || owner[i - 1] != k ||
                        owner[i + 1] != k || owner[i - w] != k || owner[i + w] != k;
      if (edge) image.at<cv::Vec3b>(v, u) = cv::Vec3b(colours[k][2], colours[k][1], colours[k][0]);
    }
  return image;
}

// An unorganized frame seen from the sensor with the default Kinect-like pinhole, the 640x480
// image centred on the cloud (ok false when no point is in front).
Projection fit_view(const Frame& frame) {
  Projection pr;
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
  return pr;
}

// An unorganized frame's points through pr, tinted; the objects' points after the others, so
// that they are not hidden by them.
void draw_points(const Frame& frame, const std::vector<int>& owner, const Tint& tint,
                 const Projection& pr, cv::Mat& image, TagPlaces& tags) {
  for (const bool held : {false, true})
    for (std::size_t i = 0; i < frame.size() && pr.ok; ++i) {
      if ((owner[i] >= 0) != held || !frame.valid(i) || !pr.in_front(frame.xyz[i].cast<double>()))
        continue;
      const Eigen::Vector2d q = pr(frame.xyz[i].cast<double>());
      const cv::Vec3b c = tint(i);
      cv::circle(image, cv::Point(int(q.x()), int(q.y())), 1, cv::Scalar(c[0], c[1], c[2]),
                 cv::FILLED);
      if (held) tags.at[owner[i]] += q, ++tags.seen[owner[i]];
    }
}

// The aligned model view of each named object: where the model says the object is.
void draw_models(const std::vector<SceneObject>& objects, const Database& db,
                 const std::vector<Rgb>& colours, const Projection& pr, cv::Mat& image) {
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const Recognition& r = objects[k].recognition;
    if (!pr.ok || r.best.view < 0 || r.name == kUnknown) continue;
    for (const auto& p : db.views[r.best.view].cloud().points) {
      const Eigen::Vector3d q3 =
          r.best.pose.topLeftCorner<3, 3>() * p + r.best.pose.topRightCorner<3, 1>();
      if (!pr.in_front(q3)) continue;
      const Eigen::Vector2d q = pr(q3);
      cv::circle(image, cv::Point(int(std::lround(q.x())), int(std::lround(q.y()))), 1,
                 bgr(colours[k]), cv::FILLED);
    }
  }
}

// Each object's id tag at the mean of its points in the picture.
void draw_id_tags(const std::vector<SceneObject>& objects, const std::vector<Rgb>& colours,
                  const Projection& pr, TagPlaces& tags, cv::Mat& image) {
  for (std::size_t k = 0; k < objects.size(); ++k) {
    // A cloud given with --object has no frame points: its centroid, projected.
    if (tags.seen[k] == 0 && pr.ok && pr.in_front(objects[k].centroid))
      tags.at[k] = pr(objects[k].centroid), tags.seen[k] = 1;
    if (tags.seen[k] == 0) continue;
    const Eigen::Vector2d q = tags.at[k] / tags.seen[k];
    draw_id_tag(image, objects[k].id, colours[k],
                cv::Point(int(std::lround(q.x())), int(std::lround(q.y()))));
  }
}

}  // namespace

namespace detail {

cv::Mat recognition_image(const Frame& frame, const std::vector<SceneObject>& objects,
                          const Database& db, cv::Size& scene_size) {
  const std::vector<Rgb> colours = recognition_colours(objects);
  const std::vector<int> owner = point_owners(frame, objects);
  const SceneShade shade(frame);
  const Tint tint{shade, owner, colours};
  TagPlaces tags(objects.size());
  cv::Mat image;
  Projection pr;
  if (frame.organized()) {
    image = draw_organized(frame, owner, colours, tint, tags);
    pr = fit_projection(frame);
  } else {
    image = cv::Mat(480, 640, CV_8UC3, cv::Scalar(40, 40, 40));
    pr = fit_view(frame);
    draw_points(frame, owner, tint, pr, image, tags);
  }
  draw_models(objects, db, colours, pr, image);
  draw_id_tags(objects, colours, pr, tags, image);
  scene_size = image.size();
  return with_legend(image, objects, colours);
}

}  // namespace detail

std::string recognition_image_png(const Frame& frame, const std::vector<SceneObject>& objects,
                                  const Database& db) {
  cv::Size scene;
  return detail::encode_png(detail::recognition_image(frame, objects, db, scene));
}

}  // namespace proxseg
