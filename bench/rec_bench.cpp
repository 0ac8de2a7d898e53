// Recognition benchmark: proxseg, Open3D and PCL name rendered LINEMOD candidates against the
// same 64-view database in the same run, on the same described clouds, each timed per candidate
// and per stage; writes a markdown table and a per-candidate CSV.
// Usage: rec_bench [--data DIR] [--db-dir DIR] [--out recognition.md] [--csv candidates.csv]
//                  [--tests N] [--seed S] [--threads T] [--views-per-object V]
//                  [--o3d-iterations A,B] [--pcl-iterations I] [--peer-sample]
//                  [--skip-open3d] [--skip-pcl] [--config params.json]
#include "bench_util.hpp"
#include "peers_rec.hpp"

#include <proxseg/database.hpp>
#include <proxseg/evaluation.hpp>
#include <proxseg/io.hpp>
#include <proxseg/params.hpp>
#include <proxseg/recognition.hpp>
#include <proxseg/registration.hpp>
#include <proxseg/render.hpp>

#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

namespace {

using proxseg::Cloud;
using proxseg::Database;
using Clock = std::chrono::steady_clock;

constexpr double kPi = 3.14159265358979323846;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

std::string fmt(double v, int digits = 1) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string pct(int k, int n) {
  return n ? fmt(100.0 * k / n, 1) : "-";
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

std::string machine() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model = "unknown CPU";
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " cores";
}

std::string today() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
  return buf;
}

// The LINEMOD objects of BOP's LM-O models folder; eggbox and glue are symmetric in BOP.
struct ObjectSpec {
  int id;
  const char* name;
  bool symmetric;
};
constexpr ObjectSpec kObjects[] = {
    {1, "ape", false},  {5, "can", false},    {6, "cat", false},  {8, "driller", false},
    {9, "duck", false}, {10, "eggbox", true}, {11, "glue", true}, {12, "holepuncher", false}};

struct Object {
  ObjectSpec spec;
  proxseg::Mesh mesh;
  Eigen::Vector3d centre;                   // bounding-box centre, where cameras look
  std::vector<Eigen::Matrix4d> symmetries;  // model-frame symmetries found on the mesh
};

// One test candidate: an object rendered from a viewpoint that is not a database viewpoint.
struct Test {
  int object = 0;  // index into the objects
  double distance = 0, nearest_view_deg = 0;
  Eigen::Matrix4d truth = Eigen::Matrix4d::Identity();  // camera <- model
  std::vector<Eigen::Vector3d> points;                  // camera frame, sensor at the origin
};

// Directions at least this far from every database viewpoint: a test should not be a noisy
// copy of a stored view (the nearest of 8 evenly spread views is ~35 degrees away on average).
constexpr double kMinAngleToViewDeg = 10;

// Renders object o from a random direction at 0.6-1.2 m with Kinect-like noise, keeping the
// points in the camera frame (recognition assumes the sensor at the origin).
Test make_test(const Object& o, int index, std::mt19937& rng,
               const std::vector<Eigen::Vector3d>& db_dirs, std::uint32_t render_seed) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> distance(0.6, 1.2), roll(-kPi, kPi);
  Test t;
  t.object = index;
  Eigen::Vector3d dir;
  do {
    dir = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    t.nearest_view_deg = 180;
    for (const auto& d : db_dirs)
      t.nearest_view_deg =
          std::min(t.nearest_view_deg, std::acos(std::clamp(dir.dot(d), -1.0, 1.0)) * 180 / kPi);
  } while (t.nearest_view_deg < kMinAngleToViewDeg);
  t.distance = distance(rng);
  proxseg::RenderParams rp;
  // Also a roll about the optical axis: look_at() keeps the model's z up in the image, as in
  // every database view, which would leave the tests upright relative to them.
  rp.camera_from_world = Eigen::AngleAxisd(roll(rng), Eigen::Vector3d::UnitZ()) *
                         proxseg::look_at(o.centre + t.distance * dir, o.centre);
  rp.depth_noise = 0.0015;
  rp.seed = render_seed;
  const proxseg::Frame image = proxseg::render({o.mesh}, rp);
  for (std::size_t k = 0; k < image.size(); ++k)
    if (image.valid(k)) t.points.push_back(image.xyz[k].cast<double>());
  t.truth = rp.camera_from_world.matrix();  // the mesh is in the model frame = world frame
  return t;
}

