// scene_bench (`make bench-scenes`): end-to-end scene recognition on generated cluttered
// tabletops (include/proxseg/eval/scene_eval.hpp). Each scene of the development and report splits
// holds known objects (in the database), colour look-alikes of them, unknown catalogue objects
// and the generator's random boxes and cylinders; proxseg (segment + recognize_scene) and the
// peer pipeline (PCL plane + Euclidean clusters, Open3D RANSAC + ICP against every view, named
// exactly as proxseg names) run on the same scenes and are scored the same way: detection,
// precision / recall / F1 over the known objects, unknown objects named, pose (ADD-S), time,
// and the ROC with negatives as the minimum score varies. Writes OUT/scenes.md, scenes.json,
// predictions.csv and truths.csv. Exit codes: 0 ok, 1 bad input, 2 usage.
// Usage: scene_bench [--models DIR] -o OUT [--dev-seeds LIST] [--report-seeds LIST]
//                    [--scenes N [--first-seed S]] [--views N] [--threads T] [--config FILE]
//                    [--peers all|none] [--json]
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/version.hpp>
#include <proxseg/eval/object_set.hpp>
#include <proxseg/eval/scene_eval.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/memory.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "bench_main.hpp"
#include "bench_util.hpp"
#include "peer_naming.hpp"
#include "peers_pcl.hpp"
#include "peers_rec.hpp"
#include "progress.hpp"  // apps/progress.hpp: the CLI's progress bar

