// The plain data of db_scale_bench (bench/db_scale_bench.cpp): its options, the distractors, what
// each recognition and each database size measured, and the functions of its other files
// (db_scale_distractors.cpp, db_scale_processes.cpp, db_scale_report.cpp).
#pragma once
#include <proxseg/eval/rec_eval.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace proxseg::bench::dbscale {

struct Options {
  std::string models, output, units = "mm", tools, open, object;
  int views = 8, tests = 200, all_tests = 40, lookalikes = 8, threads = 0;
  int all_max_views = 512, process_tests = 8;
  std::vector<int> sizes = {64, 128, 256, 512};
  std::uint64_t seed = 1;
  bool json = false;
};

void add_options(CLI::App* cmd, Options& o);

// ---- The distractors (db_scale_distractors.cpp) ----

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

// A nearly grey mesh (mean saturation x value under this) is tinted as well as hue-turned: a
// hue turn leaves grey as it is, and a copy that looks the same under another name is not a
// look-alike but the same object, which no recogniser could tell apart (the LINEMOD can,
// driller, eggbox and glue are about 0.03-0.05; ape 0.38, duck 0.77).
constexpr double kGreyChroma = 0.1;
constexpr double kTintSaturation = 0.4;

// The distractors, in database order: a look-alike every 7th place (the 1st, 8th, 15th, ...,
// until `lookalikes` of them), so that every database size holds hard negatives in about the
// same share; the others seeded boxes and cylinders.
std::vector<Distractor> distractors(const std::vector<TestObject>& tested, int count,
                                    int lookalikes, std::uint64_t seed);

// ---- The in-process rows (db_scale_bench.cpp) ----

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

// ---- One process per question (db_scale_processes.cpp) ----

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

// `db_scale_bench --open DB [--object PCD]`: what opening costs a fresh process, and with
// --object, the peak RSS of `proxseg recognize --object` (the same calls, apps/recognize.cpp).
int open_only(const std::string& dir, const std::string& object);

// The process row of the database in `dir`. first_dir: the smallest database, whose runs pair
// with this one's (empty for it).
ProcessRow measure_processes(const std::string& self, const std::string& tools,
                             const std::string& dir, const std::string& first_dir,
                             const std::vector<std::string>& test_files,
                             const std::vector<std::string>& truths, double min_score,
                             const std::filesystem::path& scratch);

// ---- The report (db_scale_report.cpp) ----

// Everything a run measured, as the report reads it.
struct Measured {
  std::vector<int> sizes;  // sorted, unique
  RecognitionParams rp;    // the default rows'
  TestSetParams tp;
  int team = 0;       // threads
  int all_tests = 0;  // tests of the every-view rows
  bool coloured = true;
  std::vector<TestObject> tested;
  std::vector<Distractor> extra_objects;
  std::vector<TestObject> objects;  // every object of the largest database: the tested first
  std::map<std::string, std::string> kinds;  // object name -> tested, box, cylinder, look-alike
  std::vector<TestView> tests;
  std::vector<Row> rows;
  std::vector<ProcessRow> process_rows;
  std::string load_start, load_end;
};

// dbscale.json and dbscale.md.
nlohmann::json report_json(const Options& o, const Measured& m);
std::string report_markdown(const Options& o, const Measured& m);

}  // namespace proxseg::bench::dbscale
