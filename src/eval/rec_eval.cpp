// Recognition evaluation [paper 4]: test set, occluded test set and measures (rec_eval.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/occlusion.hpp>
#include <proxseg/eval/pose_error.hpp>
#include <proxseg/eval/rec_eval.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/model_view.hpp>
#include <proxseg/recognition/registration.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "util/angles.hpp"
#include "util/splitmix.hpp"

namespace proxseg {

namespace {

using detail::kPi;

// BOP's LINEMOD object ids (models_info.json has no names).
const std::map<std::string, std::string>& linemod_names() {
  static const std::map<std::string, std::string> names = {
      {"obj_000001", "ape"},    {"obj_000002", "benchvise"}, {"obj_000003", "bowl"},
      {"obj_000004", "camera"}, {"obj_000005", "can"},       {"obj_000006", "cat"},
      {"obj_000007", "cup"},    {"obj_000008", "driller"},   {"obj_000009", "duck"},
      {"obj_000010", "eggbox"}, {"obj_000011", "glue"},      {"obj_000012", "holepuncher"},
      {"obj_000013", "iron"},   {"obj_000014", "lamp"},      {"obj_000015", "phone"}};
  return names;
}

// A seed per (run seed, item, attempt): neighbouring items get unrelated streams.
std::uint64_t mix(std::uint64_t seed, std::uint64_t item, std::uint64_t attempt = 0) {
  SplitMix s{seed ^ (item * 0x9e3779b97f4a7c15ull) ^ (attempt * 0xd1b54a32d192ed03ull)};
  return s.next();
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return detail::degrees(std::acos(std::clamp(a.dot(b), -1.0, 1.0)));
}

}  // namespace

std::vector<TestObject> read_test_objects(const std::string& dir, double scale) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir + ": not a directory (expected PLY meshes)");
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".ply") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(dir + ": no .ply meshes");
  std::vector<TestObject> objects;
  for (const fs::path& f : files) {
    TestObject o;
    o.file = f.filename().string();
    const std::string stem = f.stem().string();
    const auto known = linemod_names().find(stem);
    o.name = known != linemod_names().end() ? known->second : stem;
    o.mesh = read_mesh(f.string(), scale);
    std::vector<Eigen::Vector3d> vertices;
    vertices.reserve(o.mesh.vertices.size());
    for (const auto& v : o.mesh.vertices) vertices.push_back(v.cast<double>());
    Eigen::Vector3d lo = vertices.at(0), hi = lo;
    for (const auto& v : vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    o.centre = (lo + hi) / 2;  // where render_views() points its cameras
    o.symmetries = box_symmetries(vertices, 0.004);
    objects.push_back(std::move(o));
  }
  return objects;
}

Database render_database(const std::vector<TestObject>& objects, int views,
                         const DescriptorParams& descriptor, const std::string& dir) {
  ViewSphereParams vp;
  vp.views = views;
  Database db;
  if (dir.empty()) {
    db.descriptor = descriptor;
  } else {
    db = open_database(dir, descriptor);
    if (!db.views.empty()) throw InputError(dir + ": already holds a database");
  }
  for (const TestObject& o : objects) {
    const std::vector<RenderedView> rendered = render_views(o.mesh, vp);
    for (std::size_t i = 0; i < rendered.size(); ++i) {
      const std::string source =
          o.file + " view " + std::to_string(i + 1) + "/" + std::to_string(rendered.size());
      if (!dir.empty()) {
        add_view(db, o.name, rendered[i].points, rendered[i].eye, source);
        continue;
      }
      std::vector<Eigen::Vector3d> points;
      points.reserve(rendered[i].points.xyz.size());
      for (const auto& p : rendered[i].points.xyz) points.push_back(p.cast<double>());
      const std::vector<Rgb>& rgb = rendered[i].points.rgb;
      db.views.push_back(make_model_view(o.name,
                                         describe(points, rendered[i].eye, descriptor,
                                                  rgb.size() == points.size() ? &rgb : nullptr),
                                         source, o.name + "-" + std::to_string(i)));
    }
  }
  return dir.empty() ? db : load_database(dir);
}

