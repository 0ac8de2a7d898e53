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
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/eval/rec_eval.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <omp.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "bench_main.hpp"
#include "bench_util.hpp"
#include "progress.hpp"  // apps/progress.hpp: the CLI's progress bar
#include "rec_bench.hpp"

namespace proxseg::bench::recbench {

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

namespace {

// Removes the previous run's database, but never a directory that is not one.
void reset_db_dir(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  if (!fs::exists(dir)) return;
  if (!fs::is_directory(dir) || (!fs::is_empty(dir) && !fs::exists(dir / "index.json")))
    throw InputError(dir.string() + ": exists and is not a proxseg database");
  fs::remove_all(dir);
}

// The recognition parameters (--config over the defaults) and the threads.
void setup(const Options& o, Bench& b) {
  if (!o.config.empty()) b.rp = read_recognize_params(o.config, {}, b.rp).second;
  b.rp.threads = o.threads;
  b.rp.seed = o.seed;
  validate(b.rp);
  if (o.threads > 0) omp_set_num_threads(o.threads);
  b.team = o.threads > 0 ? o.threads : omp_get_max_threads();
}

// The database, built and read back as a user would (OUT/db); then the test sets.
void make_sets(const Options& o, const std::filesystem::path& db_dir, Bench& b) {
  auto t0 = Clock::now();
  b.db = render_database(b.objects, o.views, b.descriptor, db_dir.string());
  std::cerr << "rec_bench: database of " << b.db.views.size() << " views (" << b.objects.size()
            << " objects x " << o.views << ") in " << fixed(ms_since(t0) / 1000) << " s\n";
  // Tests avoid the viewpoints of every database of the run (and of the sweeps' 4 and 2 views
  // even without sweeps, so that the test set depends only on --views, --tests and --seed).
  std::vector<Eigen::Vector3d> directions;
  for (int n : {o.views, 4, 2})
    for (const auto& d : view_sphere(n)) directions.push_back(d);
  b.tp.tests = o.tests;
  b.tp.seed = o.seed;
  t0 = Clock::now();
  b.clean = make_test_views(b.objects, b.tp, directions);
  b.bins = paper_occlusion_bins();
  b.occluded = occluded_test_views(b.clean, o.occluded_tests, b.bins, o.seed);
  std::cerr << "rec_bench: " << b.clean.size() << " test views and " << b.occluded.size()
            << " occluded ones in " << fixed(ms_since(t0) / 1000) << " s\n";
}

// The first n tests of `set` through row r, each a step of the progress bar ("what: object ->
// answer").
void run_tests(Row& r, const std::vector<TestView>& set, int n, const char* set_name,
               const std::vector<TestObject>& objects, cli::Progress& progress,
               std::vector<Answer>& answers) {
  for (int i = 0; i < n; ++i) {
    answers.push_back(r.run(set[i]));
    const std::string what =
        set_name[0] ? r.label + " (" + set_name + " " + fixed(100 * set[i].occlusion, 0) + "%)"
                    : r.label;
    progress.step(what + ": " + objects[set[i].object].name + " -> " +
                  (answers.back().best.empty() ? "-" : answers.back().best));
  }
}

// Every row on its tests, after one untimed test through each (first-call costs are not the
// per-view cost).
void run_rows(Bench& b) {
  for (Row& r : b.rows) r.run(b.clean.front());
  std::size_t steps = 0;
  for (const Row& r : b.rows) steps += r.clean_tests + r.occluded_tests;
  cli::Progress progress(steps);
  for (Row& r : b.rows) {
    run_tests(r, b.clean, r.clean_tests, "", b.objects, progress, r.clean);
    run_tests(r, b.occluded, r.occluded_tests, "occluded", b.objects, progress, r.occluded);
  }
}

}  // namespace

int run(const Options& o) {
  const std::vector<std::string> peers = peer_list(o.peers);
  Bench b;
  setup(o, b);
  b.objects = read_test_objects(o.models, o.units == "mm" ? 0.001 : 1.0);
  const std::filesystem::path out = output_folder(o.output);
  const std::filesystem::path db_dir = out / "db";
  reset_db_dir(db_dir);
  make_sets(o, db_dir, b);
  add_proxseg_rows(o, b);
  add_peer_rows(o, peers, b);
  run_rows(b);
  const Tables t = report_tables(o, b);
  const std::string md = report_markdown(o, b, t, out);
  return finish(out,
                {{"summary.md", md},
                 {"summary.json", t.summary.dump(2) + "\n"},
                 {"tests.csv", t.tests_csv},
                 {"curves.csv", t.curves_csv}},
                t.summary, md, o.json);
}

}  // namespace proxseg::bench::recbench

int main(int argc, char** argv) {
  CLI::App app{
      "rec_bench: the paper's recognition experiments (Tables 2-3, ROC): rendered database, "
      "random test views, occlusions, sweeps and peers"};
  proxseg::bench::recbench::Options o;
  proxseg::bench::recbench::add_options(&app, o);
  // --peers is checked by run(), as a usage error.
  return proxseg::bench::main_of("rec_bench", app, argc, argv,
                                 [&] { return proxseg::bench::recbench::run(o); });
}
