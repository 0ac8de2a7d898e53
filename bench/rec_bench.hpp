// The plain data of rec_bench (bench/rec_bench.cpp): its options, the paper's figures, the rows
// (a recogniser and its answers), the run's database and test sets, and the functions of its
// other files (rec_bench_rows.cpp, rec_bench_plot.cpp, rec_bench_report.cpp,
// rec_bench_markdown.cpp).
#pragma once
#include <proxseg/eval/rec_eval.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace proxseg::bench::recbench {

struct Options {
  std::string models, output, config, units = "mm", peers = "all";
  int views = 8, tests = 2241, occluded_tests = 600, sweep_tests = 200, peer_tests = 60;
  int threads = 0;
  std::uint64_t seed = 1;
  bool no_sweep = false, json = false;
};

void add_options(CLI::App* cmd, Options& o);

// ---- The paper's figures [4, Tables 2 and 3], printed beside ours (rec_bench_markdown.cpp) ----

struct PaperTest {
  const char* name;
  int views;
  const char* radii;
  int ransac, icp, tp, fp;
};
inline constexpr PaperTest kPaperTable2[] = {
    {"test01", 61, "3, 5, 10, 20, 30, 50", 200, 200, 80, 20},
    {"test02", 32, "3, 5, 10, 20, 30, 50", 200, 200, 70, 30},
    {"test03", 61, "3, 10, 30", 200, 200, 83, 17},
    {"test04", 24, "3, 5, 10, 20, 30, 50", 200, 200, 60, 40},
    {"test05", 61, "5, 15", 200, 200, 81, 19},
    {"test06", 61, "3, 10, 30", 100, 150, 81, 19},
    {"test07", 32, "5, 15", 200, 200, 73, 27},
    {"test08", 32, "3, 10, 30", 100, 150, 70, 30},
    {"test09", 32, "5, 15", 100, 150, 69, 31}};
inline constexpr int kPaperTable3Tp[] = {76, 70, 60, 47, 37, 23};
// "test02 (32 views, 3, 5, 10, 20, 30, 50 mm, 200 / 200 it.): 70 / 30"; "" for i < 0.
std::string paper_row(int i);
// "10, 20, 40" (mm).
std::string radii_mm(const std::vector<double>& radii);
// "0-15" (%).
std::string bin_name(const OcclusionBin& b);

// ---- The rows (rec_bench_rows.cpp) ----

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
  std::shared_ptr<const void> owned;  // what `run` refers to besides the run's database
};

// The database and test sets of a run, and its rows.
struct Bench {
  RecognitionParams rp;
  int team = 0;  // threads
  std::vector<TestObject> objects;
  DescriptorParams descriptor;
  Database db;
  TestSetParams tp;
  std::vector<TestView> clean, occluded;
  std::vector<OcclusionBin> bins;
  int sweep_tests = 0;  // tests of each sweep row
  std::vector<Row> rows;
};

// The peers of --peers (all: those this build has), as a usage error when unknown or not built.
std::vector<std::string> peer_list(const std::string& spec);
// The rows of proxseg: its defaults, then the sweeps (one change each, like Table 2).
void add_proxseg_rows(const Options& o, Bench& b);
// The peers' rows (none in a build without them).
void add_peer_rows(const Options& o, const std::vector<std::string>& peers, Bench& b);

// ---- The curves (rec_bench_plot.cpp) ----

// A gnuplot script that draws curves (inline data blocks) into a PNG.
// Each curve has its own colour (the method's or the bin's, from a palette of 12); the occluded
// curves of the ROC are dashed in their method's colour.
struct Curve {
  std::string title;
  std::vector<std::pair<double, double>> xy;
  int colour = 0;
  bool dashed = false;
};
// A gnuplot script that draws curves (inline data blocks) into a PNG.
std::string gnuplot_script(const std::string& png, const std::string& title,
                           const std::string& xlabel, const std::string& ylabel,
                           const std::vector<Curve>& curves, const std::string& key,
                           double xmax = 1);
// Runs gnuplot on OUT/name.gp and moves the PNG into place; false when gnuplot is missing or
// fails (the CSV holds the same curves).
bool plot(const std::filesystem::path& dir, const std::string& name, const std::string& script);

// ---- The report (rec_bench_report.cpp, rec_bench_markdown.cpp) ----

// What the report writes besides summary.md: summary.json, the two CSV files and the curves.
struct Tables {
  nlohmann::json summary;
  std::string tests_csv, curves_csv;
  std::vector<Curve> roc, pr;
};

// The first n of a test set.
std::vector<TestView> subset(const std::vector<TestView>& v, std::size_t n);
Tables report_tables(const Options& o, const Bench& b);
// summary.md; draws roc.png and pr.png into `out`.
std::string report_markdown(const Options& o, const Bench& b, const Tables& t,
                            const std::filesystem::path& out);

}  // namespace proxseg::bench::recbench