// What one method made of one candidate.
struct Outcome {
  std::string name;  // the answer, "unknown" under RecognitionParams::min_score
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  // of the best view: camera <- model
  double score = 0, fitness = 0, coverage = 0;
  bool right = false;
  proxseg::PoseError raw, sym;  // pose errors, raw and the least over the object's symmetries
  // Stage times summed over the database views, and the wall time of the whole recognition
  // after describe (all views, scoring and the choice of the best).
  double describe_ms = 0, ransac_ms = 0, icp_ms = 0, score_ms = 0, wall_ms = 0;
};

struct Method {
  std::string label;
  std::function<Outcome(const Cloud&)> run;
  bool describes = false;  // proxseg describes the candidate; the peers reuse that cloud
  std::vector<Outcome> outcomes;
  Method(std::string l, std::function<Outcome(const Cloud&)> r, bool d = false)
      : label(std::move(l)), run(std::move(r)), describes(d) {}
};

// Names the candidate after the best-scoring view exactly as proxseg::recognize does (the same
// scores, score rule, minimum score and ties to the earlier view) from a peer's poses. Scoring
// runs on the same threads as proxseg's.
Outcome score_peer(const std::vector<proxseg::peers::PeerAlignment>& aligned, const Cloud& c,
                   const Database& db, const proxseg::RecognitionParams& rp, int threads) {
  const int n = static_cast<int>(aligned.size());
  std::vector<proxseg::Alignment> a(n);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int v = 0; v < n; ++v) {
    if (!aligned[v].found) continue;  // no hypothesis, no pose to score: 0
    const auto t0 = Clock::now();
    a[v] = proxseg::score_pose(c, db.views[v].cloud, aligned[v].pose, rp.registration);
    a[v].score_ms = ms_since(t0);
  }
  Outcome out;
  int best = 0;
  for (int v = 0; v < n; ++v) {
    out.ransac_ms += aligned[v].ransac_ms;
    out.icp_ms += aligned[v].icp_ms;
    out.score_ms += a[v].score_ms;
    if (proxseg::score_of(a[v], rp.score) > proxseg::score_of(a[best], rp.score)) best = v;
  }
  out.score = proxseg::score_of(a[best], rp.score);
  out.fitness = a[best].fitness;
  out.coverage = a[best].coverage;
  out.pose = aligned[best].pose;
  out.name = out.score >= rp.min_score ? db.views[best].object : "unknown";
  return out;
}

bool pose_ok(const Outcome& o, const proxseg::PoseError& e) {
  return o.right && e.translation < 0.02 && e.rotation_deg < 10;
}

// Removes the previous benchmark database, but never a directory that is not one.
void reset_db_dir(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  if (!fs::exists(dir)) return;
  if (!fs::is_directory(dir) || (!fs::is_empty(dir) && !fs::exists(dir / "index.json")))
    throw proxseg::InputError(dir.string() + ": exists and is not a proxseg database");
  fs::remove_all(dir);
}

std::string budget_name(int iterations) {
  if (iterations % 1000000 == 0) return std::to_string(iterations / 1000000) + "M";
  if (iterations % 1000 == 0) return std::to_string(iterations / 1000) + "k";
  return std::to_string(iterations);
}

std::string list(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : ", ") + fmt(1000 * x, 0);
  return s;
}