namespace {

using proxseg::InputError;
using proxseg::Prediction;
using proxseg::PredictionRow;
using proxseg::SceneCounts;
using proxseg::SceneCurvePoint;

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

// "1-20", "3,5,101-103": the seeds in the given order.
std::vector<std::uint32_t> parse_seeds(const std::string& spec, const std::string& option) {
  std::vector<std::uint32_t> seeds;
  std::stringstream in(spec);
  for (std::string item; std::getline(in, item, ',');) {
    const auto dash = item.find('-');
    try {
      std::size_t used = 0;
      const unsigned long a = std::stoul(item.substr(0, dash), &used);
      if (used != item.substr(0, dash).size()) throw std::invalid_argument(item);
      unsigned long b = a;
      if (dash != std::string::npos) {
        b = std::stoul(item.substr(dash + 1), &used);
        if (used != item.size() - dash - 1) throw std::invalid_argument(item);
      }
      if (b < a || b - a > 100000 || b > 0xffffffffUL) throw std::invalid_argument(item);
      for (unsigned long s = a; s <= b; ++s) seeds.push_back(static_cast<std::uint32_t>(s));
    } catch (const std::exception&) {
      throw CLI::ValidationError(option + ": expected seeds like 1-20 or 3,5,101-103, got '" +
                                 spec + "'");
    }
  }
  if (seeds.empty()) throw CLI::ValidationError(option + ": no seeds");
  return seeds;
}

// "1-20" for a run of consecutive seeds, else the list.
std::string seeds_text(const std::vector<std::uint32_t>& seeds) {
  bool run = true;
  for (std::size_t i = 1; i < seeds.size(); ++i) run = run && seeds[i] == seeds[i - 1] + 1;
  if (run && seeds.size() > 1)
    return std::to_string(seeds.front()) + "-" + std::to_string(seeds.back());
  std::string s;
  for (auto x : seeds) s += (s.empty() ? "" : ",") + std::to_string(x);
  return s;
}

using proxseg::bench::Clock;
using proxseg::bench::machine;
using proxseg::bench::ms_since;
using proxseg::bench::seconds_since;
using proxseg::bench::utc_now;
std::string fmt(double v, int digits = 2) {
  return proxseg::bench::fixed(v, digits);
}
std::string pct(double rate) {
  return proxseg::bench::percent(rate);
}
// The objects a split's scenes are drawn from and the database they are recognised against.
struct SceneSet {
  std::string name;  // "lmo", or an object fold's ("A1", ...)
  proxseg::SceneCatalogue catalogue;
  proxseg::Database db;
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
  std::function<std::vector<Prediction>(const proxseg::Frame&, const SceneSet&)> run;
};

// One truth object of one scene with what a method made of it (truths.csv, the failure table).
struct TruthRow {
  std::uint32_t scene = 0;
  proxseg::TruthObject truth;
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

std::vector<std::vector<int>> segments_of(const std::vector<std::uint32_t>& labels,
                                          std::uint32_t first) {
  std::map<std::uint32_t, std::vector<int>> by_label;
  for (std::size_t k = 0; k < labels.size(); ++k)
    if (labels[k] >= first) by_label[labels[k]].push_back(static_cast<int>(k));
  std::vector<std::vector<int>> out;
  for (auto& [label, pts] : by_label) out.push_back(std::move(pts));
  return out;
}

// The peer pipeline: PCL's plane + Euclidean clusters as candidates (seg_bench's "PCL plane +
// Euclidean"), each described like proxseg's candidates and aligned to every view by Open3D
// (rec_bench's peer), named exactly as proxseg::recognize does (peer_naming.hpp). A cluster too
// small to describe is not made, as recognize_scene() does with such candidates.
std::vector<Prediction> peer_scene(const proxseg::Frame& frame, const proxseg::Database& db,
                                   const proxseg::peers::Open3dPeer& open3d,
                                   const proxseg::RecognitionParams& rp, int threads) {
  bool plane = false;
  const std::vector<std::uint32_t> labels = proxseg::peers::euclidean(frame, {}, &plane);
  std::vector<Prediction> out;
  for (std::vector<int>& points : segments_of(labels, plane ? 2 : 1)) {
    std::vector<Eigen::Vector3d> xyz;
    std::vector<proxseg::Rgb> rgb;
    xyz.reserve(points.size());
    for (int k : points) {
      xyz.push_back(frame.xyz[k].cast<double>());
      if (frame.rgb.size() == frame.size()) rgb.push_back(frame.rgb[k]);
    }
    proxseg::Cloud c;
    try {
      c = proxseg::describe_candidate(xyz, db, rgb.empty() ? nullptr : &rgb);
    } catch (const InputError&) {
      continue;
    }
    const proxseg::peers::PeerAnswer a = proxseg::peers::name_alignments(
        c, open3d.align(c, static_cast<int>(rp.seed)), db, rp, threads);
    Prediction p;
    p.points = std::move(points);
    p.name = a.name;
    p.best = a.best;
    p.score = a.score;
    p.runner_up = a.runner_up;
    p.colour = a.colour;
    p.pose = a.pose;
    out.push_back(std::move(p));
  }
  return out;
}

nlohmann::json counts_json(const SceneCounts& c) {
  return {{"scenes", c.scenes},
          {"truths", c.truths},
          {"known", c.known},
          {"unknown", c.unknown},
          {"predictions", c.predictions},
          {"detected", c.detected},
          {"tp", c.tp},
          {"fn", c.fn},
          {"fp", c.fp},
          {"unknown_named", c.unknown_named},
          {"known_unknown", c.known_unknown},
          {"known_unknown_share", c.known_unknown_share()},
          {"pose_ok", c.pose_ok},
          {"detection", c.detection()},
          {"precision", c.precision()},
          {"recall", c.recall()},
          {"f1", c.f1()},
          {"unknown_named_share", c.unknown_named_share()},
          {"pose_rate", c.pose_rate()},
          {"seconds_per_scene", c.seconds_per_scene()}};
}

nlohmann::json point_json(const SceneCurvePoint& p) {
  return {{"min_score", p.min_score},
          {"tp", p.tp},
          {"fp", p.fp},
          {"unknown_named", p.unknown_named},
          {"tpr", p.tpr},
          {"unknown_named_share", p.unknown_named_share},
          {"precision", p.precision},
          {"f1", p.f1}};
}

std::string csv_name(const std::string& s) {
  return s.empty() ? "-" : s;
}

// The most frequent entries of a tally, "a -> b (n)", most frequent first (ties by name).
std::string top(const std::map<std::string, int>& tally, std::size_t n) {
  std::vector<std::pair<std::string, int>> v(tally.begin(), tally.end());
  std::stable_sort(v.begin(), v.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  std::string s;
  for (std::size_t i = 0; i < v.size() && i < n; ++i)
    s += (s.empty() ? "" : ", ") + v[i].first + " (" + std::to_string(v[i].second) + ")";
  return s.empty() ? "-" : s;
}

// Seeds of fold f's split: the first seed + 1000 f onwards, so that folds draw other scenes.
std::vector<std::uint32_t> fold_seeds(std::uint32_t first, int count, int fold) {
  return proxseg::seed_range(first + 1000u * static_cast<std::uint32_t>(fold), count);
}

// The scene sets and splits: the LINEMOD catalogue with a dev and a report split, or per object
// fold of --set objects a dev and a report split of --fold-scenes scenes each (groups "A dev",
// "A report", "B dev", "B report": a rule chosen on one half is scored on the other).
void make_splits(const Options& o, const proxseg::DescriptorParams& descriptor,
                 std::vector<SceneSet>& sets, std::vector<Split>& splits) {
  if (o.set == "lmo") {
    SceneSet set{"lmo", proxseg::scene_catalogue(o.models), {}};
    set.db = proxseg::scene_database(set.catalogue, o.views, descriptor);
    sets.push_back(std::move(set));
    if (o.scenes > 0) {
      splits.push_back({"scenes", "scenes", proxseg::seed_range(o.first_seed, o.scenes), 0});
    } else {
      splits.push_back({"dev", "dev", parse_seeds(o.dev_seeds, "--dev-seeds"), 0});
      splits.push_back({"report", "report", parse_seeds(o.report_seeds, "--report-seeds"), 0});
    }
    return;
  }
  if (o.set != "objects")
    throw CLI::ValidationError("--set: expected lmo or objects, got '" + o.set + "'");
  proxseg::ObjectPoolParams pp;
  pp.linemod_dir = o.models;
  pp.ycbv_dir = o.ycbv;
  pp.textured_dir = o.textured;
  const std::vector<proxseg::PoolObject> pool = proxseg::object_pool(pp);
  proxseg::ObjectFoldParams fp;
  fp.known = o.fold_known;
  fp.unknown = o.fold_unknown;
  const std::vector<proxseg::ObjectFold> folds = proxseg::object_folds(pool, fp);
  proxseg::CaptureParams capture;
  capture.views = o.views;
  std::vector<int> per_half(2, 0);
  for (std::size_t f = 0; f < folds.size(); ++f) {
    if (o.max_folds > 0 && per_half[folds[f].half]++ >= o.max_folds) continue;
    SceneSet set{folds[f].name, proxseg::fold_catalogue(pool, folds[f]), {}};
    set.db = proxseg::captured_database(set.catalogue, capture, descriptor);
    const std::string half(1, char('A' + folds[f].half));
    const int idx = static_cast<int>(sets.size());
    sets.push_back(std::move(set));
    splits.push_back({folds[f].name + " dev", half + " dev",
                      fold_seeds(1, o.fold_scenes, static_cast<int>(f)), idx});
    const int report = o.fold_report_scenes < 0 ? o.fold_scenes : o.fold_report_scenes;
    if (report > 0)
      splits.push_back({folds[f].name + " report", half + " report",
                        fold_seeds(101, report, static_cast<int>(f)), idx});
  }
}

int run(const Options& o) {
  namespace fs = std::filesystem;
  if (o.peers != "all" && o.peers != "none")
    throw CLI::ValidationError("--peers: expected all or none, got '" + o.peers + "'");
  proxseg::SegmentParams sp;
  proxseg::RecognitionParams rp;
  if (!o.config.empty()) std::tie(sp, rp) = proxseg::read_recognize_params(o.config, sp, rp);
  sp.threads = rp.threads = o.threads;
  proxseg::validate(sp);
  // The curves move min_score and keep the rest of the naming rule (rp).
  proxseg::validate(rp);
  if (o.threads > 0) omp_set_num_threads(o.threads);
  const int team = o.threads > 0 ? o.threads : omp_get_max_threads();

  const fs::path out(o.output);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out))
    throw InputError(o.output + ": cannot create the output folder (" + ec.message() + ")");

