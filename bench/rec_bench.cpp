// rec_bench (`make bench-rec`): the paper's recognition experiments [4, Tables 2-3, Fig. 3] on
// meshes (BOP LINEMOD by default): a model database rendered from fixed viewpoints, a seeded test
// set from other viewpoints with Kinect-like noise, the same set through the paper's occlusion
// generator, sweeps of the database size, FPFH radii and RANSAC / ICP iterations, and the peers
// (Open3D RANSAC + ICP, PCL SAC-prerejective + ICP, OpenCV PPF + ICP, Open3D FGR + ICP; built
// when PCL is, PPF when OpenCV contrib is too) on the same test views.
// Writes OUT/summary.md, summary.json, tests.csv, curves.csv and, with gnuplot, roc.png and
// pr.png (docs/metrics.md, "Recognition"). Exit codes: 0 ok, 1 bad input, 2 usage.
// Usage: rec_bench --models DIR -o OUT [--units mm|m] [--views N] [--tests N]
//                  [--occluded-tests N] [--sweep-tests N] [--no-sweep] [--peers all|none|LIST]
//                  [--peer-tests N] [--seed S] [--threads T] [--config FILE] [--json]
#include "bench_main.hpp"
#include "bench_util.hpp"

#include <proxseg/eval/pose_error.hpp>
#include <proxseg/eval/rec_eval.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/memory.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <omp.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "progress.hpp"  // apps/progress.hpp: the CLI's progress bar

#ifdef PROXSEG_WITH_PEERS
#include "peers_rec.hpp"
#endif

