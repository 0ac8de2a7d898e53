// db_scale_bench (`make bench-dbscale`): how recognition's cost and accuracy scale with the
// size of the model database [issue "A database that scales"]. The objects tested are the
// LINEMOD meshes of --models; seeded distractors fill the database up to each size: textured
// boxes and cylinders, and the LINEMOD meshes hue-turned (same shape, other colour: the hard
// negatives). Each database holds --views render_views() per object and is a prefix of the next
// (the same first objects). Every size runs the same seeded test views (make_test_views(), with
// their colours) through describe_candidate() + recognize() with the default RecognitionParams
// (a shortlist of the views nearest by signature) and, on the first --all-tests of them, with
// shortlist = 0 (every view, the paper's way) on the sizes up to --all-max-views. Each size is
// also written to a database file (OUT/db, grown from size to size; the in-process rows read
// it), and measured as a user meets it, one process per question: opening it (this program with
// --open, in a child) and `proxseg recognize --object` on the first --process-tests test views
// (wall, CPU, peak RSS, answers). Writes OUT/dbscale.md and OUT/dbscale.json.
// Exit codes: 0 ok, 1 bad input, 2 usage.
// Usage: db_scale_bench --models DIR -o OUT [--units mm|m] [--views N] [--sizes 64,128,...]
//                       [--tests N] [--all-tests N] [--all-max-views N] [--process-tests N]
//                       [--tools PATH] [--lookalikes N] [--seed S] [--threads T] [--json]
//        db_scale_bench --open DB   (prints {"views", "ms", "rss_kb"} of opening DB)
#include <proxseg/core/colour.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/eval/rec_eval.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/memory.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench_main.hpp"
#include "bench_util.hpp"
#include "progress.hpp"  // apps/progress.hpp: the CLI's progress bar

namespace {

using proxseg::Answer;
using proxseg::InputError;
using proxseg::Rgb;
using proxseg::TestObject;
using proxseg::TestView;
constexpr double kPi = 3.14159265358979323846;
namespace fs = std::filesystem;

struct Options {
  std::string models, output, units = "mm", tools, open, object;
  int views = 8, tests = 200, all_tests = 40, lookalikes = 8, threads = 0;
  int all_max_views = 512, process_tests = 8;
  std::vector<int> sizes = {64, 128, 256, 512};
  std::uint64_t seed = 1;
  bool json = false;
};

void add_options(CLI::App* cmd, Options& o) {
  cmd->add_option("--open", o.open, "Only open this database and print its time and RSS as JSON");
  cmd->add_option("--object", o.object, "With --open: then recognise this cloud (peak RSS)");
  cmd->add_option("--models", o.models,
                  "Folder of PLY meshes, the objects tested "
                  "(e.g. ../shared/data/lmo/models)");
  cmd->add_option("--all-max-views", o.all_max_views,
                  "Align every view (the --all-tests rows) only up to this many views")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  cmd->add_option("--process-tests", o.process_tests,
                  "Test views recognised one process each with `proxseg recognize --object` per "
                  "size (0: none)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  cmd->add_option("--tools", o.tools,
                  "The proxseg-tools program (default: the one in this build, ../proxseg-tools)");
  cmd->add_option("--units", o.units, "Units of the meshes")
      ->check(CLI::IsMember({"m", "mm"}))
      ->capture_default_str();
  cmd->add_option("-o,--output", o.output, "Output folder (dbscale.md, dbscale.json, db/)");
  cmd->add_option("--views", o.views, "Database views per object")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--sizes", o.sizes,
                  "Database sizes in views (multiples of --views, at least the tested objects' "
                  "views)")
      ->delimiter(',')
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--tests", o.tests, "Test views of the default rows (round-robin over objects)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--all-tests", o.all_tests,
                  "Test views (the first ones) of the every-view rows (shortlist 0)")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  cmd->add_option("--lookalikes", o.lookalikes,
                  "Hue-turned copies of the tested meshes among the distractors (at most one per "
                  "tested mesh)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  cmd->add_option("--seed", o.seed, "Seed of the test set, the distractors and every RANSAC")
      ->capture_default_str();
  cmd->add_option("--threads", o.threads,
                  "Threads (0 = all cores); the answers do not depend on it")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  cmd->add_flag("--json", o.json, "Print dbscale.json on stdout");
}

using proxseg::bench::Clock;
using proxseg::bench::machine;
using proxseg::bench::ms_since;
using proxseg::bench::seconds_since;
using proxseg::bench::utc_now;
std::string fmt(double v, int digits = 1) {
  return proxseg::bench::fixed(v, digits);
}
std::string pct(double rate) {
  return proxseg::bench::percent(rate);
}
// ---------------------------------------------------------------------------------------------
// Distractors. splitmix64 draws: the same objects with every standard library (std::
// distributions are not portable).

struct Rng {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t x = (state += 0x9e3779b97f4a7c15ull);
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
  }
  double u() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double u(double lo, double hi) { return lo + (hi - lo) * u(); }
};

// Distractor j's own stream: a distractor does not change when others are added or removed.
Rng stream(std::uint64_t seed, std::uint64_t j) {
  Rng s{seed + 0x632be59bd9b4e019ull};
  Rng r{s.next() ^ (j * 0x9e3779b97f4a7c15ull)};
  r.state = r.next();
  return r;
}

Rgb from_hsv(double h, double s, double v) {
  return proxseg::to_rgb8(proxseg::hsv_to_rgb({h, s, v}));
}

