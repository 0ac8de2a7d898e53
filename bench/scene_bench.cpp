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
#include <proxseg/eval/scene_eval.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "bench_main.hpp"
#include "bench_util.hpp"
#include "peers_rec.hpp"
#include "progress.hpp"  // apps/progress.hpp: the CLI's progress bar
#include "scene_bench.hpp"

namespace proxseg::bench::scenebench {

void add_options(CLI::App& app, Options& o) {
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
  add_ranged(app, "--views", o.views, "Database views per known object", 1, 64);
  add_ranged(app, "--threads", o.threads,
             "Threads (0 = all cores); proxseg's answers do not depend on it (the peer's may)", 0,
             1024);
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
  add_ranged(app, "--fold-scenes", o.fold_scenes,
             "--set objects: dev and report scenes per object fold", 1, 1000);
  add_ranged(app, "--fold-report-scenes", o.fold_report_scenes,
             "--set objects: report scenes per object fold (-1 = --fold-scenes; 0 = none, "
             "while choosing on the dev scenes)",
             -1, 1000);
  add_ranged(app, "--fold-known", o.fold_known, "--set objects: known objects per fold", 1, 1000);
  add_ranged(app, "--fold-unknown", o.fold_unknown, "--set objects: unknown objects per fold", 1,
             1000);
  add_ranged(app, "--max-folds", o.max_folds,
             "--set objects: only the first N folds of each half (0 = all; then not every "
             "object is unknown once)",
             0, 1000);
  add_ranged(app, "--peer-ransac", o.peer_ransac, "Open3D RANSAC iterations of the peer per view",
             1000, 10000000);
  app.add_flag("--json", o.json, "Print scenes.json on stdout");
}

namespace {

// The parameters (--config over the defaults; --peers checked, as a usage error) and threads.
void setup(const Options& o, Bench& b) {
  if (o.peers != "all" && o.peers != "none")
    throw CLI::ValidationError("--peers: expected all or none, got '" + o.peers + "'");
  if (!o.config.empty()) std::tie(b.sp, b.rp) = read_recognize_params(o.config, b.sp, b.rp);
  b.sp.threads = b.rp.threads = o.threads;
  validate(b.sp);
  // The curves move min_score and keep the rest of the naming rule (rp).
  validate(b.rp);
  if (o.threads > 0) omp_set_num_threads(o.threads);
  b.team = o.threads > 0 ? o.threads : omp_get_max_threads();
}

// The scene sets with their databases, the splits and their groups.
void make_sets(const Options& o, Bench& b) {
  const auto t0 = Clock::now();
  make_splits(o, DescriptorParams{}, b.sets, b.splits);
  std::size_t views_total = 0;
  for (const SceneSet& set : b.sets) views_total += set.db.views.size();
  std::cerr << "scene_bench: " << b.sets.size() << " database" << (b.sets.size() > 1 ? "s" : "")
            << " of " << views_total / b.sets.size() << " views on average (" << o.views
            << " per known object) in " << fixed(seconds_since(t0), 1) << " s\n";
  for (const Split& s : b.splits)
    if (std::find(b.groups.begin(), b.groups.end(), s.group) == b.groups.end())
      b.groups.push_back(s.group);
}

// proxseg, and with --peers all the peer pipeline (one Open3D peer per database, made when first
// needed).
void make_methods(const Options& o, Bench& b) {
  b.methods.push_back({"proxseg", [&b](const Frame& f, const SceneSet& set) {
                         const SegmentResult s = segment(f, b.sp);
                         return predictions_of(recognize_scene(f, s.selection, set.db, b.rp));
                       }});
  // rec_bench gives Open3D 100k iterations (its 4M default costs 2.5x, no gain); against 96
  // views for each of ~12 clusters that is ~100 s per scene here, so the scenes default to 10k.
  b.o3d.ransac_iterations = o.peer_ransac;
  b.peer_label =
      "PCL Euclidean + Open3D RANSAC " + std::to_string(o.peer_ransac / 1000) + "k + ICP";
  if (o.peers != "all") return;
  auto open3d = std::make_shared<std::map<const SceneSet*, std::unique_ptr<peers::Open3dPeer>>>();
  b.methods.push_back({b.peer_label, [&b, &o, open3d](const Frame& f, const SceneSet& set) {
                         auto& peer = (*open3d)[&set];
                         if (!peer)
                           peer = std::make_unique<peers::Open3dPeer>(set.db, b.o3d, o.threads);
                         return peer_scene(f, set.db, *peer, b.rp, b.team);
                       }});
}

// Each truth object of a scene with what the method made of it.
void add_truths(std::uint32_t seed, const std::vector<TruthObject>& truth,
                const std::vector<Prediction>& predictions, const SceneEvaluation& e, Result& r) {
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
}

// Method m on one scene, its evaluation added to r; returns the step's text for the progress bar.
std::string run_scene(const Method& m, std::uint32_t seed, const ClutterScene& scene,
                      const std::vector<TruthObject>& truth, const SceneSet& set, Result& r) {
  const auto start = Clock::now();
  const std::vector<Prediction> predictions = m.run(scene.frame, set);
  const double sec = seconds_since(start);
  SceneEvaluation e = evaluate_scene(seed, truth, predictions, set.catalogue);
  e.counts.seconds = sec;
  r.counts += e.counts;
  for (std::size_t j = 0; j < e.rows.size(); ++j) {
    r.rows.push_back(e.rows[j]);
    r.points.push_back(static_cast<int>(predictions[j].points.size()));
  }
  add_truths(seed, truth, predictions, e, r);
  return m.label + ": " + std::to_string(e.counts.tp) + "/" + std::to_string(e.counts.known) +
         " known named right, " + std::to_string(e.counts.fp) + " FP, " + fixed(sec, 1) + " s";
}

// The runs: every scene is generated once and given to every method.
void run_splits(Bench& b) {
  b.results.assign(b.splits.size(), std::vector<Result>(b.methods.size()));
  std::size_t steps = 0;
  for (const Split& s : b.splits) steps += s.seeds.size() * b.methods.size();
  cli::Progress progress(steps);
  for (std::size_t si = 0; si < b.splits.size(); ++si) {
    const SceneSet& set = b.sets[b.splits[si].set];
    for (std::uint32_t seed : b.splits[si].seeds) {
      const ClutterScene scene =
          clutter_layout_scene(scene_set_params(seed, set.catalogue, b.set_params));
      const std::vector<TruthObject> truth = scene_truth(scene, set.catalogue);
      for (std::size_t mi = 0; mi < b.methods.size(); ++mi)
        progress.step(b.splits[si].name + " seed " + std::to_string(seed) + ", " +
                      run_scene(b.methods[mi], seed, scene, truth, set, b.results[si][mi]));
    }
  }
}

// The splits' results summed per group: the tables' rows.
void group_results(Bench& b) {
  b.grouped.assign(b.groups.size(), std::vector<Result>(b.methods.size()));
  for (std::size_t si = 0; si < b.splits.size(); ++si) {
    const std::size_t gi =
        std::find(b.groups.begin(), b.groups.end(), b.splits[si].group) - b.groups.begin();
    for (std::size_t mi = 0; mi < b.methods.size(); ++mi) {
      Result& g = b.grouped[gi][mi];
      const Result& r = b.results[si][mi];
      g.counts += r.counts;
      g.rows.insert(g.rows.end(), r.rows.begin(), r.rows.end());
      g.truths.insert(g.truths.end(), r.truths.begin(), r.truths.end());
      g.points.insert(g.points.end(), r.points.begin(), r.points.end());
    }
  }
}

}  // namespace

int run(const Options& o) {
  Bench b;
  setup(o, b);
  const std::filesystem::path out = output_folder(o.output);
  make_sets(o, b);
  make_methods(o, b);
  b.load_before = load_average();
  run_splits(b);
  group_results(b);
  b.load_after = load_average();
  const nlohmann::json summary = report_json(o, b);
  const std::string md = report_markdown(o, b);
  return finish(out,
                {{"scenes.md", md},
                 {"scenes.json", summary.dump(2) + "\n"},
                 {"predictions.csv", predictions_csv(b)},
                 {"truths.csv", truths_csv(b)}},
                summary, md, o.json);
}

}  // namespace proxseg::bench::scenebench

int main(int argc, char** argv) {
  CLI::App app{
      "scene_bench: end-to-end scene recognition (segmentation + recognition) on generated "
      "cluttered tabletops with known, look-alike and unknown objects, proxseg against PCL + "
      "Open3D"};
  proxseg::bench::scenebench::Options o;
  proxseg::bench::scenebench::add_options(app, o);
  // The seed lists and --peers are checked by run(), as usage errors.
  return proxseg::bench::main_of("scene_bench", app, argc, argv,
                                 [&] { return proxseg::bench::scenebench::run(o); });
}