namespace {

using proxseg::Answer;
using proxseg::InputError;
using proxseg::TestView;

struct Options {
  std::string models, output, config, units = "mm", peers = "all";
  int views = 8, tests = 2241, occluded_tests = 600, sweep_tests = 200, peer_tests = 60;
  int threads = 0;
  std::uint64_t seed = 1;
  bool no_sweep = false, json = false;
};

void add_options(CLI::App* cmd, Options& o) {
  cmd->add_option("--models", o.models, "Folder of PLY meshes (e.g. ../shared/data/lmo/models)")
      ->required();
  cmd->add_option("--units", o.units, "Units of the meshes")
      ->check(CLI::IsMember({"m", "mm"}))
      ->capture_default_str();
  cmd->add_option("-o,--output", o.output, "Output folder (summary.md, summary.json, CSV, PNG)")
      ->required();
  cmd->add_option("--views", o.views, "Database views per object")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--tests", o.tests, "Test views without occlusion (paper: 2241)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--occluded-tests", o.occluded_tests,
                  "Occluded test views (the first tests, spread evenly over the 6 bins)")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  cmd->add_option("--sweep-tests", o.sweep_tests,
                  "Tests of each sweep row (database size, FPFH radii, iterations)")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  cmd->add_flag("--no-sweep", o.no_sweep, "Skip the sweeps");
  cmd->add_option("--peers", o.peers,
                  "Peers to run: all (those built), none, or a list of open3d,pcl,ppf,fgr")
      ->capture_default_str();
  cmd->add_option("--peer-tests", o.peer_tests,
                  "Tests the peers run, of each set (clean and occluded)")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  cmd->add_option("--seed", o.seed, "Seed of the test set, the occlusions and every RANSAC")
      ->capture_default_str();
  cmd->add_option("--threads", o.threads,
                  "Threads (0 = all cores); proxseg's answers do not depend on it (the peers' may)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  cmd->add_option(
      "--config", o.config,
      "JSON {\"recognition\": {...}} over the defaults (as proxseg recognize --config)");
  cmd->add_flag("--json", o.json, "Print summary.json on stdout");
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
std::string radii_mm(const std::vector<double>& radii) {
  std::string s;
  for (double r : radii) s += (s.empty() ? "" : ", ") + fmt(1000 * r, 0);
  return s;
}

std::string bin_name(const proxseg::OcclusionBin& b) {
  return fmt(100 * b.lo, 0) + "-" + fmt(100 * b.hi, 0);
}

// The paper's figures [4, Tables 2 and 3] printed beside ours.
struct PaperTest {
  const char* name;
  int views;
  const char* radii;
  int ransac, icp, tp, fp;
};
constexpr PaperTest kPaperTable2[] = {{"test01", 61, "3, 5, 10, 20, 30, 50", 200, 200, 80, 20},
                                      {"test02", 32, "3, 5, 10, 20, 30, 50", 200, 200, 70, 30},
                                      {"test03", 61, "3, 10, 30", 200, 200, 83, 17},
                                      {"test04", 24, "3, 5, 10, 20, 30, 50", 200, 200, 60, 40},
                                      {"test05", 61, "5, 15", 200, 200, 81, 19},
                                      {"test06", 61, "3, 10, 30", 100, 150, 81, 19},
                                      {"test07", 32, "5, 15", 200, 200, 73, 27},
                                      {"test08", 32, "3, 10, 30", 100, 150, 70, 30},
                                      {"test09", 32, "5, 15", 100, 150, 69, 31}};
constexpr int kPaperTable3Tp[] = {76, 70, 60, 47, 37, 23};
// "test02 (32 views, 3, 5, 10, 20, 30, 50 mm, 200 / 200 it.): 70 / 30"
std::string paper_row(int i) {
  if (i < 0) return "";
  const PaperTest& p = kPaperTable2[i];
  return std::string(p.name) + " (" + std::to_string(p.views) + " views, " + p.radii + " mm, " +
         std::to_string(p.ransac) + " / " + std::to_string(p.icp) +
         " it.): " + std::to_string(p.tp) + " / " + std::to_string(p.fp);
}

// One row of the tables: a recogniser and the prefixes of the two test sets it runs.
struct Row {
  std::string label, kind;  // kind: proxseg (defaults), sweep, peer
  int paper = -1;           // the paper's analogue: index into kPaperTable2, -1 = none
  int views = 0, ransac = 0, icp = 0;
  std::vector<double> radii;
  double train_ms = 0;  // a peer's one-off preparation of the database (PPF's training), untimed
  std::function<Answer(const TestView&)> run;
  int clean_tests = 0, occluded_tests = 0;
  std::vector<Answer> clean, occluded;
};

// Algorithm 3 as proxseg does it: describe the test view like the database, align every view.
std::function<Answer(const TestView&)> proxseg_recogniser(const proxseg::Database& db,
                                                          const proxseg::RecognitionParams& rp) {
  return [&db, rp](const TestView& t) {
    const auto t0 = Clock::now();
    Answer a;
    try {
      const proxseg::Cloud c = proxseg::describe_candidate(t.points, db);
      a.describe_ms = ms_since(t0);
      const proxseg::Recognition r = proxseg::recognize(c, db, rp);
      a.best = r.best.object;
      a.score = r.best.score;
      a.pose = r.best.pose;
      for (const proxseg::Alignment& x : r.alignments) {
        a.ransac_ms += x.ransac_ms;
        a.icp_ms += x.icp_ms;
        a.score_ms += x.score_ms;
      }
    } catch (const InputError&) {
      // Too few points left to describe (a heavy occlusion of a far view): no answer.
    }
    a.ms = ms_since(t0);
    return a;
  };
}

#ifdef PROXSEG_WITH_PEERS
// Names the test after the best-scoring view exactly as proxseg::recognize does (the same
// scores, score rule and ties to the earlier view) from a peer's poses, so that the rows compare
// whole recognisers that differ only in registration.
template <class Peer>
std::function<Answer(const TestView&)> peer_recogniser(const Peer& peer,
                                                       const proxseg::Database& db,
                                                       const proxseg::RecognitionParams& rp,
                                                       int threads) {
  return [&peer, &db, rp, threads](const TestView& t) {
    const auto t0 = Clock::now();
    Answer a;
    proxseg::Cloud c;
    try {
      c = proxseg::describe_candidate(t.points, db);
    } catch (const InputError&) {
      a.ms = ms_since(t0);
      return a;
    }
    a.describe_ms = ms_since(t0);
    const std::vector<proxseg::peers::PeerAlignment> aligned =
        peer.align(c, static_cast<int>(rp.seed));
    const int n = static_cast<int>(aligned.size());
    std::vector<double> score(n, 0), rank(n, 0), score_ms(n, 0);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int v = 0; v < n; ++v) {
      if (!aligned[v].found) continue;  // no hypothesis, no pose to score: 0
      const auto ts = Clock::now();
      const proxseg::Alignment scored =
          proxseg::score_pose(c, db.views[v].cloud(), aligned[v].pose, rp.registration);
      score[v] = proxseg::score_of(scored, rp.score);
      rank[v] = proxseg::rank_of(scored, rp.score);
      score_ms[v] = ms_since(ts);
    }
    for (int v = 0; v < n; ++v) {
      a.ransac_ms += aligned[v].ransac_ms;
      a.icp_ms += aligned[v].icp_ms;
      a.score_ms += score_ms[v];
    }
    // Ranked allowing for an occlusion, judged on the score, as recognize() does.
    const int best = static_cast<int>(std::max_element(rank.begin(), rank.end()) - rank.begin());
    if (n > 0 && aligned[best].found) {
      a.best = db.views[best].object;
      a.score = score[best];
      a.pose = aligned[best].pose;
    }
    a.ms = ms_since(t0);
    return a;
  };
}
#endif

// The peers in the order of their rows (and of --peers all).
constexpr const char* kPeerNames[] = {"open3d", "pcl", "ppf", "fgr"};