// Packaging-like colours as the clutter generator draws them: a fifth nearly unsaturated
// (white, grey, black), the rest saturated.
Eigen::Vector3d random_hsv(Rng& r) {
  if (r.u() < 0.2) return {r.u(), r.u(0, 0.12), r.u() < 0.5 ? r.u(0.75, 0.95) : r.u(0.1, 0.55)};
  return {r.u(), r.u(0.35, 0.95), r.u(0.35, 0.95)};
}

// A second colour that stands out from the first: the hue turned by a third to two thirds, or
// (for a grey) a much brighter or darker value.
Eigen::Vector3d contrast_hsv(Rng& r, const Eigen::Vector3d& a) {
  if (a[1] < 0.2) return {r.u(), r.u(0.4, 0.9), a[2] > 0.5 ? r.u(0.2, 0.4) : r.u(0.7, 0.95)};
  return {a[0] + r.u(1.0 / 3, 2.0 / 3), r.u(0.3, 0.95), r.u(0.35, 0.95)};
}

struct Distractor {
  TestObject object;
  std::string kind;     // box, cylinder, look-alike
  std::string texture;  // plain, stripes, bands, checker; hue-turned for look-alikes
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  // extents, metres
  int original = -1;                               // look-alike: the tested object it copies
  double hue_turn = 0;                             // look-alike: turns (0-1)
  // Look-alike: the mean saturation x value of the vertex colours: how much a hue turn can
  // change (a grey mesh stays the same).
  double chroma = 0;
};

// The k-th box or cylinder (distractor j), 3-25 cm (cylinders 3-15 cm across: cans, jars,
// bottles), in one colour or textured with stripes, bands or a checkerboard of two contrasting
// colours. Kind and texture take turns (k even: box; texture k / 2 mod 4), so that even the
// smallest database holds each; sizes and colours are drawn.
Distractor primitive(std::uint64_t seed, int j, int k) {
  Rng r = stream(seed, static_cast<std::uint64_t>(j));
  Distractor d;
  const bool box = k % 2 == 0;
  d.kind = box ? "box" : "cylinder";
  if (box) {
    d.size = {r.u(0.03, 0.25), r.u(0.03, 0.25), r.u(0.03, 0.25)};
  } else {
    const double diameter = r.u(0.03, 0.15);
    d.size = {diameter, diameter, r.u(0.03, 0.25)};
  }
  const Eigen::Vector3d a = random_hsv(r), b = contrast_hsv(r, a);
  const Rgb ca = from_hsv(a[0], a[1], a[2]), cb = from_hsv(b[0], b[1], b[2]);
  static const char* const kTextures[] = {"plain", "stripes", "bands", "checker"};
  d.texture = kTextures[(k / 2) % 4];
  proxseg::ColourFn colour;
  if (d.texture == "plain") {
    colour = [ca](const Eigen::Vector3d&) { return ca; };
  } else if (d.texture == "stripes") {  // along a random axis, 2-6 cm period
    const int axis = std::min<int>(2, static_cast<int>(r.u() * 3));
    const double period = r.u(0.02, 0.06);
    colour = [ca, cb, axis, period](const Eigen::Vector3d& p) {
      const double x = p[axis] / period;
      return x - std::floor(x) < 0.5 ? ca : cb;
    };
  } else if (d.texture == "bands") {               // 1-3 horizontal bands of 1-5 cm, like a label
    std::vector<std::pair<double, double>> bands;  // centre, half width
    const int n = 1 + std::min<int>(2, static_cast<int>(r.u() * 3));
    for (int k = 0; k < n; ++k) bands.emplace_back(r.u(-0.5, 0.5) * d.size.z(), r.u(0.005, 0.025));
    colour = [ca, cb, bands](const Eigen::Vector3d& p) {
      for (const auto& [c, w] : bands)
        if (std::abs(p.z() - c) < w) return cb;
      return ca;
    };
  } else {  // checker, 1.5-4 cm cells
    const double cell = r.u(0.015, 0.04);
    colour = [ca, cb, cell](const Eigen::Vector3d& p) {
      const auto i = static_cast<long>(std::floor(p.x() / cell) + std::floor(p.y() / cell) +
                                       std::floor(p.z() / cell));
      return i % 2 == 0 ? ca : cb;
    };
  }
  char name[32];
  std::snprintf(name, sizeof name, "%s-%02d", d.kind.c_str(), j + 1);
  d.object.name = name;
  d.object.file = std::string(name) + " (generated " + d.texture + ")";
  d.object.mesh = box ? proxseg::make_box(Eigen::Isometry3d::Identity(), d.size, colour)
                      : proxseg::make_cylinder(Eigen::Isometry3d::Identity(), d.size.x() / 2,
                                               d.size.z(), colour);
  return d;
}

// A nearly grey mesh (mean saturation x value under this) is tinted as well as hue-turned: a
// hue turn leaves grey as it is, and a copy that looks the same under another name is not a
// look-alike but the same object, which no recogniser could tell apart (the LINEMOD can,
// driller, eggbox and glue are about 0.03-0.05; ape 0.38, duck 0.77).
constexpr double kGreyChroma = 0.1;
constexpr double kTintSaturation = 0.4;