  auto t0 = Clock::now();
  const proxseg::DescriptorParams descriptor;
  std::vector<SceneSet> sets;
  std::vector<Split> splits;
  make_splits(o, descriptor, sets, splits);
  std::size_t views_total = 0;
  for (const SceneSet& set : sets) views_total += set.db.views.size();
  std::cerr << "scene_bench: " << sets.size() << " database" << (sets.size() > 1 ? "s" : "")
            << " of " << views_total / sets.size() << " views on average (" << o.views
            << " per known object) in " << fmt(seconds_since(t0), 1) << " s\n";
  const proxseg::SceneSetParams set_params;
  // The groups of splits that the tables report, in order of first appearance.
  std::vector<std::string> groups;
  for (const Split& s : splits)
    if (std::find(groups.begin(), groups.end(), s.group) == groups.end()) groups.push_back(s.group);

  std::vector<Method> methods;
  methods.push_back({"proxseg", [&](const proxseg::Frame& f, const SceneSet& set) {
                       const proxseg::SegmentResult s = proxseg::segment(f, sp);
                       return proxseg::predictions_of(
                           proxseg::recognize_scene(f, s.selection, set.db, rp));
                     }});
  proxseg::peers::Open3dParams o3d;
  // rec_bench gives Open3D 100k iterations (its 4M default costs 2.5x, no gain); against 96
  // views for each of ~12 clusters that is ~100 s per scene here, so the scenes default to 10k.
  o3d.ransac_iterations = o.peer_ransac;
  // One peer per database, made when first needed.
  std::map<const SceneSet*, std::unique_ptr<proxseg::peers::Open3dPeer>> open3d;
  const std::string peer_label =
      "PCL Euclidean + Open3D RANSAC " + std::to_string(o.peer_ransac / 1000) + "k + ICP";
  if (o.peers == "all") {
    methods.push_back({peer_label, [&](const proxseg::Frame& f, const SceneSet& set) {
                         auto& peer = open3d[&set];
                         if (!peer)
                           peer =
                               std::make_unique<proxseg::peers::Open3dPeer>(set.db, o3d, o.threads);
                         return peer_scene(f, set.db, *peer, rp, team);
                       }});
  }