std::vector<std::string> peer_list(const std::string& spec) {
  std::vector<std::string> available;
#ifdef PROXSEG_WITH_PEERS
  available = {"open3d", "pcl", "fgr"};
#ifdef PROXSEG_WITH_PPF
  available.insert(available.begin() + 2, "ppf");
#endif
#endif
  if (spec == "none") return {};
  if (spec == "all") return available;
  std::vector<std::string> out;
  std::stringstream in(spec);
  std::string name;
  while (std::getline(in, name, ',')) {
    if (std::find(std::begin(kPeerNames), std::end(kPeerNames), name) == std::end(kPeerNames))
      throw CLI::ValidationError("--peers: unknown peer '" + name +
                                 "' (expected open3d, pcl, ppf, fgr)");
    if (std::find(available.begin(), available.end(), name) == available.end())
      throw CLI::ValidationError(
          "--peers: this build has no peer '" + name +
          "' (PCL, or OpenCV contrib for ppf, was not found when it was built: run "
          "scripts/install-deps.sh --bench, then rebuild)");
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
  }
  return out;
}

// Removes the previous run's database, but never a directory that is not one.
void reset_db_dir(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  if (!fs::exists(dir)) return;
  if (!fs::is_directory(dir) || (!fs::is_empty(dir) && !fs::exists(dir / "index.json")))
    throw InputError(dir.string() + ": exists and is not a proxseg database");
  fs::remove_all(dir);
}

nlohmann::json rates_json(const proxseg::Rates& r) {
  return {
      {"tests", r.tests},           {"tp_rate", r.tp_rate()},
      {"fp_rate", r.fp_rate()},     {"unknown_rate", r.tests ? double(r.unknown) / r.tests : 0.0},
      {"pose_rate", r.pose_rate()}, {"mean_ms", r.mean_ms}};
}

// A gnuplot script that draws curves (inline data blocks) into a PNG.
// Each curve has its own colour (the method's or the bin's, from a palette of 12); the occluded
// curves of the ROC are dashed in their method's colour.
struct Curve {
  std::string title;
  std::vector<std::pair<double, double>> xy;
  int colour = 0;
  bool dashed = false;
};
constexpr const char* kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                    "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                                    "#bcbd22", "#17becf", "#000000", "#aec7e8"};
std::string gnuplot_script(const std::string& png, const std::string& title,
                           const std::string& xlabel, const std::string& ylabel,
                           const std::vector<Curve>& curves, const std::string& key,
                           double xmax = 1) {
  std::ostringstream s;
  s << "# Generated by bench/rec_bench; run: gnuplot " << png.substr(0, png.size() - 4) << ".gp\n";
  for (std::size_t i = 0; i < curves.size(); ++i) {
    s << "$c" << i << " << EOD\n";
    for (const auto& [x, y] : curves[i].xy) s << x << " " << y << "\n";
    s << "EOD\n";
  }
  s << "set terminal pngcairo size 900,650 font 'sans,11'\nset output '" << png << ".tmp'\n"
    << "set title '" << title << "'\nset xlabel '" << xlabel << "'\nset ylabel '" << ylabel
    << "'\nset xrange [0:" << xmax << "]\nset yrange [0:1.02]\nset grid\nset key " << key
    << "\nplot ";
  for (std::size_t i = 0; i < curves.size(); ++i)
    s << (i ? ", \\\n     " : "") << "$c" << i << " with lines linewidth 2 linecolor rgb '"
      << kPalette[curves[i].colour % 12] << "' dashtype " << (curves[i].dashed ? 2 : 1)
      << " title '" << curves[i].title << "'";
  s << "\nset output\n";
  return s.str();
}

// Runs gnuplot on OUT/name.gp and moves the PNG into place; false when gnuplot is missing or
// fails (the CSV holds the same curves).
bool plot(const std::filesystem::path& dir, const std::string& name, const std::string& script) {
  proxseg::write_file_atomic((dir / (name + ".gp")).string(), script);
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) return false;
  const std::string cmd = "cd '" + dir.string() + "' && gnuplot " + name + ".gp 2>&1";
  if (std::system(cmd.c_str()) != 0) return false;
  std::filesystem::rename(dir / (name + ".png.tmp"), dir / (name + ".png"));
  return true;
}