// The tested mesh with every vertex colour's hue turned by `turn` (saturation and value kept, so
// that shading and texture stay and only the colour differs; a nearly grey mesh's saturation is
// raised to kTintSaturation): same shape, other object.
Distractor lookalike(const TestObject& o, int original, double turn) {
  Distractor d;
  d.kind = "look-alike";
  d.original = original;
  d.hue_turn = turn;
  d.object = o;
  for (const Rgb& c : o.mesh.colours) {
    const Eigen::Vector3d hsv = proxseg::rgb_to_hsv(c);
    d.chroma += hsv[1] * hsv[2];
  }
  if (!o.mesh.colours.empty()) d.chroma /= static_cast<double>(o.mesh.colours.size());
  const bool tint = d.chroma < kGreyChroma;
  d.texture = tint ? "hue-turned, tinted" : "hue-turned";
  d.object.name = o.name + "-hue" + fmt(360 * turn, 0);
  d.object.file = o.file + " (" + d.texture + " " + fmt(360 * turn, 0) + " deg)";
  for (Rgb& c : d.object.mesh.colours) {
    const Eigen::Vector3d hsv = proxseg::rgb_to_hsv(c);
    c = from_hsv(hsv[0] + turn, tint ? std::max(hsv[1], kTintSaturation) : hsv[1], hsv[2]);
  }
  Eigen::Vector3d lo = o.mesh.vertices.at(0).cast<double>(), hi = lo;
  for (const auto& v : o.mesh.vertices)
    lo = lo.cwiseMin(v.cast<double>()), hi = hi.cwiseMax(v.cast<double>());
  d.size = hi - lo;
  return d;
}

// The distractors, in database order: a look-alike every 7th place (the 1st, 8th, 15th, ...,
// until `lookalikes` of them), so that every database size holds hard negatives in about the
// same share; the others seeded boxes and cylinders.
std::vector<Distractor> distractors(const std::vector<TestObject>& tested, int count,
                                    int lookalikes, std::uint64_t seed) {
  const int max_lookalikes = std::min<int>(lookalikes, static_cast<int>(tested.size()));
  std::vector<Distractor> out(std::max(count, 0));
#pragma omp parallel for schedule(dynamic, 1)
  for (int j = 0; j < count; ++j) {
    if (j % 7 == 0 && j / 7 < max_lookalikes) {
      Rng r = stream(seed, static_cast<std::uint64_t>(j));
      // A third to two thirds of a turn: far enough in hue that colour can tell them apart.
      out[j] = lookalike(tested[j / 7], j / 7, r.u(1.0 / 3, 2.0 / 3));
    } else {
      out[j] = primitive(seed, j, j - std::min(j / 7 + 1, max_lookalikes));
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// The runs.

// What one recognition gave beyond rec_eval's Answer.
struct Extra {
  int views_aligned = 0;
  std::string best, runner_up;  // best view's object before thresholds, and the runner-up's
  bool truth_shortlisted = false;
  int best_rank = 0;  // the best view's place in the shortlist, 1 = nearest by signature
  double recognize_ms = 0;
};

struct Row {
  int views = 0, objects = 0, lookalikes = 0, shortlist = 0;
  std::vector<Answer> answers;
  std::vector<Extra> extra;
  std::string load_before, load_after;
};

// describe_candidate() + recognize(), timed (wall); the answer is recognize()'s name: an
// "unknown" (under min_score or min_margin) answers nothing.
std::pair<Answer, Extra> recognise(const TestView& t, const std::string& truth,
                                   const proxseg::Database& db,
                                   const proxseg::RecognitionParams& rp) {
  Answer a;
  Extra e;
  const auto t0 = Clock::now();
  try {
    const proxseg::Cloud c = proxseg::describe_candidate(
        t.points, db, t.colours.size() == t.points.size() ? &t.colours : nullptr);
    a.describe_ms = ms_since(t0);
    const auto t1 = Clock::now();
    const proxseg::Recognition r = proxseg::recognize(c, db, rp);
    e.recognize_ms = ms_since(t1);
    a.ms = ms_since(t0);
    if (r.name == r.best.object) a.best = r.name;
    a.score = r.best.score;
    a.pose = r.best.pose;
    e.views_aligned = r.views_aligned;
    e.best = r.best.object;
    e.runner_up = r.runner_up.object;
    // Untimed: did the shortlist hold a view of the right object at all, and where was the
    // view that won?
    if (rp.shortlist > 0) {
      const std::vector<int> shortlist = proxseg::shortlist_views(c, db, rp.shortlist);
      for (std::size_t k = 0; k < shortlist.size(); ++k) {
        e.truth_shortlisted |= db.views[shortlist[k]].object == truth;
        if (shortlist[k] == r.best.view) e.best_rank = static_cast<int>(k) + 1;
      }
    }
  } catch (const InputError&) {
    a.ms = ms_since(t0);  // too few points to describe: no answer
  }
  return {a, e};
}

// ---- One process per question: how a user meets the database ----

struct ProcessRun {
  int code = -1;
  double wall_s = 0, cpu_s = 0;
  std::string out;
};

// Runs argv (stdout to out_file, stderr discarded): wall from spawn to exit, the child's CPU
// (user + system) from wait4().
ProcessRun run_process(const std::vector<std::string>& argv, const std::string& out_file) {
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&files, 2, "/dev/null", O_WRONLY, 0);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  ProcessRun r;
  pid_t pid = 0;
  const auto t0 = Clock::now();
  const int failed = posix_spawn(&pid, args[0], &files, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  if (failed) throw InputError(argv[0] + ": cannot run (" + std::strerror(failed) + ")");
  int status = 0;
  rusage usage{};
  ::wait4(pid, &status, 0, &usage);
  r.wall_s = ms_since(t0) / 1000;
  r.cpu_s = usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
            (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(out_file);
  r.out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return r;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
}

// This process's peak resident set (VmHWM: of this program's memory since its exec). A parent's
// wait4() cannot tell it: Linux carries the RSS peak of the memory that spawned a child into the
// child's ru_maxrss.
double peak_rss_mb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6)) / 1024.0;
  return 0;
}

// `db_scale_bench --open DB [--object PCD]`: what opening costs a fresh process, and with
// --object, the peak RSS of `proxseg recognize --object` (the same calls, apps/recognize.cpp).
int open_only(const std::string& dir, const std::string& object) {
  const auto t0 = Clock::now();
  const proxseg::Database db = proxseg::load_database(dir);
  const double ms = ms_since(t0);
  nlohmann::json out = {{"views", db.views.size()}, {"ms", ms}, {"rss_mb", peak_rss_mb()}};
  if (!object.empty()) {
    const proxseg::SceneObject o =
        proxseg::recognize_object(proxseg::read_point_cloud(object), db, {});
    out["object"] = {{"name", o.recognition.name}, {"rss_mb", peak_rss_mb()}};
  }
  std::cout << out.dump() << "\n";
  return 0;
}

// Per database size: the file, opening it, and recognize --object processes.
struct ProcessRow {
  int views = 0;
  double file_mb = 0, open_ms = 0, open_rss_mb = 0;
  double wall_s = 0, cpu_s = 0, rss_mb = 0;  // recognize --object: medians, peak RSS the largest
  // Medians of the ratios to the smallest database's process run just before each (paired: the
  // sizes are minutes apart on a shared machine, whose speed drifts in between).
  double wall_ratio = 1, cpu_ratio = 1;
  int tests = 0, tp = 0;
};

// first_dir: the smallest database, whose runs pair with this one's (empty for it).
ProcessRow measure_processes(const std::string& self, const std::string& tools,
                             const std::string& dir, const std::string& first_dir,
                             const std::vector<std::string>& test_files,
                             const std::vector<std::string>& truths, double min_score,
                             const fs::path& scratch) {
  ProcessRow row;
  std::error_code ec;
  row.file_mb = fs::file_size(fs::path(dir) / proxseg::kDatabaseFile, ec) / 1e6;
  std::vector<double> open_ms;
  for (int i = 0; i < 5; ++i) {
    const ProcessRun r = run_process({self, "--open", dir}, (scratch / "open.json").string());
    if (r.code != 0) throw InputError(dir + ": opening it in a child process failed");
    const nlohmann::json j = nlohmann::json::parse(r.out);
    row.views = j["views"];
    open_ms.push_back(j["ms"]);
    row.open_rss_mb = std::max(row.open_rss_mb, j["rss_mb"].get<double>());
  }
  row.open_ms = median(open_ms);
  std::vector<double> wall, cpu, wall_ratio, cpu_ratio;
  const auto object = [&](const std::string& db, const std::string& test) {
    return run_process(
        {tools, "recognize", "--object", test, "--db", db, "--json", "--threads", "2"},
        (scratch / "object.json").string());
  };
  for (std::size_t i = 0; i < test_files.size(); ++i) {
    const ProcessRun first = first_dir.empty() ? ProcessRun{} : object(first_dir, test_files[i]);
    const ProcessRun r = object(dir, test_files[i]);
    if (r.code != 0) throw InputError(tools + " recognize --object " + test_files[i] + " failed");
    const nlohmann::json j = nlohmann::json::parse(r.out);
    const nlohmann::json& c = j["candidates"][0];
    ++row.tests;
    row.tp += c["name"] == truths[i] && c["score"].get<double>() >= min_score;
    wall.push_back(r.wall_s);
    cpu.push_back(r.cpu_s);
    if (!first_dir.empty()) {
      wall_ratio.push_back(r.wall_s / first.wall_s);
      cpu_ratio.push_back(r.cpu_s / first.cpu_s);
    }
    const ProcessRun peak = run_process({self, "--open", dir, "--object", test_files[i]},
                                        (scratch / "object-rss.json").string());
    if (peak.code != 0) throw InputError(dir + ": recognising in a child process failed");
    row.rss_mb =
        std::max(row.rss_mb, nlohmann::json::parse(peak.out)["object"]["rss_mb"].get<double>());
  }
  row.wall_s = median(wall);
  row.cpu_s = median(cpu);
  if (!first_dir.empty()) {
    row.wall_ratio = median(wall_ratio);
    row.cpu_ratio = median(cpu_ratio);
  }
  return row;
}

nlohmann::json counts_json(const std::map<std::string, int>& counts) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [k, n] : counts) j[k] = n;
  return j;
}