  const std::string load_before = proxseg::bench::load_average();
  // The runs: every scene is generated once and given to every method.
  std::vector<std::vector<Result>> results(splits.size(), std::vector<Result>(methods.size()));
  std::size_t steps = 0;
  for (const Split& s : splits) steps += s.seeds.size() * methods.size();
  cli::Progress progress(steps);
  for (std::size_t si = 0; si < splits.size(); ++si) {
    const SceneSet& set = sets[splits[si].set];
    for (std::uint32_t seed : splits[si].seeds) {
      const proxseg::ClutterScene scene =
          proxseg::clutter_layout_scene(proxseg::scene_set_params(seed, set.catalogue, set_params));
      const std::vector<proxseg::TruthObject> truth = proxseg::scene_truth(scene, set.catalogue);
      for (std::size_t mi = 0; mi < methods.size(); ++mi) {
        const auto start = Clock::now();
        const std::vector<Prediction> predictions = methods[mi].run(scene.frame, set);
        const double sec = seconds_since(start);
        proxseg::SceneEvaluation e =
            proxseg::evaluate_scene(seed, truth, predictions, set.catalogue);
        e.counts.seconds = sec;
        Result& r = results[si][mi];
        r.counts += e.counts;
        for (std::size_t j = 0; j < e.rows.size(); ++j) {
          r.rows.push_back(e.rows[j]);
          r.points.push_back(static_cast<int>(predictions[j].points.size()));
        }
        for (std::size_t i = 0; i < truth.size(); ++i) {
          TruthRow t;
          t.scene = seed;
          t.truth = truth[i];
          t.prediction = e.match[i];
          if (t.prediction >= 0) {
            t.iou = e.rows[t.prediction].iou;
            t.name = predictions[t.prediction].name;
            t.score = predictions[t.prediction].score;
          }
          r.truths.push_back(std::move(t));
        }
        progress.step(splits[si].name + " seed " + std::to_string(seed) + ", " + methods[mi].label +
                      ": " + std::to_string(e.counts.tp) + "/" + std::to_string(e.counts.known) +
                      " known named right, " + std::to_string(e.counts.fp) + " FP, " + fmt(sec, 1) +
                      " s");
      }
    }
  }

  // The splits' results summed per group: the tables' rows.
  std::vector<std::vector<Result>> grouped(groups.size(), std::vector<Result>(methods.size()));
  for (std::size_t si = 0; si < splits.size(); ++si) {
    const std::size_t gi =
        std::find(groups.begin(), groups.end(), splits[si].group) - groups.begin();
    for (std::size_t mi = 0; mi < methods.size(); ++mi) {
      Result& g = grouped[gi][mi];
      const Result& r = results[si][mi];
      g.counts += r.counts;
      g.rows.insert(g.rows.end(), r.rows.begin(), r.rows.end());
      g.truths.insert(g.truths.end(), r.truths.begin(), r.truths.end());
      g.points.insert(g.points.end(), r.points.begin(), r.points.end());
    }
  }

  // The report.
  const std::vector<double> thresholds = {0.3, 0.4, 0.5, 0.6, 0.7, 0.8};
  nlohmann::json summary;
  summary["proxseg"] = {{"version", proxseg::version()}, {"commit", proxseg::git_commit()}};
  nlohmann::json cat = nlohmann::json::array();
  for (const SceneSet& set : sets) {
    nlohmann::json entries = nlohmann::json::array();
    for (std::size_t i = 0; i < set.catalogue.entries.size(); ++i)
      entries.push_back({{"name", set.catalogue.entries[i].name},
                         {"kind", proxseg::to_string(set.catalogue.entries[i].kind)},
                         {"known", set.catalogue.known[i] != 0},
                         {"diameter", set.catalogue.diameters[i]}});
    cat.push_back({{"set", set.name}, {"views", set.db.views.size()}, {"entries", entries}});
  }
  summary["load_average"] = {{"before", load_before}, {"after", proxseg::bench::load_average()}};
  summary["parameters"] = {{"models", o.models},
                           {"set", o.set},
                           {"sets", cat},
                           {"views_per_object", o.views},
                           {"min_objects", set_params.min_objects},
                           {"max_objects", set_params.max_objects},
                           {"catalogue_share", set_params.catalogue_share},
                           {"mesh_share", set_params.mesh_share},
                           {"segmentation", proxseg::to_json(sp)},
                           {"recognition", proxseg::to_json(rp)},
                           {"peer", o.peers == "all" ? peer_label : ""},
                           {"open3d_ransac_iterations", o3d.ransac_iterations},
                           {"threads", team}};
  summary["splits"] = nlohmann::json::array();