int run(const Options& o) {
  namespace fs = std::filesystem;
  const std::vector<std::string> peers = peer_list(o.peers);
  proxseg::RecognitionParams rp;
  if (!o.config.empty()) rp = proxseg::read_recognize_params(o.config, {}, rp).second;
  rp.threads = o.threads;
  rp.seed = o.seed;
  proxseg::validate(rp);
  if (o.threads > 0) omp_set_num_threads(o.threads);
  const int team = o.threads > 0 ? o.threads : omp_get_max_threads();

  const std::vector<proxseg::TestObject> objects =
      proxseg::read_test_objects(o.models, o.units == "mm" ? 0.001 : 1.0);
  const fs::path out(o.output);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out))
    throw InputError(o.output + ": cannot create the output folder (" + ec.message() + ")");
  const fs::path db_dir = out / "db";
  reset_db_dir(db_dir);

  // The database, built and read back as a user would; then the test sets.
  auto t0 = Clock::now();
  const proxseg::DescriptorParams descriptor;
  const proxseg::Database db =
      proxseg::render_database(objects, o.views, descriptor, db_dir.string());
  std::cerr << "rec_bench: database of " << db.views.size() << " views (" << objects.size()
            << " objects x " << o.views << ") in " << fmt(ms_since(t0) / 1000) << " s\n";
  // Tests avoid the viewpoints of every database of the run (and of the sweeps' 4 and 2 views
  // even without sweeps, so that the test set depends only on --views, --tests and --seed).
  std::vector<Eigen::Vector3d> directions;
  for (int n : {o.views, 4, 2})
    for (const auto& d : proxseg::view_sphere(n)) directions.push_back(d);
  proxseg::TestSetParams tp;
  tp.tests = o.tests;
  tp.seed = o.seed;
  t0 = Clock::now();
  const std::vector<TestView> clean = proxseg::make_test_views(objects, tp, directions);
  const std::vector<proxseg::OcclusionBin> bins = proxseg::paper_occlusion_bins();
  const std::vector<TestView> occluded =
      proxseg::occluded_test_views(clean, o.occluded_tests, bins, o.seed);
  std::cerr << "rec_bench: " << clean.size() << " test views and " << occluded.size()
            << " occluded ones in " << fmt(ms_since(t0) / 1000) << " s\n";

  // The rows: proxseg's defaults, the sweeps (one change each, like Table 2), the peers.
  std::vector<Row> rows;
  std::vector<std::unique_ptr<proxseg::Database>> sweep_dbs;
  const auto add_proxseg = [&](const std::string& label, const std::string& kind, int paper,
                               const proxseg::Database& d, const proxseg::RecognitionParams& p,
                               int views) {
    Row r;
    r.label = label;
    r.kind = kind;
    r.paper = paper;
    r.views = views;
    r.radii = d.descriptor.fpfh_radii;
    r.ransac = p.registration.ransac_iterations;
    r.icp = p.registration.icp_iterations;
    r.run = proxseg_recogniser(d, p);
    rows.push_back(std::move(r));
  };
  add_proxseg("proxseg", "proxseg", 0, db, rp, o.views);
  rows.back().clean_tests = static_cast<int>(clean.size());
  rows.back().occluded_tests = static_cast<int>(occluded.size());
  const int sweep_tests = o.no_sweep ? 0 : std::min<int>(o.sweep_tests, clean.size());
  if (sweep_tests > 0) {
    const auto sweep_db = [&](int views, const proxseg::DescriptorParams& d) -> const auto& {
      sweep_dbs.push_back(
          std::make_unique<proxseg::Database>(proxseg::render_database(objects, views, d)));
      return *sweep_dbs.back();
    };
    for (int views : {4, 2})
      if (views < o.views)
        add_proxseg(std::to_string(views) + " views per object", "sweep", views == 4 ? 1 : 3,
                    sweep_db(views, descriptor), rp, views);
    const std::pair<std::vector<double>, int> radii[] = {{{0.015}, 4}, {{0.01, 0.02, 0.04}, 2}};
    for (const auto& [r, paper] : radii) {
      proxseg::DescriptorParams d = descriptor;
      d.fpfh_radii = r;
      add_proxseg("FPFH " + radii_mm(r) + " mm", "sweep", paper, sweep_db(o.views, d), rp, o.views);
    }
    proxseg::RecognitionParams fewer = rp;
    fewer.registration.ransac_iterations = 250;
    fewer.registration.icp_iterations = 10;
    add_proxseg("RANSAC 250, ICP 10", "sweep", 5, db, fewer, o.views);
    for (std::size_t i = 1; i < rows.size(); ++i) rows[i].clean_tests = sweep_tests;
  }
#ifdef PROXSEG_WITH_PEERS
  proxseg::peers::Open3dParams o3d;
  o3d.ransac_iterations = 100000;  // its 4M default: 2.5x the time, no gain (docs/method.md)
  std::unique_ptr<proxseg::peers::Open3dPeer> open3d;
  std::unique_ptr<proxseg::peers::PclPeer> pcl;
  const proxseg::peers::PclParams pcl_params;
  std::unique_ptr<proxseg::peers::FgrPeer> fgr;
  const proxseg::peers::FgrParams fgr_params;
#ifdef PROXSEG_WITH_PPF
  std::unique_ptr<proxseg::peers::PpfPeer> ppf;
  const proxseg::peers::PpfParams ppf_params;