// "ape-hue150 (look-alike) 3, box-12 (box) 1", most first; "-" when empty.
std::string counts_md(const std::map<std::string, int>& counts,
                      const std::map<std::string, std::string>& kinds) {
  std::vector<std::pair<std::string, int>> v(counts.begin(), counts.end());
  std::stable_sort(v.begin(), v.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  std::string s;
  for (const auto& [name, n] : v) {
    const auto k = kinds.find(name);
    s += (s.empty() ? "" : ", ") + name + " (" + (k == kinds.end() ? "?" : k->second) + ") " +
         std::to_string(n);
  }
  return s.empty() ? "-" : s;
}

int run(const Options& o) {
  if (!o.open.empty()) return open_only(o.open, o.object);
  if (o.models.empty()) throw CLI::ValidationError("--models", "required");
  if (o.output.empty()) throw CLI::ValidationError("-o,--output", "required");
  std::vector<int> sizes = o.sizes;
  std::sort(sizes.begin(), sizes.end());
  sizes.erase(std::unique(sizes.begin(), sizes.end()), sizes.end());
  proxseg::RecognitionParams rp;
  rp.threads = o.threads;
  rp.seed = o.seed;
  proxseg::validate(rp);
  proxseg::RecognitionParams every = rp;
  every.shortlist = 0;   // every view, as the paper aligns them:
  every.early_exit = 0;  // none skipped either
  every.early_reject = 0;
  if (o.threads > 0) omp_set_num_threads(o.threads);
  const int team = o.threads > 0 ? o.threads : omp_get_max_threads();

  const std::vector<TestObject> tested =
      proxseg::read_test_objects(o.models, o.units == "mm" ? 0.001 : 1.0);
  const int n_tested = static_cast<int>(tested.size());
  for (int s : sizes)
    if (s % o.views != 0 || s < n_tested * o.views)
      throw CLI::ValidationError("--sizes", std::to_string(s) + ": not a multiple of --views (" +
                                                std::to_string(o.views) + ") of at least the " +
                                                std::to_string(n_tested * o.views) +
                                                " views of the tested objects");
  const fs::path out(o.output);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out))
    throw InputError(o.output + ": cannot create the output folder (" + ec.message() + ")");
  const std::string load_start = proxseg::bench::load_averages();
  // The database file, grown size by size, and the programs run per question.
  const fs::path db_dir = out / "db";
  fs::remove_all(db_dir, ec);
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  const std::string tools =
      o.tools.empty() ? (fs::path(self).parent_path().parent_path() / "proxseg-tools").string()
                      : o.tools;
  if (o.process_tests > 0 && !fs::exists(tools))
    throw InputError(tools + ": no proxseg-tools there (give --tools)");

  // Every object of the largest database, in database order: the tested ones first.
  auto t0 = Clock::now();
  const std::vector<Distractor> extra_objects =
      distractors(tested, sizes.back() / o.views - n_tested, o.lookalikes, o.seed);
  std::vector<TestObject> objects = tested;
  std::map<std::string, std::string> kinds;
  for (const TestObject& t : tested) kinds[t.name] = "tested";
  for (const Distractor& d : extra_objects) {
    objects.push_back(d.object);
    kinds[d.object.name] = d.kind;
  }
  std::cerr << "db_scale_bench: " << objects.size() << " objects (" << n_tested << " tested, "
            << extra_objects.size() << " distractors) in " << fmt(ms_since(t0) / 1000) << " s\n";

  // The tests avoid the viewpoints of the database (and those of 4 and 2 views per object, as
  // rec_bench's do, so that with 8 views the first tests are rec_bench's).
  std::vector<Eigen::Vector3d> directions;
  for (int n : {o.views, 4, 2})
    for (const auto& d : proxseg::view_sphere(n)) directions.push_back(d);
  proxseg::TestSetParams tp;
  tp.tests = o.tests;
  tp.seed = o.seed;
  t0 = Clock::now();
  const std::vector<TestView> tests = proxseg::make_test_views(tested, tp, directions);
  const int all_tests = std::min<int>(o.all_tests, static_cast<int>(tests.size()));
  // The process tests, as the PCD files a user would give.
  std::vector<std::string> test_files, test_truths;
  fs::create_directories(out / "tests", ec);
  for (int i = 0; i < std::min<int>(o.process_tests, static_cast<int>(tests.size())); ++i) {
    proxseg::Frame f;
    for (const auto& p : tests[i].points) f.xyz.push_back(p.cast<float>());
    if (tests[i].colours.size() == tests[i].points.size()) f.rgb = tests[i].colours;
    f.width = static_cast<int>(f.xyz.size());
    f.height = 1;
    char name[32];
    std::snprintf(name, sizeof name, "test-%03d.pcd", i);
    test_files.push_back((out / "tests" / name).string());
    proxseg::write_pcd(test_files.back(), f, {});
    test_truths.push_back(tested[tests[i].object].name);
  }
  bool coloured = true;
  for (const TestView& t : tests) coloured &= t.colours.size() == t.points.size();
  std::cerr << "db_scale_bench: " << tests.size() << " test views"
            << (coloured ? " with colours" : " (some without colour)") << " in "
            << fmt(ms_since(t0) / 1000) << " s\n";

  // One database file, grown from size to size: each is the previous one plus the next objects'
  // views, so the smaller databases are prefixes of the larger ones. The rows read it as a
  // program does (opened, each view read when first shortlisted).
  const proxseg::DescriptorParams descriptor;
  proxseg::Database db;
  int built = 0;  // objects in db
  std::vector<Row> rows;
  std::vector<ProcessRow> process_rows;
  const auto every_sizes =
      std::count_if(sizes.begin(), sizes.end(), [&](int n) { return n <= o.all_max_views; });
  cli::Progress progress(sizes.size() * tests.size() + every_sizes * all_tests);
  for (int size : sizes) {
    t0 = Clock::now();
    const int n_objects = size / o.views;
    {
      const proxseg::Database part = proxseg::render_database(
          std::vector<TestObject>(objects.begin() + built, objects.begin() + n_objects), o.views,
          descriptor);
      // Closed first: the write's connection is then the last one, and folds its write-ahead
      // log into the file when it closes (the file's size is the database's).
      db = proxseg::Database{};
      proxseg::write_database(part, db_dir.string());
    }
    db = proxseg::load_database(db_dir.string());
    built = n_objects;
    std::cerr << "db_scale_bench: database of " << db.views.size() << " views (" << n_objects
              << " objects): " << fmt(ms_since(t0) / 1000) << " s to render, describe and store "
              << "the views added\n";
    if (!test_files.empty()) {
      // The smallest database stays beside the grown one: the larger sizes' runs pair with it.
      const fs::path first_dir = out / "db-smallest";
      if (process_rows.empty()) {
        fs::remove_all(first_dir, ec);
        fs::create_directories(first_dir);
        fs::copy_file(db_dir / proxseg::kDatabaseFile, first_dir / proxseg::kDatabaseFile);
      }
      process_rows.push_back(measure_processes(self, tools, db_dir.string(),
                                               process_rows.empty() ? "" : first_dir.string(),
                                               test_files, test_truths, rp.min_score, out));
      const ProcessRow& p = process_rows.back();
      std::cerr << "db_scale_bench: " << p.views << " views, " << fmt(p.file_mb, 0) << " MB: open "
                << fmt(p.open_ms, 1) << " ms, " << fmt(p.open_rss_mb, 0)
                << " MB; recognize --object " << fmt(p.wall_s, 2) << " s wall, " << fmt(p.cpu_s, 2)
                << " s CPU, " << fmt(p.rss_mb, 0) << " MB, TP " << p.tp << "/" << p.tests << "\n";
    }
    int lookalikes = 0;
    for (int j = 0; j < n_objects - n_tested; ++j)
      lookalikes += extra_objects[j].kind == "look-alike";
    for (const proxseg::RecognitionParams* p : {&rp, &every}) {
      const int n = p == &rp ? static_cast<int>(tests.size()) : all_tests;
      if (n == 0 || (p == &every && size > o.all_max_views)) continue;
      Row r;
      r.views = static_cast<int>(db.views.size());
      r.objects = n_objects;
      r.lookalikes = lookalikes;
      r.shortlist = p->shortlist;
      // One untimed test first: first-call costs are not the per-candidate cost.
      recognise(tests.front(), tested[tests.front().object].name, db, *p);
      r.load_before = proxseg::bench::load_averages();
      for (int i = 0; i < n; ++i) {
        const TestView& t = tests[i];
        auto [a, e] = recognise(t, tested[t.object].name, db, *p);
        progress.step(std::to_string(size) + " views, shortlist " + std::to_string(p->shortlist) +
                      ": " + tested[t.object].name + " -> " +
                      (a.best.empty() ? "unknown" : a.best));
        r.answers.push_back(std::move(a));
        r.extra.push_back(std::move(e));
      }
      r.load_after = proxseg::bench::load_averages();
      rows.push_back(std::move(r));
    }
  }
  const std::string load_end = proxseg::bench::load_averages();

  // The measures.
  const double m = rp.min_score;
  struct Summary {
    proxseg::Rates rates;
    double describe_ms = 0, recognize_ms = 0, views_aligned = 0, best_right = 0, shortlisted = 0,
           best_rank = 0;
    std::map<std::string, int> wrong, unknown_runner_up;
  };
  // Over the first n answers of a row.
  const auto summarise = [&](const Row& r, std::size_t n) {
    n = std::min(n, r.answers.size());
    Summary s;
    const std::vector<Answer> answers(r.answers.begin(), r.answers.begin() + n);
    s.rates = proxseg::rates(tests, answers, tested, m);
    for (std::size_t i = 0; i < n; ++i) {
      const Answer& a = r.answers[i];
      const Extra& e = r.extra[i];
      const std::string& truth = tested[tests[i].object].name;
      s.describe_ms += a.describe_ms;
      s.recognize_ms += e.recognize_ms;
      s.views_aligned += e.views_aligned;
      s.best_right += e.best == truth;
      s.shortlisted += e.truth_shortlisted;
      s.best_rank += e.best_rank;
      if (!a.best.empty() && a.score >= m && a.best != truth) ++s.wrong[a.best];
      if (a.best.empty() || a.score < m) {
        const std::string& in_the_way = e.best == truth ? e.runner_up : e.best;
        if (!in_the_way.empty()) ++s.unknown_runner_up[in_the_way];
      }
    }
    if (n > 0)
      for (double* x : {&s.describe_ms, &s.recognize_ms, &s.views_aligned, &s.best_right,
                        &s.shortlisted, &s.best_rank})
        *x /= static_cast<double>(n);
    return s;
  };
  const auto row_of = [&](int views, int shortlist) -> const Row* {
    for (const Row& r : rows)
      if (r.views == views && r.shortlist == shortlist) return &r;
    return nullptr;
  };

  nlohmann::json summary;
  summary["parameters"] = {{"models", o.models},
                           {"views_per_object", o.views},
                           {"sizes", sizes},
                           {"tests", tests.size()},
                           {"all_view_tests", all_tests},
                           {"test_colours", coloured},
                           {"seed", o.seed},
                           {"threads", team},
                           {"test_set",
                            {{"min_distance", tp.min_distance},
                             {"max_distance", tp.max_distance},
                             {"depth_noise", tp.depth_noise},
                             {"disparity_step", tp.disparity_step},
                             {"min_angle_to_view_deg", tp.min_angle_to_view_deg}}},
                           {"recognition", proxseg::to_json(rp)}};
  summary["machine"] = machine();
  summary["date"] = utc_now();
  summary["commit"] = proxseg::bench::git_commit();
  summary["loadavg"] = {{"start", load_start}, {"end", load_end}};
  summary["objects"] = nlohmann::json::array();
  for (std::size_t i = 0; i < objects.size(); ++i) {
    nlohmann::json j = {{"name", objects[i].name}, {"file", objects[i].file}};
    if (i < tested.size()) {
      j["kind"] = "tested";
    } else {
      const Distractor& d = extra_objects[i - tested.size()];
      j["kind"] = d.kind;
      j["texture"] = d.texture;
      j["size_m"] = {d.size.x(), d.size.y(), d.size.z()};
      if (d.original >= 0) {
        j["hue_turn_deg"] = 360 * d.hue_turn;
        j["mean_chroma"] = d.chroma;
      }
    }
    summary["objects"].push_back(j);
  }
  summary["rows"] = nlohmann::json::array();
  for (const Row& r : rows) {
    const Summary s = summarise(r, r.answers.size());
    nlohmann::json j = {
        {"views", r.views},
        {"objects", r.objects},
        {"lookalikes", r.lookalikes},
        {"shortlist", r.shortlist},
        {"tests", s.rates.tests},
        {"tp_rate", s.rates.tp_rate()},
        {"fp_rate", s.rates.fp_rate()},
        {"unknown_rate", s.rates.tests ? double(s.rates.unknown) / s.rates.tests : 0.0},
        {"pose_rate", s.rates.pose_rate()},
        {"best_right_rate", s.best_right},
        {"mean_ms", s.rates.mean_ms},
        {"mean_describe_ms", s.describe_ms},
        {"mean_recognize_ms", s.recognize_ms},
        {"mean_views_aligned", s.views_aligned},
        {"wrong_answers", counts_json(s.wrong)},
        {"unknown_runner_up", counts_json(s.unknown_runner_up)},
        {"loadavg_before", r.load_before},
        {"loadavg_after", r.load_after}};
    if (r.shortlist > 0) {
      j["truth_shortlisted_rate"] = s.shortlisted;
      j["mean_best_view_rank"] = s.best_rank;
    }
    summary["rows"].push_back(j);
  }
  // The acceptance: the cost of the largest database against the smallest, shortlist default.
  const Row* small = row_of(sizes.front(), rp.shortlist);
  const Row* large = row_of(sizes.back(), rp.shortlist);
  double ratio = 0, ratio_every = 0;
  if (small && large) {
    ratio = summarise(*large, large->answers.size()).rates.mean_ms /
            summarise(*small, small->answers.size()).rates.mean_ms;
    summary["cost_ratio"] = {{"views", {sizes.front(), sizes.back()}}, {"ratio", ratio}};
  }
  const Row* small_every = row_of(sizes.front(), 0);
  const Row* large_every = row_of(sizes.back(), 0);
  if (small_every && large_every) {
    ratio_every = summarise(*large_every, all_tests).rates.mean_ms /
                  summarise(*small_every, all_tests).rates.mean_ms;
    summary["cost_ratio_every_view"] = ratio_every;
  }

  summary["processes"] = nlohmann::json::array();
  for (const ProcessRow& p : process_rows)
    summary["processes"].push_back({{"views", p.views},
                                    {"file_mb", p.file_mb},
                                    {"open_ms", p.open_ms},
                                    {"open_rss_mb", p.open_rss_mb},
                                    {"object_wall_s", p.wall_s},
                                    {"object_cpu_s", p.cpu_s},
                                    {"object_rss_mb", p.rss_mb},
                                    {"object_wall_ratio", p.wall_ratio},
                                    {"object_cpu_ratio", p.cpu_ratio},
                                    {"tests", p.tests},
                                    {"tp", p.tp}});

  // The report.
  std::ostringstream md;
  int n_box = 0, n_cylinder = 0, n_lookalike = 0;
  for (const Distractor& d : extra_objects)
    (d.kind == "box" ? n_box : d.kind == "cylinder" ? n_cylinder : n_lookalike) += 1;
  md << "## Recognition against database size (" << sizes.front() << "-" << sizes.back()
     << " views)\n\n"
     << "Generated by `make bench-dbscale` (bench/db_scale_bench.cpp) at commit "
     << proxseg::bench::git_commit() << " on " << machine() << ", " << utc_now() << "; seed "
     << o.seed << ", " << team << " threads. Load average (1, 5, 15 min): " << load_start
     << " at the start, " << load_end
     << " at the end (the machine is shared: times compare within this run only).\n\n"
     << "Objects tested: the " << n_tested << " meshes of `"
     << fs::path(o.models).filename().string()
     << "` (LINEMOD). Distractors fill each database: " << n_box << " boxes and " << n_cylinder
     << " cylinders (seeded, 3-25 cm, plain or striped, banded, checkered in two contrasting "
        "colours) and "
     << n_lookalike
     << " look-alikes (a tested mesh with every hue turned by 120-240 degrees, nearly grey "
        "meshes also tinted to saturation "
     << fmt(kTintSaturation, 1) << ": same shape, other colour), one every 7th distractor. "
     << o.views << " noiseless render_views() per object; each database is a prefix of the next. "
     << "Tests: " << tests.size() << " make_test_views() of the tested objects (round-robin), "
     << (coloured ? "with their rendered colours" : "without colour") << ", "
     << fmt(tp.min_distance, 1) << "-" << fmt(tp.max_distance, 1)
     << " m, Kinect-like noise, at least " << fmt(tp.min_angle_to_view_deg, 0)
     << " degrees from every database viewpoint. Each test: describe_candidate() + recognize() "
        "with the default RecognitionParams (shortlist "
     << rp.shortlist << ", min_score " << fmt(m, 2) << ", min_margin " << fmt(rp.min_margin, 2)
     << "); the shortlist 0 rows align every view (the paper's way) on the first " << all_tests
     << " tests only (their cost grows with the views). TP: recognize() names the object; FP: it "
        "names another; unknown: it answers \"unknown\" (min_score or min_margin); pose ok: "
        "named right and within 2 cm and 10 degrees. Best view right: the best view's object "
        "before the thresholds. Shortlisted: a view of the right object was among the views "
        "aligned. Best view's rank: its place in the shortlist (1 = nearest by signature), "
        "mean. ms: describe + recognition, wall, per candidate.\n\n";
  md << "| views | objects (look-alikes) | shortlist | tests | views aligned | ms / candidate | TP "
        "(%) | FP (%) | unknown (%) | pose ok (%) | best view right (%) | shortlisted (%) | best "
        "view's rank | load before / after |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    const Summary s = summarise(r, r.answers.size());
    md << "| " << r.views << " | " << r.objects << " (" << r.lookalikes << ") | "
       << (r.shortlist > 0 ? std::to_string(r.shortlist) : "0 (every view)") << " | "
       << s.rates.tests << " | " << fmt(s.views_aligned, 1) << " | " << fmt(s.rates.mean_ms, 0)
       << " | " << pct(s.rates.tp_rate()) << " | " << pct(s.rates.fp_rate()) << " | "
       << pct(s.rates.tests ? double(s.rates.unknown) / s.rates.tests : 0) << " | "
       << pct(s.rates.pose_rate()) << " | " << pct(s.best_right) << " | "
       << (r.shortlist > 0 ? pct(s.shortlisted) : "-") << " | "
       << (r.shortlist > 0 ? fmt(s.best_rank, 1) : "-") << " | "
       << r.load_before.substr(0, r.load_before.find(' ')) << " / "
       << r.load_after.substr(0, r.load_after.find(' ')) << " |\n";
  }
  if (small && large && small != large)
    md << "\nCost of " << sizes.back() << " views against " << sizes.front() << " (shortlist "
       << rp.shortlist << "): ms(" << sizes.back() << ") / ms(" << sizes.front()
       << ") = " << fmt(ratio, 2) << " (acceptance: at most 2: " << (ratio <= 2 ? "met" : "not met")
       << ")"
       << (small_every && large_every && small_every != large_every
               ? "; every view: " + fmt(ratio_every, 2)
               : std::string())
       << ".\n";
  if (!process_rows.empty()) {
    const ProcessRow& base = process_rows.front();
    md << "\n### The database file, one process per question\n\n"
       << "Each size stored in one database file (`proxseg db` format, docs/database.md). Open: "
          "a fresh process runs load_database() (median of 5; RSS: the process's peak after "
          "opening, libraries included). recognize --object: `proxseg recognize --object TEST "
          "--db DB --json --threads 2` on the first "
       << base.tests
       << " test views (as PCD files with their colours), one process each: median wall and "
          "CPU (user + system) from spawn to exit, the largest peak RSS, and the answers named "
          "right (TP, min_score "
       << fmt(m, 2)
       << "). x smallest: the median ratio to the smallest database's run of the same test just "
          "before (paired, so that the machine's drift between sizes cancels).\n\n"
       << "| views | file (MB) | open (ms) | RSS after open (MB) | recognize --object wall (s) | "
          "x smallest | CPU (s) | x smallest | peak RSS (MB) | TP |\n"
       << "|---|---|---|---|---|---|---|---|---|---|\n";
    for (const ProcessRow& p : process_rows)
      md << "| " << p.views << " | " << fmt(p.file_mb, 0) << " | " << fmt(p.open_ms, 1) << " | "
         << fmt(p.open_rss_mb, 0) << " | " << fmt(p.wall_s, 2) << " | " << fmt(p.wall_ratio, 2)
         << " | " << fmt(p.cpu_s, 2) << " | " << fmt(p.cpu_ratio, 2) << " | " << fmt(p.rss_mb, 0)
         << " | " << p.tp << "/" << p.tests << " |\n";
  }
  if (all_tests > 0) {
    md << "\n### Shortlist against every view, on the same first " << all_tests << " tests\n\n"
       << "| views | TP shortlist / every view (%) | FP (%) | unknown (%) | pose ok (%) | ms "
          "shortlist / every view | speed-up |\n"
       << "|---|---|---|---|---|---|---|\n";
    for (int size : sizes) {
      const Row* d = row_of(size, rp.shortlist);
      const Row* e = row_of(size, 0);
      if (!d || !e) continue;
      const Summary a = summarise(*d, all_tests), b = summarise(*e, all_tests);
      const auto unk = [](const proxseg::Rates& x) {
        return x.tests ? double(x.unknown) / x.tests : 0.0;
      };
      md << "| " << size << " | " << pct(a.rates.tp_rate()) << " / " << pct(b.rates.tp_rate())
         << " | " << pct(a.rates.fp_rate()) << " / " << pct(b.rates.fp_rate()) << " | "
         << pct(unk(a.rates)) << " / " << pct(unk(b.rates)) << " | " << pct(a.rates.pose_rate())
         << " / " << pct(b.rates.pose_rate()) << " | " << fmt(a.rates.mean_ms, 0) << " / "
         << fmt(b.rates.mean_ms, 0) << " | " << fmt(b.rates.mean_ms / a.rates.mean_ms, 1) << " |\n";
    }
  }
  md << "\n### What takes the answers\n\n"
     << "Per row: the objects named wrongly (FP), and for the unknown answers the object that "
        "stood in the way (the wrong best view, or the runner-up of a right one).\n\n"
     << "| views | shortlist | wrong answers | unknown: in the way |\n|---|---|---|---|\n";
  for (const Row& r : rows) {
    const Summary s = summarise(r, r.answers.size());
    md << "| " << r.views << " | " << r.shortlist << " | " << counts_md(s.wrong, kinds) << " | "
       << counts_md(s.unknown_runner_up, kinds) << " |\n";
  }
  md << "\nEvery object (kind, texture, size, hue turn) and row (stage times, load) is in "
        "`dbscale.json`.\n";

  return proxseg::bench::finish(
      out, {{"dbscale.md", md.str()}, {"dbscale.json", summary.dump(2) + "\n"}}, summary, md.str(),
      o.json);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "db_scale_bench: recognition cost and accuracy against the database size (tested "
      "LINEMOD meshes + seeded distractors), shortlist against every view"};
  Options o;
  add_options(&app, o);
  // --sizes is checked by run(), as a usage error.
  return proxseg::bench::main_of("db_scale_bench", app, argc, argv, [&] { return run(o); });
}
