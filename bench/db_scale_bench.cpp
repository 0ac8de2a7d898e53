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
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/eval/rec_eval.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "bench_main.hpp"
#include "bench_util.hpp"
#include "db_scale_bench.hpp"
#include "progress.hpp"  // apps/progress.hpp: the CLI's progress bar

namespace proxseg::bench::dbscale {

namespace fs = std::filesystem;

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

namespace {

// describe_candidate() + recognize(), timed (wall); the answer is recognize()'s name: an
// "unknown" (under min_score or min_margin) answers nothing.
std::pair<Answer, Extra> recognize_one(const TestView& t, const std::string& truth,
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

// The sizes sorted, the default rows' recognition parameters, the threads and the tested objects;
// a size that is not a multiple of --views of at least the tested objects' views is a usage error.
Measured setup(const Options& o) {
  if (o.models.empty()) throw CLI::ValidationError("--models", "required");
  if (o.output.empty()) throw CLI::ValidationError("-o,--output", "required");
  Measured m;
  m.sizes = o.sizes;
  std::sort(m.sizes.begin(), m.sizes.end());
  m.sizes.erase(std::unique(m.sizes.begin(), m.sizes.end()), m.sizes.end());
  m.rp.threads = o.threads;
  m.rp.seed = o.seed;
  validate(m.rp);
  if (o.threads > 0) omp_set_num_threads(o.threads);
  m.team = o.threads > 0 ? o.threads : omp_get_max_threads();
  m.tested = read_test_objects(o.models, o.units == "mm" ? 0.001 : 1.0);
  const int n_tested = static_cast<int>(m.tested.size());
  for (int s : m.sizes)
    if (s % o.views != 0 || s < n_tested * o.views)
      throw CLI::ValidationError("--sizes", std::to_string(s) + ": not a multiple of --views (" +
                                                std::to_string(o.views) + ") of at least the " +
                                                std::to_string(n_tested * o.views) +
                                                " views of the tested objects");
  return m;
}

// The programs run per question: this one (--open) and proxseg-tools.
struct Programs {
  std::string self, tools;
};

Programs programs(const Options& o) {
  Programs p;
  p.self = fs::read_symlink("/proc/self/exe").string();
  p.tools = o.tools.empty()
                ? (fs::path(p.self).parent_path().parent_path() / "proxseg-tools").string()
                : o.tools;
  if (o.process_tests > 0 && !fs::exists(p.tools))
    throw InputError(p.tools + ": no proxseg-tools there (give --tools)");
  return p;
}

// Every object of the largest database, in database order: the tested ones first.
void make_objects(const Options& o, Measured& m) {
  const auto t0 = Clock::now();
  const int n_tested = static_cast<int>(m.tested.size());
  m.extra_objects =
      distractors(m.tested, m.sizes.back() / o.views - n_tested, o.lookalikes, o.seed);
  m.objects = m.tested;
  for (const TestObject& t : m.tested) m.kinds[t.name] = "tested";
  for (const Distractor& d : m.extra_objects) {
    m.objects.push_back(d.object);
    m.kinds[d.object.name] = d.kind;
  }
  std::cerr << "db_scale_bench: " << m.objects.size() << " objects (" << n_tested << " tested, "
            << m.extra_objects.size() << " distractors) in " << fixed(ms_since(t0) / 1000, 1)
            << " s\n";
}

// The first --process-tests test views as the PCD files a user would give (OUT/tests/).
struct TestFiles {
  std::vector<std::string> files, truths;
};

TestFiles write_test_files(const Options& o, const fs::path& out, const Measured& m) {
  TestFiles t;
  std::error_code ec;
  fs::create_directories(out / "tests", ec);
  for (int i = 0; i < std::min<int>(o.process_tests, static_cast<int>(m.tests.size())); ++i) {
    Frame f;
    for (const auto& p : m.tests[i].points) f.xyz.push_back(p.cast<float>());
    if (m.tests[i].colours.size() == m.tests[i].points.size()) f.rgb = m.tests[i].colours;
    f.width = static_cast<int>(f.xyz.size());
    f.height = 1;
    char name[32];
    std::snprintf(name, sizeof name, "test-%03d.pcd", i);
    t.files.push_back((out / "tests" / name).string());
    write_pcd(t.files.back(), f, {});
    t.truths.push_back(m.tested[m.tests[i].object].name);
  }
  return t;
}

// The test views: they avoid the viewpoints of the database (and those of 4 and 2 views per
// object, as rec_bench's do, so that with 8 views the first tests are rec_bench's).
TestFiles make_tests(const Options& o, const fs::path& out, Measured& m) {
  std::vector<Eigen::Vector3d> directions;
  for (int n : {o.views, 4, 2})
    for (const auto& d : view_sphere(n)) directions.push_back(d);
  m.tp.tests = o.tests;
  m.tp.seed = o.seed;
  const auto t0 = Clock::now();
  m.tests = make_test_views(m.tested, m.tp, directions);
  m.all_tests = std::min<int>(o.all_tests, static_cast<int>(m.tests.size()));
  TestFiles files = write_test_files(o, out, m);
  for (const TestView& t : m.tests) m.coloured &= t.colours.size() == t.points.size();
  std::cerr << "db_scale_bench: " << m.tests.size() << " test views"
            << (m.coloured ? " with colours" : " (some without colour)") << " in "
            << fixed(ms_since(t0) / 1000, 1) << " s\n";
  return files;
}

// The database file grown to `n_objects` objects (it holds `built`): the previous one plus the
// next objects' views, so the smaller databases are prefixes of the larger ones. Read back as a
// program does (opened, each view read when first shortlisted).
Database grow_database(const Options& o, const Measured& m, const fs::path& db_dir, Database db,
                       int built, int n_objects) {
  const auto t0 = Clock::now();
  {
    const Database part = render_database(
        std::vector<TestObject>(m.objects.begin() + built, m.objects.begin() + n_objects), o.views,
        DescriptorParams{});
    // Closed first: the write's connection is then the last one, and folds its write-ahead
    // log into the file when it closes (the file's size is the database's).
    db = Database{};
    write_database(part, db_dir.string());
  }
  db = load_database(db_dir.string());
  std::cerr << "db_scale_bench: database of " << db.views.size() << " views (" << n_objects
            << " objects): " << fixed(ms_since(t0) / 1000, 1)
            << " s to render, describe and store the views added\n";
  return db;
}

// The process row of the database in OUT/db; the smallest database stays beside it (OUT/
// db-smallest): the larger sizes' runs pair with it.
void add_process_row(const fs::path& out, const Programs& p, const TestFiles& files, Measured& m) {
  const fs::path db_dir = out / "db", first_dir = out / "db-smallest";
  if (m.process_rows.empty()) {
    std::error_code ec;
    fs::remove_all(first_dir, ec);
    fs::create_directories(first_dir);
    fs::copy_file(db_dir / kDatabaseFile, first_dir / kDatabaseFile);
  }
  m.process_rows.push_back(measure_processes(p.self, p.tools, db_dir.string(),
                                             m.process_rows.empty() ? "" : first_dir.string(),
                                             files.files, files.truths, m.rp.min_score, out));
  const ProcessRow& r = m.process_rows.back();
  std::cerr << "db_scale_bench: " << r.views << " views, " << fixed(r.file_mb, 0) << " MB: open "
            << fixed(r.open_ms, 1) << " ms, " << fixed(r.open_rss_mb, 0)
            << " MB; recognize --object " << fixed(r.wall_s, 2) << " s wall, " << fixed(r.cpu_s, 2)
            << " s CPU, " << fixed(r.rss_mb, 0) << " MB, TP " << r.tp << "/" << r.tests << "\n";
}

// One row: the first n tests through `db` with `p`, after one untimed test (first-call costs are
// not the per-candidate cost).
Row measure_row(const Measured& m, const Database& db, const RecognitionParams& p, int n, int size,
                int n_objects, cli::Progress& progress) {
  Row r;
  r.views = static_cast<int>(db.views.size());
  r.objects = n_objects;
  for (int j = 0; j < n_objects - static_cast<int>(m.tested.size()); ++j)
    r.lookalikes += m.extra_objects[j].kind == "look-alike";
  r.shortlist = p.shortlist;
  recognize_one(m.tests.front(), m.tested[m.tests.front().object].name, db, p);
  r.load_before = load_averages();
  for (int i = 0; i < n; ++i) {
    const TestView& t = m.tests[i];
    auto [a, e] = recognize_one(t, m.tested[t.object].name, db, p);
    progress.step(std::to_string(size) + " views, shortlist " + std::to_string(p.shortlist) + ": " +
                  m.tested[t.object].name + " -> " + (a.best.empty() ? "unknown" : a.best));
    r.answers.push_back(std::move(a));
    r.extra.push_back(std::move(e));
  }
  r.load_after = load_averages();
  return r;
}

// Every size in turn: the database grown to it, its process row, and its rows with the default
// shortlist (every test) and with every view (the first --all-tests, up to --all-max-views).
void measure_sizes(const Options& o, const fs::path& out, const Programs& p, const TestFiles& files,
                   Measured& m) {
  RecognitionParams every = m.rp;
  every.shortlist = 0;   // every view, as the paper aligns them:
  every.early_exit = 0;  // none skipped either
  every.early_reject = 0;
  const auto every_sizes =
      std::count_if(m.sizes.begin(), m.sizes.end(), [&](int n) { return n <= o.all_max_views; });
  cli::Progress progress(m.sizes.size() * m.tests.size() + every_sizes * m.all_tests);
  Database db;
  int built = 0;  // objects in db
  for (int size : m.sizes) {
    const int n_objects = size / o.views;
    db = grow_database(o, m, out / "db", std::move(db), built, n_objects);
    built = n_objects;
    if (!files.files.empty()) add_process_row(out, p, files, m);
    m.rows.push_back(
        measure_row(m, db, m.rp, static_cast<int>(m.tests.size()), size, n_objects, progress));
    if (m.all_tests > 0 && size <= o.all_max_views)
      m.rows.push_back(measure_row(m, db, every, m.all_tests, size, n_objects, progress));
  }
}

}  // namespace

int run(const Options& o) {
  if (!o.open.empty()) return open_only(o.open, o.object);
  Measured m = setup(o);
  const fs::path out = output_folder(o.output);
  m.load_start = load_averages();
  std::error_code ec;
  fs::remove_all(out / "db", ec);  // the database file, grown size by size
  const Programs p = programs(o);
  make_objects(o, m);
  const TestFiles files = make_tests(o, out, m);
  measure_sizes(o, out, p, files, m);
  m.load_end = load_averages();
  const nlohmann::json summary = report_json(o, m);
  const std::string md = report_markdown(o, m);
  return finish(out, {{"dbscale.md", md}, {"dbscale.json", summary.dump(2) + "\n"}}, summary, md,
                o.json);
}

}  // namespace proxseg::bench::dbscale

int main(int argc, char** argv) {
  CLI::App app{
      "db_scale_bench: recognition cost and accuracy against the database size (tested "
      "LINEMOD meshes + seeded distractors), shortlist against every view"};
  proxseg::bench::dbscale::Options o;
  proxseg::bench::dbscale::add_options(&app, o);
  // --sizes is checked by run(), as a usage error.
  return proxseg::bench::main_of("db_scale_bench", app, argc, argv,
                                 [&] { return proxseg::bench::dbscale::run(o); });
}