#endif
  for (const std::string& peer : peers) {
    Row r;
    r.kind = "peer";
    r.views = o.views;
    r.radii = descriptor.fpfh_radii;
    if (peer == "open3d") {
      open3d = std::make_unique<proxseg::peers::Open3dPeer>(db, o3d, o.threads);
      r.label = "Open3D RANSAC 100k + ICP";
      r.ransac = o3d.ransac_iterations;
      r.icp = o3d.icp_iterations;
      r.run = peer_recogniser(*open3d, db, rp, team);
    } else if (peer == "pcl") {
      pcl = std::make_unique<proxseg::peers::PclPeer>(db, pcl_params, o.threads);
      r.label = "PCL SAC-prerejective 50k + ICP";
      r.radii.resize(1);  // its point type holds one histogram
      r.ransac = pcl_params.ransac_iterations;
      r.icp = pcl_params.icp_iterations;
      r.run = peer_recogniser(*pcl, db, rp, team);
    } else if (peer == "fgr") {
      fgr = std::make_unique<proxseg::peers::FgrPeer>(db, fgr_params, o.threads);
      r.label = "Open3D FGR + ICP";
      r.icp = fgr_params.icp_iterations;  // no RANSAC
      r.run = peer_recogniser(*fgr, db, rp, team);
    } else {
#ifdef PROXSEG_WITH_PPF
      ppf = std::make_unique<proxseg::peers::PpfPeer>(db, ppf_params, o.threads);
      r.label = "OpenCV PPF + ICP";
      r.radii.clear();  // point pair features, no FPFH
      r.icp = ppf_params.icp_iterations;
      r.train_ms = ppf->train_ms();
      std::cerr << "rec_bench: OpenCV PPF detectors of " << db.views.size() << " views trained in "
                << fmt(r.train_ms / 1000, 2) << " s\n";
      r.run = peer_recogniser(*ppf, db, rp, team);
#endif
    }
    r.clean_tests = std::min<int>(o.peer_tests, clean.size());
    r.occluded_tests = std::min<int>(o.peer_tests, occluded.size());
    rows.push_back(std::move(r));
  }