  std::ostringstream md, csv, truth_csv;
  const std::string commit = proxseg::bench::git_commit();
  if (o.set == "lmo")
    md << "## Scene recognition: segmentation + recognition on generated cluttered tabletops\n\n";
  else
    md << "## Recognition on the object folds"
       << (o.max_folds > 0 ? " (the first " + std::to_string(o.max_folds) + " of each half)" : "")
       << ": objects that no choice was made on\n\n";
  md << "Generated by `make " << (o.set == "lmo" ? "bench-scenes" : "bench-objects")
     << "` (bench/scene_bench.cpp) at commit " << commit << " on " << machine() << ", " << utc_now()
     << ", " << team << " threads (load average " << load_before << " before the runs, "
     << proxseg::bench::load_average()
     << " after: the times are wall times). Scenes: the clutter generator "
     << "(docs/clutter.md) with " << set_params.min_objects << "-" << set_params.max_objects
     << " objects; a free or touching object is drawn with probability "
     << fmt(set_params.catalogue_share, 2) << " from a catalogue of fixed objects, at most 2 of "
     << "each per scene; the others are the generator's random boxes and cylinders (unknown). ";
  if (o.set == "lmo") {
    const proxseg::SceneCatalogue& catalogue = sets[0].catalogue;
    std::size_t objects_known = 0;
    for (char k : catalogue.known) objects_known += k != 0;
    md << "The catalogue (scene_catalogue(), include/proxseg/eval/scene_eval.hpp): "
       << objects_known << " known (in the database: ";
    for (std::size_t i = 0; i < catalogue.entries.size(); ++i)
      if (catalogue.known[i]) md << (i ? ", " : "") << catalogue.entries[i].name;
    md << ") and " << catalogue.entries.size() - objects_known << " unknown (";
    std::string unknown_names;
    for (std::size_t i = 0; i < catalogue.entries.size(); ++i)
      if (!catalogue.known[i])
        unknown_names += (unknown_names.empty() ? "" : ", ") + catalogue.entries[i].name;
    md << unknown_names
       << "). duck-blue and ape-green are the duck and ape meshes in another hue, the markers one "
          "cylinder in two colours, the boxes near in shape and different in colour. Database: "
       << o.views << " noiseless render_views() per known object (" << sets[0].db.views.size()
       << " views). ";
  } else {
    md << "The object-varied set (`--set objects`, include/proxseg/eval/object_set.hpp): a pool "
          "of objects in two halves A and B; per half, object folds of "
       << o.fold_known << " known and " << o.fold_unknown
       << " unknown objects such that every object is unknown in one fold; per fold "
       << o.fold_scenes << " dev and " << o.fold_scenes << " report scenes. Databases: " << o.views
       << " views per known object captured unlike the scenes (captured_database(): 0.45 m, "
          "Kinect noise, a light beside the camera, another white balance). A rule chosen on "
          "half A is scored on half B and the other way round. Folds:";
    for (std::size_t k = 0; k < sets.size(); ++k) {
      std::string unknown_names;
      for (std::size_t i = 0; i < sets[k].catalogue.entries.size(); ++i)
        if (!sets[k].catalogue.known[i])
          unknown_names += (unknown_names.empty() ? "" : ", ") + sets[k].catalogue.entries[i].name;
      md << (k ? ";" : "") << " " << sets[k].name << " unknown: " << unknown_names;
    }
    md << ". ";
  }
  md << "proxseg: segment() with "
     << (o.config.empty() ? "default parameters" : "the config's parameters")
     << " + recognize_scene() (min score " << fmt(rp.min_score, 2) << ", min margin "
     << fmt(rp.min_margin, 2) << " unless the score reaches " << fmt(rp.confident_score, 2)
     << ", or a lone match: at least " << fmt(rp.lone_score, 2) << " with the runner-up under "
     << fmt(rp.lone_ratio, 2) << " of it; a look-alike vote (" << fmt(rp.lookalike_share, 2)
     << " of the votes) when the runner-up is within the margin"
     << "; shortlist " << rp.shortlist << " views, early reject under " << fmt(rp.early_reject, 2)
     << ", split and merge on). "
     << "Peer: PCL plane + Euclidean clusters (seg_bench's \"PCL plane + Euclidean\") as "
        "candidates, each described like proxseg's (with its colours) and aligned to every view "
        "by Open3D RANSAC "
     << o.peer_ransac / 1000
     << "k + ICP (rec_bench's peer, 100k there; fewer here, as every cluster meets every "
        "view); its poses are scored and the candidate named exactly as proxseg names (same "
        "score, same naming rule).\n\n"
     << "Measures (docs/metrics.md, \"Scenes\"): truth objects and predictions are matched by "
        "the assignment of largest total point IoU among pairs with IoU >= 0.5; detection = "
        "matched truths / truths. TP: a known truth whose match carries its name; FN: the other "
        "known truths; FP: every prediction with a known name that is not a TP (a wrong name, a "
        "named unknown object, a name on no object). Precision = TP / (TP + FP), recall = TP / "
        "known truths. Unknown named: unknown truths whose match carries a known name. Pose ok: "
        "TPs with ADD-S under 10 % of the object's diameter. s / scene: segmentation + "
        "recognition, wall (generating the scene not counted).\n\n";