std::vector<TestView> make_test_views(const std::vector<TestObject>& objects,
                                      const TestSetParams& params,
                                      const std::vector<Eigen::Vector3d>& database_directions) {
  if (objects.empty()) throw InputError("test set: no objects");
  if (params.tests < 1) throw InputError("test set: tests must be >= 1");
  if (!(params.min_distance > 0) || !(params.max_distance >= params.min_distance))
    throw InputError("test set: expected 0 < min_distance <= max_distance");
  const int n = params.tests;
  std::vector<TestView> tests(n);
  std::vector<int> failed(n, 0);
#pragma omp parallel for schedule(dynamic, 4)
  for (int k = 0; k < n; ++k) {
    SplitMix rng{mix(params.seed, static_cast<std::uint64_t>(k))};
    TestView& t = tests[k];
    t.index = k;
    t.object = k % static_cast<int>(objects.size());
    const TestObject& o = objects[t.object];
    // A uniform direction on the sphere, away from every database viewpoint.
    Eigen::Vector3d dir;
    int draws = 0;
    do {
      dir = Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()).normalized();
      t.nearest_view_deg = 180;
      for (const auto& d : database_directions)
        t.nearest_view_deg = std::min(t.nearest_view_deg, angle_deg(dir, d));
    } while (t.nearest_view_deg < params.min_angle_to_view_deg && ++draws < 10000);
    if (t.nearest_view_deg < params.min_angle_to_view_deg) {
      failed[k] = 1;
      continue;
    }
    t.distance = rng.uniform(params.min_distance, params.max_distance);
    RenderParams rp;
    rp.camera = params.camera;
    // A roll about the optical axis too: look_at() keeps the model's z up in the image, as in
    // every database view, which would leave the tests upright relative to them.
    rp.camera_from_world = Eigen::AngleAxisd(rng.uniform(-kPi, kPi), Eigen::Vector3d::UnitZ()) *
                           look_at(o.centre + t.distance * dir, o.centre);
    rp.depth_noise = params.depth_noise;
    rp.disparity_step = params.disparity_step;
    rp.seed = static_cast<std::uint32_t>(rng.next());
    const Frame image = render({o.mesh}, rp);
    const bool coloured = image.rgb.size() == image.size();
    for (std::size_t i = 0; i < image.size(); ++i)
      if (image.valid(i)) {
        t.points.push_back(image.xyz[i].cast<double>());
        if (coloured) t.colours.push_back(image.rgb[i]);
      }
    t.rendered_points = static_cast<int>(t.points.size());
    t.truth = rp.camera_from_world.matrix();  // the mesh is in the model frame = world frame
  }
  if (std::find(failed.begin(), failed.end(), 1) != failed.end())
    throw InputError("test set: no viewpoint " + std::to_string(params.min_angle_to_view_deg) +
                     " degrees away from every database viewpoint (too many database views?)");
  return tests;
}

std::vector<OcclusionBin> paper_occlusion_bins() {
  std::vector<OcclusionBin> bins;
  for (int b = 1; b <= 6; ++b) bins.push_back({b / 10.0, (b + 1) / 10.0});
  return bins;
}