void write_file(const std::string& path, const std::string& text) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  proxseg::write_file_atomic(path, text);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"proxseg recognition benchmark against Open3D and PCL registration"};
  std::string data = "../shared/data", db_dir = "build/bench-out/linemod-db", out, csv;
  int tests = 40, seed = 1, threads = 0, views_per_object = 8;
  bool skip_pcl = false, skip_open3d = false, peer_sample = false;
  std::vector<int> o3d_iterations = {4000000, 100000};
  proxseg::peers::PclParams pcl_params;
  app.add_option("--data", data, "Shared data folder (holds lmo/models)")->capture_default_str();
  app.add_option("--db-dir", db_dir, "Database folder, removed and rebuilt")->capture_default_str();
  app.add_option("--out", out, "Markdown results file to write");
  app.add_option("--csv", csv, "Per-candidate CSV to write");
  app.add_option("--tests", tests, "Test candidates, round-robin over the 8 objects")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "Seed of the test viewpoints, the noise and every RANSAC")
      ->capture_default_str();
  app.add_option("--threads", threads, "Threads for proxseg, PCL and Open3D (0 = all cores)")
      ->capture_default_str();
  app.add_option("--views-per-object", views_per_object, "Database views per object")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--o3d-iterations", o3d_iterations,
                 "Open3D RANSAC budgets, one row each (a,b,...)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--pcl-iterations", pcl_params.ransac_iterations, "PCL RANSAC iterations")
      ->capture_default_str();
  app.add_flag("--peer-sample", peer_sample,
               "Peers match, RANSAC and ICP on proxseg's candidate sample (max_points) too");
  app.add_flag("--skip-pcl", skip_pcl, "Do not run the PCL peer");
  app.add_flag("--skip-open3d", skip_open3d, "Do not run the Open3D peer");
  std::string config;
  app.add_option("--config", config,
                 "JSON {\"recognition\": {...}} for proxseg (as proxseg recognize --config)");
  CLI11_PARSE(app, argc, argv);
  // Open3D has no thread setting of its own: its parallel loops take OpenMP's default team.
  if (threads > 0) omp_set_num_threads(threads);
  const int team = threads > 0 ? threads : omp_get_max_threads();

  // The database, built and then loaded from disk as a user would.
  std::vector<Object> objects;
  Database db;
  try {
    const auto t0 = Clock::now();
    reset_db_dir(db_dir);
    Database building = proxseg::open_database(db_dir, proxseg::DescriptorParams{});
    for (const ObjectSpec& spec : kObjects) {
      char file[32];
      std::snprintf(file, sizeof file, "obj_%06d.ply", spec.id);
      Object o{spec,
               proxseg::read_mesh(data + "/lmo/models/" + file, 0.001),
               Eigen::Vector3d::Zero(),
               {}};
      std::vector<Eigen::Vector3d> vertices;
      for (const auto& v : o.mesh.vertices) vertices.push_back(v.cast<double>());
      Eigen::Vector3d lo = vertices.at(0), hi = lo;
      for (const auto& v : vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      o.centre = (lo + hi) / 2;  // where render_views() points its cameras
      o.symmetries = proxseg::box_symmetries(vertices, 0.004);
      proxseg::ViewSphereParams vp;
      vp.views = views_per_object;
      const auto views = proxseg::render_views(o.mesh, vp);
      for (std::size_t i = 0; i < views.size(); ++i)
        proxseg::add_view(building, spec.name, views[i].points, views[i].eye,
                          std::string(file) + " view " + std::to_string(i + 1) + "/" +
                              std::to_string(views.size()));
      objects.push_back(std::move(o));
    }
    db = proxseg::load_database(db_dir);
    std::cerr << "database: " << db.views.size() << " views of " << objects.size() << " objects in "
              << fmt(ms_since(t0) / 1000) << " s (" << db_dir << ")\n";
  } catch (const std::exception& e) {
    std::cerr << "rec_bench: " << e.what() << "\n";
    return 1;
  }

  // Test candidates, round-robin over the objects, and one more (never timed) for the warm-up.
  const std::vector<Eigen::Vector3d> db_dirs = proxseg::view_sphere(views_per_object);
  std::mt19937 rng(static_cast<std::uint32_t>(seed));
  const int n_objects = static_cast<int>(objects.size());
  const auto make = [&](int k) {
    return make_test(objects[k % n_objects], k % n_objects, rng, db_dirs,
                     static_cast<std::uint32_t>(seed) * 100003u + static_cast<std::uint32_t>(k));
  };
  std::vector<Test> suite;
  for (int k = 0; k < tests; ++k) suite.push_back(make(k));
  const Test warm = make(tests);

  proxseg::RecognitionParams rp;
  if (!config.empty()) {
    try {
      rp = proxseg::read_recognize_params(config, {}, rp).second;
    } catch (const std::exception& e) {
      std::cerr << "rec_bench: " << e.what() << "\n";
      return 1;
    }
  }
  rp.threads = threads;
  rp.seed = static_cast<std::uint64_t>(seed);

  // What the peers register: the described candidate, or (--peer-sample) the sample of it
  // proxseg itself registers; either way the poses are scored on every candidate point.
  const auto sample = [&](const Cloud& c) {
    return peer_sample ? proxseg::subsample(c, rp.registration.max_points) : c;
  };
  std::vector<Method> methods;
  methods.push_back({"proxseg",
                     [&](const Cloud& c) {
                       const proxseg::Recognition r = proxseg::recognize(c, db, rp);
                       Outcome o;
                       for (const proxseg::Alignment& a : r.alignments) {
                         o.ransac_ms += a.ransac_ms;
                         o.icp_ms += a.icp_ms;
                         o.score_ms += a.score_ms;
                       }
                       o.wall_ms = r.align_ms;
                       o.name = r.name;
                       o.pose = r.best.pose;
                       o.score = r.best.score;
                       o.fitness = r.best.fitness;
                       o.coverage = r.best.coverage;
                       return o;
                     },
                     true});
  std::vector<std::unique_ptr<proxseg::peers::Open3dPeer>> open3d;
  if (!skip_open3d)
    for (int iterations : o3d_iterations) {
      proxseg::peers::Open3dParams p;
      p.ransac_iterations = iterations;
      open3d.push_back(std::make_unique<proxseg::peers::Open3dPeer>(db, p, threads));
      const proxseg::peers::Open3dPeer* peer = open3d.back().get();
      methods.push_back(
          {"Open3D RANSAC " + budget_name(iterations) + " + ICP", [&, peer](const Cloud& c) {
             const auto t0 = Clock::now();
             Outcome o = score_peer(peer->align(sample(c), seed), c, db, rp, team);
             o.wall_ms = ms_since(t0);
             return o;
           }});
    }
  std::unique_ptr<proxseg::peers::PclPeer> pcl;
  if (!skip_pcl) {
    pcl = std::make_unique<proxseg::peers::PclPeer>(db, pcl_params, threads);
    methods.push_back(
        {"PCL SAC-prerejective " + budget_name(pcl_params.ransac_iterations) + " + ICP",
         [&](const Cloud& c) {
           const auto t0 = Clock::now();
           Outcome o = score_peer(pcl->align(sample(c), seed), c, db, rp, team);
           o.wall_ms = ms_since(t0);
           return o;
         }});
  }

  // One untimed candidate through every method first: first-call costs (page faults, lazy
  // initialisation, thread pools) are not the per-candidate cost.
  {
    const Cloud c = proxseg::describe_candidate(warm.points, db);
    for (Method& m : methods) m.run(c);
  }
  // For the CSV: the cloud size, and the best score a view of the right object gets at the
  // true pose (how well the database covers the test's viewpoint).
  std::vector<std::size_t> cloud_points;
  std::vector<double> truth_score;
  for (int k = 0; k < tests; ++k) {
    const Test& t = suite[k];
    const Object& obj = objects[t.object];
    const auto t0 = Clock::now();
    const Cloud cloud = proxseg::describe_candidate(t.points, db);
    const double describe_ms = ms_since(t0);
    cloud_points.push_back(cloud.size());
    truth_score.push_back(0);
    for (const proxseg::ModelView& v : db.views)
      if (v.object == obj.spec.name)
        truth_score.back() =
            std::max(truth_score.back(),
                     proxseg::score_of(
                         proxseg::score_pose(cloud, v.cloud, t.truth, rp.registration), rp.score));
    std::cerr << "[" << k + 1 << "/" << tests << "] " << obj.spec.name << " (" << cloud.size()
              << " pts, " << fmt(t.distance, 2) << " m, score at the true pose "
              << fmt(truth_score.back(), 2) << "):";
    for (Method& m : methods) {
      Outcome o = m.run(cloud);
      if (m.describes) o.describe_ms = describe_ms;
      o.right = o.name == obj.spec.name;
      o.raw = proxseg::pose_error(o.pose, t.truth, {});
      o.sym = proxseg::pose_error(o.pose, t.truth, obj.symmetries);
      std::cerr << " | " << m.label << " " << o.name << " " << fmt(o.score, 2) << " "
                << fmt(o.wall_ms, 0) << " ms";
      m.outcomes.push_back(o);
    }
    std::cerr << "\n";
  }

  // The report.
  const int n = tests;
  std::ostringstream md;
  md << "## Recognition (LINEMOD, " << objects.size() << " objects x " << views_per_object
     << " views = " << db.views.size() << "-view database, " << n << " candidates)\n\n"
     << "Generated by bench/rec_bench.cpp at commit " << proxseg::bench::git_commit() << " on "
     << machine() << ", " << today()
     << ". Every method names the same candidates, described once by "
     << "proxseg (same voxel-filtered points, normals and FPFH for all), against the same "
     << "database in the same run, and is judged by the same score; one untimed warm-up "
     << "candidate first. Seed " << seed << ", threads " << team << ".\n\n";
  md << "| method | named right (%) | pose ok (%) | pose ok, symmetry-aware (%) | median error "
        "when named right (deg / mm) | ms per candidate (wall) | describe | corr. + RANSAC | "
        "ICP | scoring |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Method& m : methods) {
    int right = 0, ok = 0, ok_sym = 0;
    double wall = 0, describe = 0, ransac = 0, icp = 0, score = 0;
    std::vector<double> rot, trans;
    for (const Outcome& o : m.outcomes) {
      right += o.right;
      ok += pose_ok(o, o.raw);
      ok_sym += pose_ok(o, o.sym);
      if (o.right) rot.push_back(o.raw.rotation_deg), trans.push_back(1000 * o.raw.translation);
      wall += o.wall_ms;
      describe += o.describe_ms;
      ransac += o.ransac_ms;
      icp += o.icp_ms;
      score += o.score_ms;
    }
    md << "| " << m.label << " | " << pct(right, n) << " | " << pct(ok, n) << " | "
       << pct(ok_sym, n) << " | " << fmt(median(rot)) << " / " << fmt(median(trans)) << " | "
       << fmt(wall / n, 0) << " | " << (m.describes ? fmt(describe / n) : "(shared)") << " | "
       << fmt(ransac / n, 0) << " | " << fmt(icp / n, 0) << " | " << fmt(score / n, 0) << " |\n";
  }
  md << "\n\"Named right\": the best view's object is the truth (an answer under the minimum "
        "score is \"unknown\", wrong). \"Pose ok\": named right, and the best view's pose within "
        "2 cm and 10 degrees of the truth (camera <- model), raw or the least over the "
        "symmetries box_symmetries() finds on the mesh (";
  {
    std::string found;
    for (const Object& o : objects)
      if (o.symmetries.size() > 1)
        found += (found.empty() ? "" : ", ") + std::string(o.spec.name) + " " +
                 std::to_string(o.symmetries.size() - 1);
    md << (found.empty() ? "none" : found);
  }
  md << "; BOP lists eggbox and glue as symmetric, so their raw errors may be a symmetric "
        "equivalent). Wall: the whole recognition after describe (all views, scoring and the "
        "choice), mean per candidate. Stage columns: ms summed over the "
     << db.views.size() << " views, mean per candidate; every method spreads the views over "
     << team
     << " threads, so the sums exceed the wall time. Peers' feature time is zero: they "
        "reuse proxseg's cloud.\n\n";

  md << "### Per object (named right / pose ok, symmetry-aware)\n\n| object |";
  for (const Method& m : methods) md << " " << m.label << " |";
  md << "\n|---|";
  for (std::size_t i = 0; i < methods.size(); ++i) md << "---|";
  md << "\n";
  for (int j = 0; j < n_objects; ++j) {
    md << "| " << objects[j].spec.name << (objects[j].spec.symmetric ? " (sym.)" : "") << " |";
    for (const Method& m : methods) {
      int count = 0, right = 0, ok = 0;
      for (int k = 0; k < n; ++k)
        if (suite[k].object == j) {
          ++count;
          right += m.outcomes[k].right;
          ok += pose_ok(m.outcomes[k], m.outcomes[k].sym);
        }
      md << " " << right << "/" << count << " / " << ok << "/" << count << " |";
    }
    md << "\n";
  }

  const proxseg::DescriptorParams& d = db.descriptor;
  const proxseg::RegistrationParams& g = rp.registration;
  const proxseg::peers::Open3dParams o3;
  const proxseg::peers::PclParams& pp = pcl_params;
  md << "\n### Setup\n\n"
     << "- Database: BOP LM-O models obj_000001, 05, 06, 08, 09, 10, 11, 12 (mm -> m), "
     << views_per_object << " noiseless render_views() each, built with add_view() and read "
     << "back with load_database(). Descriptor: voxel " << fmt(1000 * d.voxel_size, 0)
     << " mm, normal radius " << fmt(1000 * d.normal_radius, 0) << " mm, FPFH radii "
     << list(d.fpfh_radii) << " mm.\n"
     << "- Candidates: render() from random directions at least " << fmt(kMinAngleToViewDeg, 0)
     << " degrees from every database viewpoint, 0.6-1.2 m, random roll, depth noise 1.5 mm "
        "at 1 m; points in the camera frame.\n"
     << "- proxseg: recognize() with RecognitionParams{} (RANSAC " << g.ransac_iterations
     << " hypotheses, inlier distance " << fmt(1000 * g.ransac_distance, 0)
     << " mm, edge similarity " << fmt(g.edge_similarity, 2) << ", normal tolerance "
     << fmt(g.normal_tolerance_deg, 0) << " deg, " << g.ransac_candidates
     << " distinct hypotheses re-judged, ICP from the best " << g.icp_starts << ", ICP "
     << g.icp_iterations << " x " << fmt(1000 * g.icp_distance, 0) << " mm "
     << (g.point_to_plane ? "point-to-plane" : "point-to-point")
     << ", matching, RANSAC and ICP on at most " << g.max_points
     << " candidate points, fitness distance " << fmt(1000 * g.fitness_distance, 0) << " mm, score "
     << (rp.score == proxseg::Score::kSymmetric
             ? "sqrt(close fitness x coverage) within " + fmt(1000 * g.score_distance, 0) + " mm"
             : std::string("fitness"))
     << ", minimum " << fmt(rp.min_score, 2) << ").\n"
     << "- Open3D 0.16: RegistrationRANSACBasedOnFeatureMatching (source = view, target = "
        "candidate, all FPFH radii, mutual filter off, max correspondence distance "
     << fmt(1000 * o3.max_correspondence_distance, 0)
     << " mm, point-to-point, ransac_n 3, checkers edge length "
     << fmt(o3.edge_length_similarity, 2) << " + distance " << fmt(1000 * o3.checker_distance, 0)
     << " mm, confidence " << o3.ransac_confidence << ", max iterations as in the row), then "
     << "point-to-point RegistrationICP (" << o3.icp_iterations << " x "
     << fmt(1000 * o3.icp_distance, 0) << " mm).\n"
     << "- PCL 1.13: SampleConsensusPrerejective<PointNormal, PointNormal, FPFHSignature33> "
        "(the first FPFH radius only: the point type holds one histogram; "
     << pp.ransac_iterations << " iterations, " << pp.samples << " samples, correspondence "
     << "randomness " << pp.correspondence_randomness << ", similarity "
     << fmt(pp.similarity_threshold, 2) << ", max correspondence distance "
     << fmt(1000 * pp.max_correspondence_distance, 0) << " mm, inlier fraction "
     << fmt(pp.inlier_fraction, 2) << "), then IterativeClosestPoint (" << pp.icp_iterations
     << " x " << fmt(1000 * pp.icp_distance, 0) << " mm).\n"
     << "- Peers: "
     << (peer_sample ? "matching, RANSAC and ICP on the same candidate sample as proxseg; "
                     : "matching, RANSAC and ICP on every candidate point; ")
     << "a view whose RANSAC found no hypothesis scores 0 (no ICP); otherwise the ICP pose "
        "is scored as proxseg's align() scores its own (proxseg::fitness() and coverage() "
        "on all candidate points) and the candidate named exactly as recognize() does. Peers "
        "draw from a generator shared by their threads, so their rows may vary slightly from "
        "run to run.\n";

  std::cout << md.str();
  if (!out.empty()) write_file(out, md.str());
  if (!csv.empty()) {
    std::ostringstream c;
    c << "test,object,distance_m,nearest_db_view_deg,raw_points,cloud_points,truth_score,method,"
         "answer,"
         "right,score,fitness,coverage,rot_err_deg,trans_err_m,rot_err_sym_deg,trans_err_sym_m,"
         "describe_ms,ransac_ms,icp_ms,score_ms,wall_ms\n";
    for (int k = 0; k < n; ++k)
      for (const Method& m : methods) {
        const Outcome& o = m.outcomes[k];
        c << k << "," << objects[suite[k].object].spec.name << "," << fmt(suite[k].distance, 3)
          << "," << fmt(suite[k].nearest_view_deg) << "," << suite[k].points.size() << ","
          << cloud_points[k] << "," << fmt(truth_score[k], 3) << ",\"" << m.label << "\"," << o.name
          << "," << o.right << "," << fmt(o.score, 4) << "," << fmt(o.fitness, 4) << ","
          << fmt(o.coverage, 4) << "," << fmt(o.raw.rotation_deg, 2) << ","
          << fmt(o.raw.translation, 4) << "," << fmt(o.sym.rotation_deg, 2) << ","
          << fmt(o.sym.translation, 4) << "," << fmt(o.describe_ms, 2) << "," << fmt(o.ransac_ms, 2)
          << "," << fmt(o.icp_ms, 2) << "," << fmt(o.score_ms, 2) << "," << fmt(o.wall_ms, 2)
          << "\n";
      }
    write_file(csv, c.str());
  }
  return 0;
}
