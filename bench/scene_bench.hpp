// The plain data of scene_bench (bench/scene_bench.cpp): its options, the scene sets and splits,
// the methods and what each gave, and the functions of its other files (scene_bench_sets.cpp,
// scene_bench_peer.cpp, scene_bench_report.cpp, scene_bench_markdown.cpp).
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/eval/scene_eval.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "peers_rec.hpp"

namespace proxseg::bench::scenebench {

struct Options {
  std::string models = "../shared/data/lmo/models", output, config, peers = "all";
  // --set objects: the object-varied set (object_set.hpp) instead of the LINEMOD catalogue.
  std::string set = "lmo", ycbv = "../shared/data/ycbv", textured = "../shared/data/ycb_textured";
  int fold_scenes = 4, fold_report_scenes = -1, fold_known = 12, fold_unknown = 4, max_folds = 0;
  std::string dev_seeds = "1-20", report_seeds = "101-120";
  int scenes = 0;
  std::uint32_t first_seed = 1;
  int views = 8, threads = 0;
  int peer_ransac = 10000;
  bool json = false;
};

void add_options(CLI::App& app, Options& o);

// The objects a split's scenes are drawn from and the database they are recognised against.
struct SceneSet {
  std::string name;  // "lmo", or an object fold's ("A1", ...)
  SceneCatalogue catalogue;
  Database db;
};

struct Split {
  std::string name;   // "dev", "report", "A1 dev", ...
  std::string group;  // the tables' row: "dev", "report", "A dev", "B report", ...
  std::vector<std::uint32_t> seeds;
  int set = 0;  // index into the scene sets
};

// A recogniser of whole scenes: frame (and the set's database) -> predictions.
struct Method {
  std::string label;
  std::function<std::vector<Prediction>(const Frame&, const SceneSet&)> run;
};

// One truth object of one scene with what a method made of it (truths.csv, the failure table).
struct TruthRow {
  std::uint32_t scene = 0;
  TruthObject truth;
  int prediction = -1;
  double iou = 0;
  std::string name;  // the matched prediction's, "" when unmatched
  double score = 0;
};

// Everything one method gave on one split.
struct Result {
  SceneCounts counts;
  std::vector<PredictionRow> rows;
  std::vector<TruthRow> truths;
  std::vector<int> points;  // per row: the prediction's size
};

// Everything a run measured, as the report reads it.
struct Bench {
  SegmentParams sp;
  RecognitionParams rp;
  int team = 0;  // threads
  std::vector<SceneSet> sets;
  std::vector<Split> splits;
  std::vector<std::string> groups;  // of the splits, in order of first appearance
  SceneSetParams set_params;
  std::vector<Method> methods;
  std::string peer_label;
  peers::Open3dParams o3d;
  std::vector<std::vector<Result>> results;  // [split][method]
  std::vector<std::vector<Result>> grouped;  // [group][method]: the splits' results summed
  std::string load_before, load_after;
};

// ---- The scene sets and splits (scene_bench_sets.cpp) ----

// "1-20", "3,5,101-103": the seeds in the given order (a usage error naming `option` else).
std::vector<std::uint32_t> parse_seeds(const std::string& spec, const std::string& option);
// "1-20" for a run of consecutive seeds, else the list.
std::string seeds_text(const std::vector<std::uint32_t>& seeds);
// The scene sets and splits: the LINEMOD catalogue with a dev and a report split, or per object
// fold of --set objects a dev and a report split of --fold-scenes scenes each (groups "A dev",
// "A report", "B dev", "B report": a rule chosen on one half is scored on the other).
void make_splits(const Options& o, const DescriptorParams& descriptor, std::vector<SceneSet>& sets,
                 std::vector<Split>& splits);

// ---- The peer pipeline (scene_bench_peer.cpp) ----

// PCL's plane + Euclidean clusters as candidates (seg_bench's "PCL plane + Euclidean"), each
// described like proxseg's candidates and aligned to every view by Open3D (rec_bench's peer),
// named exactly as proxseg::recognize does (peer_naming.hpp). A cluster too small to describe is
// not made, as recognize_scene() does with such candidates.
std::vector<Prediction> peer_scene(const Frame& frame, const Database& db,
                                   const peers::Open3dPeer& open3d, const RecognitionParams& rp,
                                   int threads);

// ---- The report (scene_bench_report.cpp, scene_bench_markdown.cpp) ----

// scenes.json.
nlohmann::json report_json(const Options& o, const Bench& b);
// scenes.md.
std::string report_markdown(const Options& o, const Bench& b);
// predictions.csv and truths.csv.
std::string predictions_csv(const Bench& b);
std::string truths_csv(const Bench& b);
// The failures of method mi over every split: counts per truth name (and answer).
struct Failures {
  std::map<std::string, int> wrong, called_unknown, missed, unknown_named, on_nothing;
};
Failures failures(const Bench& b, std::size_t mi);
// The seeds of group gi's splits, in order.
std::vector<std::uint32_t> group_seeds(const Bench& b, std::size_t gi);
// The index of each group a minimum score is chosen on: the dev groups (the first group when none
// is called dev).
std::vector<std::size_t> choosers(const Bench& b);

}  // namespace proxseg::bench::scenebench