std::vector<TestView> occluded_test_views(const std::vector<TestView>& clean, int count,
                                          const std::vector<OcclusionBin>& bins,
                                          std::uint64_t seed) {
  if (bins.empty()) throw InputError("occluded test set: no bins");
  const int n = std::min<int>(count, static_cast<int>(clean.size()));
  std::vector<TestView> out(std::max(n, 0));
  std::vector<char> found(out.size(), 0);
#pragma omp parallel for schedule(dynamic, 4)
  for (int i = 0; i < n; ++i) {
    const TestView& t = clean[i];
    if (t.points.empty()) continue;
    const int b = i % static_cast<int>(bins.size());
    // Radii up to the view's bounding-box diagonal reach every share of removed points.
    Eigen::Vector3d lo = t.points[0], hi = lo;
    for (const auto& p : t.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double max_radius = (hi - lo).norm();
    for (int attempt = 0; attempt < 1000 && !found[i]; ++attempt) {
      Occlusion o =
          occlude(t.points, max_radius, mix(seed, static_cast<std::uint64_t>(i), attempt));
      if (o.removed_share < bins[b].lo || o.removed_share >= bins[b].hi) continue;
      out[i] = t;
      out[i].points = std::move(o.points);
      // The colours of the points occlude() kept: the same test, point by point.
      out[i].colours.clear();
      if (t.colours.size() == t.points.size())
        for (std::size_t p = 0; p < t.points.size(); ++p)
          if ((t.points[p] - o.centre).norm() > o.radius) out[i].colours.push_back(t.colours[p]);
      out[i].bin = b;
      out[i].occlusion = o.removed_share;
      found[i] = 1;
    }
  }
  std::vector<TestView> kept;
  for (std::size_t i = 0; i < out.size(); ++i)
    if (found[i]) kept.push_back(std::move(out[i]));
  return kept;
}

bool named_right(const Answer& a, const TestView& t, const std::vector<TestObject>& objects,
                 double min_score) {
  return !a.best.empty() && a.score >= min_score && a.best == objects.at(t.object).name;
}

Rates rates(const std::vector<TestView>& tests, const std::vector<Answer>& answers,
            const std::vector<TestObject>& objects, double min_score,
            const std::function<bool(const TestView&)>& which) {
  Rates r;
  for (std::size_t i = 0; i < tests.size() && i < answers.size(); ++i) {
    const TestView& t = tests[i];
    if (which && !which(t)) continue;
    const Answer& a = answers[i];
    ++r.tests;
    r.mean_ms += a.ms;
    if (a.best.empty() || a.score < min_score) {
      ++r.unknown;
    } else if (named_right(a, t, objects, min_score)) {
      ++r.right;
      const PoseError e = pose_error(a.pose, t.truth, objects[t.object].symmetries);
      r.pose_ok += e.translation < 0.02 && e.rotation_deg < 10;
    } else {
      ++r.wrong;
    }
  }
  if (r.tests) r.mean_ms /= r.tests;
  return r;
}

std::vector<CurvePoint> score_curve(const std::vector<TestView>& tests,
                                    const std::vector<Answer>& answers,
                                    const std::vector<TestObject>& objects,
                                    const std::function<bool(const TestView&)>& which) {
  struct Scored {
    double score;
    bool right;
  };
  std::vector<Scored> answered;
  int total = 0;
  for (std::size_t i = 0; i < tests.size() && i < answers.size(); ++i) {
    if (which && !which(tests[i])) continue;
    ++total;
    if (!answers[i].best.empty())
      answered.push_back({answers[i].score, named_right(answers[i], tests[i], objects, 0)});
  }
  std::sort(answered.begin(), answered.end(),
            [](const Scored& a, const Scored& b) { return a.score > b.score; });
  std::vector<CurvePoint> curve = {{answered.empty() ? 1.0 : answered[0].score + 1e-9, 0, 0, 1}};
  int right = 0, wrong = 0;
  for (std::size_t i = 0; i < answered.size(); ++i) {
    (answered[i].right ? right : wrong) += 1;
    if (i + 1 < answered.size() && answered[i + 1].score == answered[i].score) continue;
    CurvePoint p;
    p.min_score = answered[i].score;
    p.tp_rate = total ? double(right) / total : 0;
    p.fp_rate = total ? double(wrong) / total : 0;
    p.precision = double(right) / (right + wrong);
    curve.push_back(p);
  }
  return curve;
}

}  // namespace proxseg
