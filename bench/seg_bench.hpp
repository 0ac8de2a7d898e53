// The plain data of seg_bench (bench/seg_bench.cpp): its options, the scene sets, what the
// methods measured, the whole-process times (seg_bench_process.cpp) and the report
// (seg_bench_report.cpp).
#pragma once
#include <proxseg/core/pipeline.hpp>
#include <proxseg/eval/seg_summary.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace proxseg::bench::segbench {

struct Options {
  std::string data, clutter, out, csv, methods;
  std::vector<std::string> configs;
  int limit = 0, threads = 0, process_scenes = 10;
  std::string proxseg_cli, lccp_process;  // default: beside this program
};

struct SceneSet {
  std::string name;  // "mOSD learn", "generated"
  std::vector<std::filesystem::path> files;
  int done = 0;     // labelled scenes evaluated
  std::string dir;  // the folder
};

// ---- Whole-process times (seg_bench_process.cpp) ----

// Seconds a process took: wall from spawn to exit, CPU = user + sys (its own and its threads').
struct ProcessCost {
  double wall = 0, cpu = 0;
  ProcessCost& operator+=(const ProcessCost& o) {
    wall += o.wall, cpu += o.cpu;
    return *this;
  }
};

// Whole-process seconds per frame of one set and mode, for proxseg and lccp_process.
struct ProcessTimes {
  std::string set, mode;
  int frames = 0;
  ProcessCost proxseg, lccp;  // sums over the frames
};

struct Processes {
  std::vector<ProcessTimes> times;
  ProcessCost startup_proxseg, startup_lccp;  // sums over 5 runs
};

// Each tool as its own process (read the PCD, segment, write the outputs) on the first
// --process-scenes scenes of each set, timed from spawn to exit; outputs go to a temporary
// directory removed at the end. An InputError when a tool fails.
Processes measure_processes(const Options& o, const std::vector<SceneSet>& sets);

// ---- The report (seg_bench_report.cpp) ----

// Table 1 of the paper: the paper's precision / recall and V-measure of the raw labels, before and
// after the MRF, per preset (sums over scenes).
struct Table1 {
  double precision = 0, recall = 0, v = 0;
  int scenes = 0;
};

// proxseg's stage times and Table 1 sums, gathered while its variants run.
struct Stages {
  std::map<std::string, std::map<std::string, double>> ms;  // variant -> stage -> sum
  std::map<std::string, int> frames;                        // variant -> frames timed
  std::vector<std::string> order;                           // in pipeline order
  std::vector<std::string> concurrent;  // stages on a second thread, not in the sequence
  // set -> "variant k-means" / "variant k-means+MRF" -> sums
  std::map<std::string, std::map<std::string, Table1>> table1;
  std::string current_set;
  // Time a method spent on work outside its own answer (the Table 1 rerun), taken off its time
  // per frame.
  double untimed_seconds = 0;
};

inline const std::string kTotal = "total (segment() wall time)";

// Everything the report reads.
struct Measured {
  std::vector<SceneSet> sets;
  std::vector<std::string> methods;                               // that ran, in order
  std::vector<std::string> run_variants;                          // the proxseg variants that ran
  std::vector<std::pair<std::string, std::string>> config_files;  // name, path
  std::vector<SceneScores> scores;
  std::map<std::string, std::vector<SceneScores>> scores_of_set;
  Stages stages;
  Processes processes;
};

std::string report_markdown(const Options& o, const Measured& m);

}  // namespace proxseg::bench::segbench