  const auto table_header = [&] {
    md << "| method | scenes | truth objects (known / unknown) | detection (%) | precision | "
          "recall | F1 | unknown named (%) | known called unknown (%) | pose ok (%) | s / scene |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  };
  const auto row = [&](const std::string& label, const SceneCounts& c) {
    md << "| " << label << " | " << c.scenes << " | " << c.truths << " (" << c.known << " / "
       << c.unknown << ") | " << pct(c.detection()) << " | " << fmt(c.precision(), 3) << " | "
       << fmt(c.recall(), 3) << " | " << fmt(c.f1(), 3) << " | " << pct(c.unknown_named_share())
       << " (" << c.unknown_named << ") | " << pct(c.known_unknown_share()) << " ("
       << c.known_unknown << ") | " << pct(c.pose_rate()) << " | " << fmt(c.seconds_per_scene(), 1)
       << " |\n";
  };
  for (std::size_t gi = 0; gi < groups.size(); ++gi) {
    std::vector<std::uint32_t> seeds;
    for (const Split& sp : splits)
      if (sp.group == groups[gi]) seeds.insert(seeds.end(), sp.seeds.begin(), sp.seeds.end());
    md << "### Split " << groups[gi];
    if (o.set == "lmo") md << " (seeds " << seeds_text(seeds) << ")";
    md << "\n\n";
    table_header();
    nlohmann::json js = {{"name", groups[gi]}, {"seeds", seeds}};
    js["methods"] = nlohmann::json::array();
    for (std::size_t mi = 0; mi < methods.size(); ++mi) {
      const Result& r = grouped[gi][mi];
      const SceneCounts& c = r.counts;
      row(methods[mi].label, c);
      nlohmann::json jm = {{"label", methods[mi].label}, {"counts", counts_json(c)}};
      jm["curve"] = nlohmann::json::array();
      for (const SceneCurvePoint& p : proxseg::scene_curve(r.rows, c.known, c.unknown, rp))
        jm["curve"].push_back(point_json(p));
      jm["at"] = nlohmann::json::array();
      for (double t : thresholds)
        jm["at"].push_back(point_json(proxseg::scene_point(r.rows, c.known, c.unknown, t, rp)));
      jm["best_threshold"] = point_json(
          proxseg::best_threshold(proxseg::scene_curve(r.rows, c.known, c.unknown, rp), 0.1));
      js["methods"].push_back(jm);
    }
    md << "\n";
    summary["splits"].push_back(js);
  }
  if (o.set != "lmo") {
    md << "### Per fold\n\n";
    table_header();
    summary["folds"] = nlohmann::json::array();
    for (std::size_t si = 0; si < splits.size(); ++si)
      for (std::size_t mi = 0; mi < methods.size(); ++mi) {
        row(methods[mi].label + ", " + splits[si].name, results[si][mi].counts);
        summary["folds"].push_back({{"split", splits[si].name},
                                    {"label", methods[mi].label},
                                    {"seeds", splits[si].seeds},
                                    {"counts", counts_json(results[si][mi].counts)}});
      }
    md << "\n";
  }

  md << "### ROC with negatives\n\nThe same answers re-thresholded: a prediction is named after "
        "its best view when the score reaches the minimum (and leads the runner-up by min_margin "
        "unless it reaches confident_score, both kept at the run's value), else \"unknown\" (the "
        "segmentation, "
        "and proxseg's split and merge passes, which depend on the minimum score, are not "
        "re-run). TPR = TP / known truths; every point of the curve is in scenes.json.\n\n"
     << "| method | split | min score | TPR | unknown named (%) | precision | F1 |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (std::size_t mi = 0; mi < methods.size(); ++mi)
    for (std::size_t gi = 0; gi < groups.size(); ++gi) {
      const Result& r = grouped[gi][mi];
      for (double t : thresholds) {
        const SceneCurvePoint p =
            proxseg::scene_point(r.rows, r.counts.known, r.counts.unknown, t, rp);
        md << "| " << methods[mi].label << " | " << groups[gi] << " | " << fmt(t, 2) << " | "
           << fmt(p.tpr, 3) << " | " << pct(p.unknown_named_share) << " | " << fmt(p.precision, 3)
           << " | " << fmt(p.f1, 3) << " |\n";
      }
    }
  md << "\n";

  // The minimum score of best F1 with at most 10 % of the unknowns named, chosen on each dev
  // group (the first group when none is called dev) and applied to the others.
  std::vector<std::size_t> choosers;
  for (std::size_t gi = 0; gi < groups.size(); ++gi)
    if (groups[gi].size() >= 3 && groups[gi].compare(groups[gi].size() - 3, 3, "dev") == 0)
      choosers.push_back(gi);
  if (choosers.empty()) choosers.push_back(0);
  summary["chosen_threshold"] = nlohmann::json::array();
  for (std::size_t ci : choosers) {
    md << "### Minimum score chosen on " << groups[ci] << "\n\nThe minimum score of largest F1 on "
       << groups[ci] << " with at most 10 % of the unknown objects named"
       << (groups.size() > 1 ? ", then applied to the other splits" : "") << ".\n\n"
       << "| method | split | min score | TPR | unknown named (%) | precision | F1 |\n"
       << "|---|---|---|---|---|---|---|\n";
    for (std::size_t mi = 0; mi < methods.size(); ++mi) {
      const Result& d = grouped[ci][mi];
      const SceneCurvePoint best = proxseg::best_threshold(
          proxseg::scene_curve(d.rows, d.counts.known, d.counts.unknown, rp), 0.1);
      nlohmann::json jc = {
          {"label", methods[mi].label}, {"chosen_on", groups[ci]}, {"min_score", best.min_score}};
      for (std::size_t gi = 0; gi < groups.size(); ++gi) {
        const Result& r = grouped[gi][mi];
        const SceneCurvePoint p =
            proxseg::scene_point(r.rows, r.counts.known, r.counts.unknown, best.min_score, rp);
        md << "| " << methods[mi].label << " | " << groups[gi] << " | " << fmt(best.min_score, 3)
           << " | " << fmt(p.tpr, 3) << " | " << pct(p.unknown_named_share) << " | "
           << fmt(p.precision, 3) << " | " << fmt(p.f1, 3) << " |\n";
        jc[groups[gi]] = point_json(p);
      }
      summary["chosen_threshold"].push_back(jc);
    }
    md << "\n";
  }

  // Where it fails, over every split: counts per truth name (and answer).
  md << "### Where it fails (all splits)\n\n"
     << "| method | known named wrong (truth -> answer) | known called unknown | not detected "
        "(IoU < 0.5) | unknown named | names on no object |\n|---|---|---|---|---|---|\n";
  summary["failures"] = nlohmann::json::array();
  for (std::size_t mi = 0; mi < methods.size(); ++mi) {
    std::map<std::string, int> wrong, called_unknown, missed, unknown_named, on_nothing;
    for (std::size_t si = 0; si < splits.size(); ++si) {
      const Result& r = results[si][mi];
      for (const TruthRow& t : r.truths) {
        if (t.prediction < 0) {
          ++missed[t.truth.name];
        } else if (t.truth.known && t.name == "unknown") {
          ++called_unknown[t.truth.name];
        } else if (t.truth.known && t.name != t.truth.name) {
          ++wrong[t.truth.name + " -> " + t.name];
        } else if (!t.truth.known && t.name != "unknown") {
          ++unknown_named[t.truth.name + " -> " + t.name];
        }
      }
      for (const PredictionRow& p : r.rows)
        if (p.truth < 0 && p.name != "unknown") ++on_nothing[p.name];
    }
    md << "| " << methods[mi].label << " | " << top(wrong, 8) << " | " << top(called_unknown, 6)
       << " | " << top(missed, 6) << " | " << top(unknown_named, 6) << " | " << top(on_nothing, 6)
       << " |\n";
    summary["failures"].push_back({{"label", methods[mi].label},
                                   {"named_wrong", wrong},
                                   {"called_unknown", called_unknown},
                                   {"not_detected", missed},
                                   {"unknown_named", unknown_named},
                                   {"named_on_nothing", on_nothing}});
  }
  md << "\nPer prediction: `predictions.csv`; per truth object: `truths.csv`.\n";

  csv << "method,split,scene,prediction,points,truth,truth_name,truth_known,iou,name,best,score,"
         "runner_up,colour,add_s_m,pose_ok\n";
  truth_csv << "method,split,scene,label,name,catalogue,known,points,prediction,iou,answer,score\n";
  for (std::size_t si = 0; si < splits.size(); ++si)
    for (std::size_t mi = 0; mi < methods.size(); ++mi) {
      const Result& r = results[si][mi];
      for (std::size_t j = 0; j < r.rows.size(); ++j) {
        const PredictionRow& p = r.rows[j];
        csv << '"' << methods[mi].label << "\"," << splits[si].name << "," << p.scene << ","
            << p.prediction << "," << r.points[j] << "," << p.truth << "," << csv_name(p.truth_name)
            << "," << p.truth_known << "," << fmt(p.iou, 3) << "," << p.name << ","
            << csv_name(p.best) << "," << fmt(p.score, 4) << "," << fmt(p.runner_up, 4) << ","
            << (p.colour < 0 ? "" : fmt(p.colour, 4)) << "," << (p.add_s < 0 ? "" : fmt(p.add_s, 4))
            << "," << p.pose_ok << "\n";
      }
      for (const TruthRow& t : r.truths)
        truth_csv << '"' << methods[mi].label << "\"," << splits[si].name << "," << t.scene << ","
                  << t.truth.label << "," << t.truth.name << "," << t.truth.catalogue << ","
                  << t.truth.known << "," << t.truth.points.size() << "," << t.prediction << ","
                  << fmt(t.iou, 3) << "," << csv_name(t.name) << "," << fmt(t.score, 4) << "\n";
    }

  return proxseg::bench::finish(out,
                                {{"scenes.md", md.str()},
                                 {"scenes.json", summary.dump(2) + "\n"},
                                 {"predictions.csv", csv.str()},
                                 {"truths.csv", truth_csv.str()}},
                                summary, md.str(), o.json);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "scene_bench: end-to-end scene recognition (segmentation + recognition) on generated "
      "cluttered tabletops with known, look-alike and unknown objects, proxseg against PCL + "
      "Open3D"};
  Options o;
  app.add_option("--models", o.models, "Folder of the LINEMOD meshes (obj_0000NN.ply, mm)")
      ->capture_default_str();
  app.add_option("-o,--output", o.output,
                 "Output folder (scenes.md, scenes.json, predictions.csv, truths.csv)")
      ->required();
  auto* dev = app.add_option("--dev-seeds", o.dev_seeds, "Seeds of the development split")
                  ->capture_default_str();
  auto* report = app.add_option("--report-seeds", o.report_seeds, "Seeds of the report split")
                     ->capture_default_str();
  auto* scenes = app.add_option("--scenes", o.scenes,
                                "One split of N scenes (seeds --first-seed..) instead of dev "
                                "and report")
                     ->check(CLI::Range(1, 100000))
                     ->excludes(dev)
                     ->excludes(report);
  app.add_option("--first-seed", o.first_seed, "First seed of --scenes")
      ->needs(scenes)
      ->capture_default_str();
  app.add_option("--views", o.views, "Database views per known object")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--threads", o.threads,
                 "Threads (0 = all cores); proxseg's answers do not depend on it (the peer's may)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_option("--config", o.config,
                 "JSON {\"segmentation\": {...}, \"recognition\": {...}} over the defaults (as "
                 "proxseg recognize --config)");
  app.add_option("--peers", o.peers, "all (PCL Euclidean + Open3D) or none")->capture_default_str();
  app.add_option("--set", o.set,
                 "lmo (the LINEMOD catalogue, dev and report seeds) or objects (the object-varied "
                 "set: object folds in halves A and B, docs/method.md)")
      ->capture_default_str();
  app.add_option("--ycbv", o.ycbv, "--set objects: the YCB-Video folder (models/, classes.txt)")
      ->capture_default_str();
  app.add_option("--textured", o.textured,
                 "--set objects: the folder of textured meshes (<name>/*.obj)")
      ->capture_default_str();
  app.add_option("--fold-scenes", o.fold_scenes,
                 "--set objects: dev and report scenes per object fold")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--fold-report-scenes", o.fold_report_scenes,
                 "--set objects: report scenes per object fold (-1 = --fold-scenes; 0 = none, "
                 "while choosing on the dev scenes)")
      ->check(CLI::Range(-1, 1000))
      ->capture_default_str();
  app.add_option("--fold-known", o.fold_known, "--set objects: known objects per fold")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--fold-unknown", o.fold_unknown, "--set objects: unknown objects per fold")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--max-folds", o.max_folds,
                 "--set objects: only the first N folds of each half (0 = all; then not every "
                 "object is unknown once)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  app.add_option("--peer-ransac", o.peer_ransac, "Open3D RANSAC iterations of the peer per view")
      ->check(CLI::Range(1000, 10000000))
      ->capture_default_str();
  app.add_flag("--json", o.json, "Print scenes.json on stdout");
  // The seed lists and --peers are checked by run(), as usage errors.
  return proxseg::bench::main_of("scene_bench", app, argc, argv, [&] { return run(o); });
}