#endif

  // One untimed test through every row first: first-call costs are not the per-view cost.
  for (Row& r : rows) r.run(clean.front());
  std::size_t steps = 0;
  for (const Row& r : rows) steps += r.clean_tests + r.occluded_tests;
  cli::Progress progress(steps);
  for (Row& r : rows) {
    for (int i = 0; i < r.clean_tests; ++i) {
      r.clean.push_back(r.run(clean[i]));
      progress.step(r.label + ": " + objects[clean[i].object].name + " -> " +
                    (r.clean.back().best.empty() ? "-" : r.clean.back().best));
    }
    for (int i = 0; i < r.occluded_tests; ++i) {
      r.occluded.push_back(r.run(occluded[i]));
      progress.step(r.label + " (occluded " + fmt(100 * occluded[i].occlusion, 0) +
                    "%): " + objects[occluded[i].object].name + " -> " +
                    (r.occluded.back().best.empty() ? "-" : r.occluded.back().best));
    }
  }

  // The measures.
  const double m = rp.min_score;
  const auto subset = [](const std::vector<TestView>& v, std::size_t n) {
    return std::vector<TestView>(v.begin(), v.begin() + std::min(n, v.size()));
  };
  const auto in_bin = [](int b) { return [b](const TestView& t) { return t.bin == b; }; };
  nlohmann::json summary;
  summary["parameters"] = {
      {"models", o.models},
      {"objects",
       [&] {
         nlohmann::json j = nlohmann::json::array();
         for (const auto& ob : objects)
           j.push_back({{"name", ob.name},
                        {"file", ob.file},
                        {"symmetries", static_cast<int>(ob.symmetries.size()) - 1}});
         return j;
       }()},
      {"views", o.views},
      {"database_views", db.views.size()},
      {"descriptor",
       {{"voxel_size", descriptor.voxel_size},
        {"normal_radius", descriptor.normal_radius},
        {"fpfh_radii", descriptor.fpfh_radii}}},
      {"test_set",
       {{"tests", clean.size()},
        {"occluded_tests", occluded.size()},
        {"seed", o.seed},
        {"min_distance", tp.min_distance},
        {"max_distance", tp.max_distance},
        {"depth_noise", tp.depth_noise},
        {"disparity_step", tp.disparity_step},
        {"min_angle_to_view_deg", tp.min_angle_to_view_deg}}},
      {"recognition", proxseg::to_json(rp)},
      {"sweep_tests", sweep_tests},
      {"peer_tests", o.peer_tests},
      {"threads", team}};
  summary["bins"] = nlohmann::json::array();
  for (const auto& b : bins) summary["bins"].push_back(bin_name(b));
  summary["methods"] = nlohmann::json::array();
  std::ostringstream tests_csv, curves_csv;
  tests_csv << "method,set,test,object,distance_m,nearest_db_view_deg,points,occlusion,answer,"
               "score,right,rot_err_deg,trans_err_m,ms\n";
  curves_csv << "method,set,tests,min_score,tp_rate,fp_rate,precision\n";
  std::vector<Curve> roc_curves, pr_curves;
  for (const Row& r : rows) {
    const std::vector<TestView> c = subset(clean, r.clean.size()),
                                oc = subset(occluded, r.occluded.size());
    nlohmann::json j = {{"label", r.label},
                        {"kind", r.kind},
                        {"views", r.views},
                        {"fpfh_radii", r.radii},
                        {"ransac_iterations", r.ransac},
                        {"icp_iterations", r.icp},
                        {"train_ms", r.train_ms},
                        {"paper_analogue", r.paper < 0 ? "" : kPaperTable2[r.paper].name}};
    j["sets"]["clean"] = rates_json(proxseg::rates(c, r.clean, objects, m));
    double stage[4] = {0, 0, 0, 0};
    for (const Answer& a : r.clean) {
      stage[0] += a.describe_ms / r.clean.size(), stage[1] += a.ransac_ms / r.clean.size();
      stage[2] += a.icp_ms / r.clean.size(), stage[3] += a.score_ms / r.clean.size();
    }
    j["sets"]["clean"]["stage_ms"] = {
        {"describe", stage[0]}, {"ransac", stage[1]}, {"icp", stage[2]}, {"score", stage[3]}};
    if (!oc.empty()) {
      j["sets"]["occluded"] = rates_json(proxseg::rates(oc, r.occluded, objects, m));
      for (std::size_t b = 0; b < bins.size(); ++b)
        j["sets"][bin_name(bins[b])] =
            rates_json(proxseg::rates(oc, r.occluded, objects, m, in_bin(static_cast<int>(b))));
    }
    summary["methods"].push_back(j);
    const auto csv_rows = [&](const char* set, const std::vector<TestView>& tv,
                              const std::vector<Answer>& answers) {
      for (std::size_t i = 0; i < answers.size(); ++i) {
        const TestView& t = tv[i];
        const Answer& a = answers[i];
        const proxseg::PoseError e =
            proxseg::pose_error(a.pose, t.truth, objects[t.object].symmetries);
        tests_csv << '"' << r.label << "\"," << set << "," << t.index << ","
                  << objects[t.object].name << "," << fmt(t.distance, 3) << ","
                  << fmt(t.nearest_view_deg) << "," << t.points.size() << "," << fmt(t.occlusion, 3)
                  << "," << (a.best.empty() ? "-" : a.best) << "," << fmt(a.score, 4) << ","
                  << proxseg::named_right(a, t, objects, m) << "," << fmt(e.rotation_deg, 2) << ","
                  << fmt(e.translation, 4) << "," << fmt(a.ms, 1) << "\n";
      }
    };
    csv_rows("clean", c, r.clean);
    csv_rows("occluded", oc, r.occluded);
    const auto curve = [&](const std::string& set, const std::vector<TestView>& tv,
                           const std::vector<Answer>& answers,
                           const std::function<bool(const TestView&)>& which) {
      const auto points = proxseg::score_curve(tv, answers, objects, which);
      int n = 0;
      for (const auto& t : tv) n += !which || which(t);
      for (const auto& p : points)
        curves_csv << '"' << r.label << "\"," << set << "," << n << "," << fmt(p.min_score, 4)
                   << "," << fmt(p.tp_rate, 4) << "," << fmt(p.fp_rate, 4) << ","
                   << fmt(p.precision, 4) << "\n";
      return points;
    };
    const int colour = static_cast<int>(&r - rows.data());
    Curve roc{r.label + " (" + std::to_string(c.size()) + " tests)", {}, colour};
    const auto clean_points = curve("clean", c, r.clean, {});
    for (const auto& p : clean_points) roc.xy.emplace_back(p.fp_rate, p.tp_rate);
    roc_curves.push_back(roc);
    if (!oc.empty()) {  // Fig. 3b's occluded tests, all bins together
      Curve roc_occluded{
          r.label + ", occluded (" + std::to_string(oc.size()) + " tests)", {}, colour, true};
      for (const auto& p : curve("occluded", oc, r.occluded, {}))
        roc_occluded.xy.emplace_back(p.fp_rate, p.tp_rate);
      roc_curves.push_back(roc_occluded);
    }
    for (std::size_t b = 0; b < bins.size() && !oc.empty(); ++b) {
      const auto points = curve(bin_name(bins[b]), oc, r.occluded, in_bin(static_cast<int>(b)));
      if (r.kind != "proxseg") continue;
      Curve pr{"occlusion " + bin_name(bins[b]) + " %", {}, static_cast<int>(b) + 1};
      for (const auto& p : points) pr.xy.emplace_back(p.tp_rate, p.precision);
      pr_curves.push_back(pr);
    }
    if (r.kind == "proxseg") {
      Curve pr{"no occlusion", {}};
      for (const auto& p : clean_points) pr.xy.emplace_back(p.tp_rate, p.precision);
      pr_curves.insert(pr_curves.begin(), pr);
    }
  }
  summary["paper"]["table2"] = nlohmann::json::array();
  for (const PaperTest& p : kPaperTable2)
    summary["paper"]["table2"].push_back({{"test", p.name},
                                          {"views", p.views},
                                          {"radii_mm", p.radii},
                                          {"ransac_iterations", p.ransac},
                                          {"icp_iterations", p.icp},
                                          {"tp_rate", p.tp / 100.0},
                                          {"fp_rate", p.fp / 100.0}});
  summary["paper"]["table3_tp_rate"] = nlohmann::json::array();
  for (int tp3 : kPaperTable3Tp) summary["paper"]["table3_tp_rate"].push_back(tp3 / 100.0);

  // The report.
  const Row& main_row = rows.front();
  std::ostringstream md;
  md << "## Recognition: the paper's Tables 2 and 3 (" << objects.size() << " objects)\n\n"
     << "Generated by `make bench-rec` (bench/rec_bench.cpp) on " << machine() << ", " << utc_now()
     << "; seed " << o.seed << ", " << team << " threads. Database: " << o.views
     << " noiseless render_views() per object (" << db.views.size()
     << " views). Test views: " << clean.size() << " renderings from random directions at least "
     << fmt(tp.min_angle_to_view_deg, 0) << " degrees from every database viewpoint, "
     << fmt(tp.min_distance, 1) << "-" << fmt(tp.max_distance, 1)
     << " m, random roll, Kinect-like depth noise (" << fmt(1000 * tp.depth_noise, 1)
     << " mm at 1 m, growing with z^2) and disparity steps (" << fmt(1000 * tp.disparity_step, 2)
     << " mm at 1 m); occluded views: the first " << occluded.size()
     << " through the paper's occlusion generator, evenly over the six bins. A test is a true "
        "positive when the answer names its object, a false positive when it names another; "
        "an answer under the minimum score ("
     << fmt(m, 2)
     << ") is \"unknown\" (neither). Pose ok: named right and within 2 cm and 10 degrees "
        "(symmetry-aware). Times: describe + recognition, wall, per test view.\n\n";
  md << "### Table 2 analogue (no occlusion)\n\n"
     << "| run | views / object | FPFH radii (mm) | RANSAC | ICP | tests | TP (%) | FP (%) | "
        "unknown (%) | pose ok (%) | ms / view | paper (TP / FP %) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  // The first n tests of row r (rates() stops at the shorter of tests and answers).
  const auto table2_row = [&](const Row& r, std::size_t n, const std::string& label, int paper) {
    const proxseg::Rates x = proxseg::rates(subset(clean, n), r.clean, objects, m);
    md << "| " << label << " | " << r.views << " | " << radii_mm(r.radii) << " | " << r.ransac
       << " | " << r.icp << " | " << x.tests << " | " << pct(x.tp_rate()) << " | "
       << pct(x.fp_rate()) << " | " << pct(double(x.unknown) / std::max(x.tests, 1)) << " | "
       << pct(x.pose_rate()) << " | " << fmt(x.mean_ms, 0) << " | " << paper_row(paper) << " |\n";
  };
  table2_row(main_row, main_row.clean.size(), "proxseg (defaults)", main_row.paper);
  if (sweep_tests > 0) {
    table2_row(main_row, sweep_tests, "proxseg (defaults), first " + std::to_string(sweep_tests),
               -1);
    for (const Row& r : rows)
      if (r.kind == "sweep") table2_row(r, r.clean.size(), r.label, r.paper);
  }
  md << "\nThe paper's Table 2 (its database: 8 objects, 61 views in all; ours renders " << o.views
     << " per object): ";
  for (int i = 0; i < static_cast<int>(std::size(kPaperTable2)); ++i)
    md << (i ? "; " : "") << paper_row(i);
  md << ".\n\n";

  md << "### Table 3 analogue (occlusion, proxseg defaults)\n\n| occlusion (%) |";
  for (const auto& b : bins) md << " " << bin_name(b) << " |";
  md << "\n|---|";
  for (std::size_t b = 0; b < bins.size(); ++b) md << "---|";
  const std::vector<TestView> main_occluded = subset(occluded, main_row.occluded.size());
  std::vector<proxseg::Rates> per_bin;
  for (std::size_t b = 0; b < bins.size(); ++b)
    per_bin.push_back(
        proxseg::rates(main_occluded, main_row.occluded, objects, m, in_bin(static_cast<int>(b))));
  const auto bin_line = [&](const std::string& name, auto value) {
    md << "\n| " << name << " |";
    for (std::size_t b = 0; b < bins.size(); ++b) md << " " << value(b) << " |";
  };
  bin_line("tests", [&](std::size_t b) { return std::to_string(per_bin[b].tests); });
  bin_line("TP (%)", [&](std::size_t b) { return pct(per_bin[b].tp_rate()); });
  bin_line("FP (%)", [&](std::size_t b) { return pct(per_bin[b].fp_rate()); });
  bin_line("pose ok (%)", [&](std::size_t b) { return pct(per_bin[b].pose_rate()); });
  bin_line("ms / view", [&](std::size_t b) { return fmt(per_bin[b].mean_ms, 0); });
  bin_line("paper TP (%)", [&](std::size_t b) { return std::to_string(kPaperTable3Tp[b]); });
  bin_line("paper FP (%)", [&](std::size_t b) { return std::to_string(100 - kPaperTable3Tp[b]); });
  md << "\n\n";

  const auto peer =
      std::find_if(rows.begin(), rows.end(), [](const Row& r) { return r.kind == "peer"; });
  if (peer != rows.end()) {  // every peer runs the same tests
    const int pc = peer->clean_tests, po = peer->occluded_tests;
    md << "### Against the peers (the same " << pc << " test views and " << po
       << " occluded ones)\n\n"
       << "Each peer aligns every database view with its own registration; its poses are scored "
          "and the test named exactly as proxseg does (same score, minimum and database), so "
          "the rows differ only in registration.";
    for (const Row& r : rows)
      if (r.train_ms > 0)
        md << " " << r.label << " trains one detector per database view, once before the first "
           << "test (not in ms / view): " << fmt(r.train_ms / 1000, 1) << " s for the "
           << db.views.size() << " views.";
    md << "\n\n"
       << "| method | TP (%) | FP (%) | pose ok (%) | ms / view | occluded: TP (%) | FP (%) | "
          "pose ok (%) | ms / view |\n|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
      if (r.kind == "sweep") continue;
      const proxseg::Rates a = proxseg::rates(subset(clean, pc), r.clean, objects, m);
      const proxseg::Rates b = proxseg::rates(subset(occluded, po), r.occluded, objects, m);
      md << "| " << r.label << " | " << pct(a.tp_rate()) << " | " << pct(a.fp_rate()) << " | "
         << pct(a.pose_rate()) << " | " << fmt(a.mean_ms, 0) << " | " << pct(b.tp_rate()) << " | "
         << pct(b.fp_rate()) << " | " << pct(b.pose_rate()) << " | " << fmt(b.mean_ms, 0) << " |\n";
    }
    md << "\n";
  }

  // Per-stage times on the views every non-sweep row ran (the first of the clean set).
  {
    std::size_t n = main_row.clean.size();
    for (const Row& r : rows)
      if (r.kind != "sweep") n = std::min(n, r.clean.size());
    md << "### Stage times (ms per test view, mean over the first " << n << " clean test views)\n\n"
       << "Describe: voxel filter, normals and FPFH of the test view (wall). RANSAC (with the "
          "feature correspondences; for FGR its matching and optimisation, for PPF the voting and "
          "pose clustering), ICP and scoring: summed over the "
       << db.views.size() << " database views, which run on " << team
       << " threads, so the sums exceed the wall time.\n\n"
       << "| method | describe | RANSAC | ICP | scoring | wall |\n|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
      if (r.kind == "sweep" || n == 0) continue;
      double d = 0, ra = 0, ic = 0, sc = 0, wall = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const Answer& a = r.clean[i];
        d += a.describe_ms, ra += a.ransac_ms, ic += a.icp_ms, sc += a.score_ms, wall += a.ms;
      }
      md << "| " << r.label << " | " << fmt(d / n) << " | " << fmt(ra / n, 0) << " | "
         << fmt(ic / n, 0) << " | " << fmt(sc / n, 0) << " | " << fmt(wall / n, 0) << " |\n";
    }
    md << "\n";
  }

  // False positives are rare: the ROC's x axis ends a little past the largest rate.
  double fp_max = 0;
  for (const Curve& c : roc_curves)
    for (const auto& xy : c.xy) fp_max = std::max(fp_max, xy.first);
  const bool roc_png =
      plot(out, "roc",
           gnuplot_script("roc.png", "ROC (minimum score varied; unknown = rejected)",
                          "false-positive rate", "true-positive rate", roc_curves, "bottom right",
                          std::min(1.0, std::max(0.05, 1.15 * fp_max))));
  const bool pr_png =
      plot(out, "pr",
           gnuplot_script("pr.png", "Precision-recall per occlusion (proxseg)",
                          "recall (true-positive rate)", "precision", pr_curves, "bottom left"));
  md << "### Curves\n\nROC (true- against false-positive rate as the minimum score goes from 1 "
        "to 0, \"unknown\" as the rejection; Fig. 3a) and precision-recall per occlusion bin "
        "(Fig. 3b): `curves.csv`"
     << (roc_png && pr_png ? ", `roc.png` and `pr.png`"
                           : " (no PNG: gnuplot is not installed; scripts/install-deps.sh --bench)")
     << "; per test: `tests.csv`.\n";
  if (!roc_png || !pr_png)
    std::cerr << "rec_bench: gnuplot not found or failed: no PNG plots (the .gp scripts and "
                 "curves.csv are written; scripts/install-deps.sh --bench installs gnuplot)\n";

  return proxseg::bench::finish(out,
                                {{"summary.md", md.str()},
                                 {"summary.json", summary.dump(2) + "\n"},
                                 {"tests.csv", tests_csv.str()},
                                 {"curves.csv", curves_csv.str()}},
                                summary, md.str(), o.json);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rec_bench: the paper's recognition experiments (Tables 2-3, ROC): rendered database, "
      "random test views, occlusions, sweeps and peers"};
  Options o;
  add_options(&app, o);
  // --peers is checked by run(), as a usage error.
  return proxseg::bench::main_of("rec_bench", app, argc, argv, [&] { return run(o); });
}
