// proxseg command-line tool: proxseg <command> [options]. Logs on stderr, results on stdout or
// files. Exit codes: 0 success, 1 bad input, 2 usage.
#include <proxseg/clutter.hpp>
#include <proxseg/evaluation.hpp>
#include <proxseg/io.hpp>
#include <proxseg/memory.hpp>
#include <proxseg/output.hpp>
#include <proxseg/params.hpp>
#include <proxseg/pipeline.hpp>
#include <proxseg/render.hpp>
#include <proxseg/version.hpp>

#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <fstream>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include "cli.hpp"

namespace cli {

using proxseg::InputError;

void add_scene_options(CLI::App* cmd, SegmentOptions& o) {
  cmd->add_option("--color", o.color, "Colour image (PNG/JPG) of an RGB-D pair");
  cmd->add_option("--depth", o.depth, "16-bit depth PNG of an RGB-D pair");
  cmd->add_option("--intrinsics", o.intrinsics,
                  "JSON with fx, fy, cx, cy, depth_scale (units per metre)");
  cmd->add_option("--meta", o.meta, "YCB-Video meta JSON (intrinsic_matrix, factor_depth)");
  cmd->add_option("--preset", o.preset,
                  "Base parameters: default (best measured) or paper (the paper's settings)")
      ->check(CLI::IsMember({"default", "paper"}));
  cmd->add_flag("--no-mrf", o.no_mrf, "Stop after k-means (no MRF refinement)");
  cmd->add_option("--mrf-method", o.mrf_method, "MRF moves: swap (paper) or expansion")
      ->check(CLI::IsMember({"swap", "expansion"}));
  cmd->add_option("--mrf-cycles", o.mrf_cycles,
                  "Most MRF sweeps over the labels (default 2; paper: until nothing changes)");
  cmd->add_option("--voxel-size", o.voxel_size, "Voxel side in metres (paper: 0.02)");
  cmd->add_option("--min-points", o.min_points, "Voxels with fewer points are not clustered");
  cmd->add_option("--alpha", o.alpha, "Chi-square confidence of Algorithm 1 (paper: 0.85)");
  cmd->add_option("--pca-dims", o.pca_dims, "Principal axes kept for clustering");
  cmd->add_option("--prior-weight", o.prior_weight, "Shrinkage of centroid covariances (voxels)");
  cmd->add_option("--wu", o.wu, "MRF unary weight w_u (paper: 1.0)");
  cmd->add_option("--wc", o.wc, "MRF Potts weight w_c (paper: 0.275)");
  cmd->add_option("--colour-weight", o.colour_weight, "Weight of the colour block");
  cmd->add_option("--texture-weight", o.texture_weight, "Weight of the texture block");
  cmd->add_option("--shape-weight", o.shape_weight, "Weight of the shape block");
  cmd->add_flag("--no-colour", o.no_colour, "Switch the colour block off");
  cmd->add_flag("--no-texture", o.no_texture, "Switch the texture block off");
  cmd->add_flag("--no-shape", o.no_shape, "Switch the shape block off");
  cmd->add_option("--cluster-tolerance", o.cluster_tolerance,
                  "Euclidean clustering tolerance of the selection, metres");
  cmd->add_option("--min-candidate-points", o.min_candidate_points,
                  "Smaller components are not candidates");
  cmd->add_option("--threads", o.threads,
                  "Worker threads (0 = all cores); results do not depend on it");
}

// Preset < --config < individual flags.
proxseg::SegmentParams segment_params(const SegmentOptions& o, proxseg::SegmentParams p) {
  if (o.voxel_size) p.voxels.voxel_size = *o.voxel_size;
  if (o.min_points) p.voxels.min_points_per_voxel = *o.min_points;
  if (o.alpha) p.clustering.alpha = *o.alpha;
  if (o.pca_dims) p.clustering.pca_dims = *o.pca_dims;
  if (o.prior_weight) p.clustering.prior_weight = *o.prior_weight;
  if (o.wu) p.mrf.unary_weight = *o.wu;
  if (o.wc) p.mrf.pairwise_weight = *o.wc;
  if (o.colour_weight) p.features.colour_weight = *o.colour_weight;
  if (o.texture_weight) p.features.texture_weight = *o.texture_weight;
  if (o.shape_weight) p.features.shape_weight = *o.shape_weight;
  if (o.no_colour) p.features.use_colour = false;
  if (o.no_texture) p.features.use_texture = false;
  if (o.no_shape) p.features.use_shape = false;
  if (o.no_mrf) p.mrf.enabled = false;
  if (o.mrf_method)
    p.mrf.method =
        *o.mrf_method == "swap" ? proxseg::MrfMethod::kSwap : proxseg::MrfMethod::kExpansion;
  if (o.mrf_cycles) p.mrf.max_cycles = *o.mrf_cycles;
  if (o.cluster_tolerance) p.selection.cluster_tolerance = *o.cluster_tolerance;
  if (o.min_candidate_points) p.selection.min_candidate_points = *o.min_candidate_points;
  if (o.threads) p.threads = *o.threads;
  proxseg::validate(p);
  return p;
}

proxseg::Frame read_input(const SegmentOptions& o) {
  if (!o.input.empty()) return proxseg::read_point_cloud(o.input);
  const proxseg::Intrinsics k =
      o.meta.empty() ? proxseg::read_intrinsics(o.intrinsics) : proxseg::read_ycb_meta(o.meta);
  return proxseg::read_rgbd(o.color, o.depth, k);
}

void make_parent(const std::string& path) {
  const auto parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  if (ec)
    throw InputError(parent.string() + ": cannot create output directory (" + ec.message() + ")");
}

void check_scene_options(const SegmentOptions& o, const std::vector<std::string>& outputs) {
  const bool rgbd = !o.color.empty() || !o.depth.empty();
  if (o.input.empty() == !rgbd)
    throw CLI::ValidationError("give either INPUT or --color and --depth");
  if (rgbd && (o.color.empty() || o.depth.empty()))
    throw CLI::ValidationError("--color and --depth go together");
  if (rgbd && o.intrinsics.empty() == o.meta.empty())
    throw CLI::ValidationError("an RGB-D pair needs exactly one of --intrinsics or --meta");
  for (const std::string& in : {o.input, o.color, o.depth})
    for (const std::string& out : outputs)
      if (!in.empty() && std::filesystem::exists(in) && std::filesystem::exists(out) &&
          std::filesystem::equivalent(in, out))
        throw CLI::ValidationError("--output would overwrite the input " + in);
}

namespace {
// The one piece of process state a signal handler may touch (async-signal-safe).
volatile std::sig_atomic_t interrupt_signal = 0;

extern "C" void on_interrupt(int sig) {
  interrupt_signal = sig;
  std::signal(sig, SIG_DFL);  // a second interrupt ends the process at once
  const char msg[] =
      "\nproxseg: interrupted: finishing the current item (interrupt again to abort)\n";
  [[maybe_unused]] const ssize_t w = ::write(STDERR_FILENO, msg, sizeof msg - 1);
}
}  // namespace

void catch_interrupts() {
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
}

bool interrupted() {
  return interrupt_signal != 0;
}

double rss_mib() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  if (!(statm >> pages >> resident)) return 0;
  return static_cast<double>(resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1 << 20);
}

double peak_rss_mib() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;  // KiB on Linux
}

}  // namespace cli

namespace {

using proxseg::InputError;
using namespace cli;

struct SegmentCommand : SegmentOptions {
  std::string output, config, candidates_dir, batch;
  bool json = false;
};

void add_segment(CLI::App& app, SegmentCommand& o) {
  auto* cmd = app.add_subcommand(
      "segment", "Segment an RGB-D scene into regions and candidate objects (paper 3.1-3.3)");
  cmd->add_option("input", o.input,
                  "Point cloud (.pcd organized or not, .ply); or use --color/--depth");
  cmd->add_option("-o,--output", o.output,
                  "Output prefix: writes PREFIX.pcd, PREFIX.png, PREFIX.json (with --batch: a "
                  "folder of SCENE.pcd/.png/.json and summary.json)")
      ->required();
  cmd->add_option("--batch", o.batch,
                  "Segment every .pcd and .ply of this folder (an interrupt stops after the "
                  "current scene and writes the summary)");
  cmd->add_option("--config", o.config,
                  "JSON parameters over the preset (same layout as the report's \"parameters\")");
  cmd->add_option("--candidates-dir", o.candidates_dir,
                  "Also write one PCD per candidate object to this directory");
  add_scene_options(cmd, o);
  cmd->add_flag("--json", o.json, "Print the JSON report on stdout");
}

// One scene of a batch: its outputs, or the error that stopped it.
nlohmann::json segment_one(const std::filesystem::path& file, const std::string& prefix,
                           const proxseg::SegmentParams& params) {
  nlohmann::json row = {{"scene", file.filename().string()}};
  try {
    const auto start = std::chrono::steady_clock::now();
    const proxseg::Frame frame = proxseg::read_point_cloud(file.string());
    const proxseg::SegmentResult result = proxseg::segment(frame, params);
    const nlohmann::json report = proxseg::write_segmentation(prefix, frame, params, result);
    row["outputs"] = {prefix + ".pcd", prefix + ".png", prefix + ".json"};
    row["k"] = result.k();
    row["candidates"] = report["selection"]["candidates"];
    row["ms"] =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  } catch (const InputError& e) {
    row["error"] = e.what();
  }
  // Memory after each scene: a batch must not grow (docs/robustness.md).
  row["rss_mib"] = rss_mib();
  return row;
}

// `segment --batch DIR -o OUT`: OUT/<scene>.{pcd,png,json} per scene and OUT/summary.json. A scene
// that cannot be read is reported and skipped; an interrupt stops between scenes.
int run_segment_batch(const SegmentCommand& o, const proxseg::SegmentParams& params) {
  const auto files = proxseg::scene_files(o.batch, {".pcd", ".ply"});
  const std::filesystem::path out(o.output);
  make_parent((out / "summary.json").string());
  std::set<std::string> stems;
  for (const auto& f : files) {
    if (std::filesystem::equivalent(f.parent_path(), out))
      throw CLI::ValidationError("--output must not be the input folder (it would overwrite " +
                                 f.filename().string() + ")");
    if (!stems.insert(f.stem().string()).second)
      throw InputError(o.batch + ": two scenes named " + f.stem().string() +
                       " (expected one file per name: their outputs would overwrite each other)");
  }
  catch_interrupts();
  nlohmann::json scenes = nlohmann::json::array();
  Progress progress(files.size());
  std::size_t failed = 0;
  for (const auto& f : files) {
    if (interrupted()) break;
    scenes.push_back(segment_one(f, (out / f.stem()).string(), params));
    failed += scenes.back().contains("error");
    progress.step(f.filename().string() + (scenes.back().contains("error") ? " (failed)" : ""));
  }
  const nlohmann::json summary = {{"folder", o.batch},
                                  {"scenes_total", files.size()},
                                  {"scenes_done", scenes.size() - failed},
                                  {"scenes_failed", failed},
                                  {"interrupted", interrupted()},
                                  {"peak_rss_mib", peak_rss_mib()},
                                  {"scenes", scenes},
                                  {"proxseg", proxseg::build_info()},
                                  {"parameters", proxseg::to_json(params)}};
  proxseg::write_file_atomic((out / "summary.json").string(), summary.dump(2) + "\n");
  if (o.json)
    std::cout << summary.dump(2) << "\n";
  else
    std::cout << (out / "summary.json").string() << ": " << scenes.size() - failed << " of "
              << files.size() << " scenes segmented"
              << (failed ? ", " + std::to_string(failed) + " failed" : "")
              << (interrupted() ? " (interrupted)" : "") << "\n";
  for (const auto& row : scenes)
    if (row.contains("error"))
      std::cerr << "proxseg: error: " << row["error"].get<std::string>() << "\n";
  if (interrupted()) return kInterruptedExit;
  return failed ? 1 : 0;
}

int run_segment(const SegmentCommand& o) {
  if (o.batch.empty()) {
    check_scene_options(o, {o.output + ".pcd", o.output + ".png", o.output + ".json"});
  } else {
    if (!o.input.empty() || !o.color.empty() || !o.depth.empty())
      throw CLI::ValidationError("--batch takes a folder instead of INPUT or --color/--depth");
    if (!o.candidates_dir.empty())
      throw CLI::ValidationError("--candidates-dir goes without --batch");
  }
  proxseg::SegmentParams base = proxseg::preset(o.preset);
  if (!o.config.empty()) base = proxseg::read_params(o.config, base);
  const proxseg::SegmentParams params = segment_params(o, base);
  if (!o.batch.empty()) return run_segment_batch(o, params);
  make_parent(o.output);  // before the work: an unwritable output fails at once
  const proxseg::Frame frame = read_input(o);
  std::cerr << "proxseg: " << frame.valid_count() << " valid points (" << frame.width << "x"
            << frame.height << ")\n";
  const proxseg::SegmentResult result = proxseg::segment(frame, params);
  const nlohmann::json report = proxseg::write_segmentation(o.output, frame, params, result);
  if (const auto far = report["input"]["out_of_range_points"].get<std::size_t>(); far > 0)
    std::cerr << "proxseg: warning: " << far
              << " points too far out to voxelise (coordinates beyond 1e9 voxels) are unlabelled\n";
  if (!o.candidates_dir.empty()) {
    const auto files = proxseg::write_candidates(o.candidates_dir, frame, result);
    std::cerr << "proxseg: " << files.size() << " candidate clouds in " << o.candidates_dir << "\n";
  }
  if (o.json) {
    std::cout << report.dump(2) << "\n";
  } else {
    std::cout << o.output << ".pcd " << o.output << ".png " << o.output
              << ".json: " << result.voxels.size() << " voxels, " << result.initial_centroids.size()
              << " initial centroids, k = " << result.k() << ", "
              << report["selection"]["candidates"].get<int>() << " candidates, "
              << report["times_ms"]["total"].get<double>() << " ms\n";
  }
  return 0;
}

struct SynthOptions {
  std::string output;
  unsigned seed = 1;
  double noise = proxseg::SynthParams{}.depth_noise;
  bool clutter = false;  // --clutter: proxseg::clutter_scene (docs/clutter.md)
  unsigned count = 0, first_seed = 1;
  std::string models;
};

// `synth --clutter`: one scene (-o FILE) or --count scenes (-o DIR/clutter-SSS.pcd).
int run_clutter(const SynthOptions& o) {
  proxseg::ClutterParams p;
  p.depth_noise = o.noise;
  p.models_dir = o.models;
  const std::string lmo = "../shared/data/lmo/models";
  if (p.models_dir.empty() && std::filesystem::is_directory(lmo)) p.models_dir = lmo;
  if (p.models_dir.empty())
    std::cerr << "proxseg: note: no LINEMOD meshes at " << lmo
              << " (give --models DIR); boxes and cylinders only\n";
  if (o.count == 0) {
    p.seed = o.seed;
    const proxseg::ClutterScene scene = proxseg::clutter_layout_scene(p);
    make_parent(o.output);
    proxseg::write_pcd(o.output, scene.frame, {{"label", scene.frame.label}});
    std::cout << o.output << ": clutter scene seed " << o.seed << ", "
              << proxseg::clutter_summary(scene) << ", ground truth in field 'label'\n";
    return 0;
  }
  if (o.first_seed + static_cast<std::uint64_t>(o.count) - 1 > 0xffffffffull)
    throw InputError("--first-seed, --count: the seeds must stay below 2^32");
  const std::filesystem::path dir(o.output);
  make_parent((dir / "clutter-000.pcd").string());
  catch_interrupts();
  Progress progress(o.count);
  const auto start = std::chrono::steady_clock::now();
  std::size_t objects = 0;
  unsigned done = 0;
  for (; done < o.count && !interrupted(); ++done) {
    p.seed = o.first_seed + done;
    char name[32];
    std::snprintf(name, sizeof name, "clutter-%03u.pcd", p.seed);
    const proxseg::ClutterScene scene = proxseg::clutter_layout_scene(p);
    proxseg::write_pcd((dir / name).string(), scene.frame, {{"label", scene.frame.label}});
    objects += scene.objects.size();
    progress.step(std::string(name) + ": " + proxseg::clutter_summary(scene));
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << o.output << ": " << done << " clutter scenes (seeds " << o.first_seed << "-"
            << o.first_seed + (done > 0 ? done - 1 : 0) << "), " << objects << " objects, " << s
            << " s" << (interrupted() ? " (interrupted)" : "") << "\n";
  return interrupted() ? kInterruptedExit : 0;
}

int run_synth(const SynthOptions& o) {
  if (!(o.noise >= 0 && o.noise < 1)) throw InputError("--noise: expected metres in [0, 1)");
  if (o.clutter) return run_clutter(o);
  const proxseg::Frame frame = proxseg::synth_scene({o.seed, o.noise});
  make_parent(o.output);
  proxseg::write_pcd(o.output, frame, {{"label", frame.label}});
  std::cout << o.output << ": synthetic scene " << frame.width << "x" << frame.height << ", "
            << frame.valid_count() << " valid points, ground truth in field 'label'\n";
  return 0;
}

struct EvalOptions {
  std::string truth, predicted, field, batch, pred_dir, output, config;
  std::string preset = "default";
  std::optional<int> threads;
  bool json = false;
};

void add_eval(CLI::App& app, EvalOptions& o) {
  auto* cmd = app.add_subcommand(
      "eval-seg", "Score a segmentation against ground truth (docs/metrics.md), or a whole folder");
  cmd->add_option("truth", o.truth, "Ground-truth PCD with a label field (e.g. mOSD)");
  cmd->add_option("predicted", o.predicted,
                  "Predicted PCD of the same cloud (proxseg output or any PCD with the field)");
  cmd->add_option("--field", o.field,
                  "Predicted field to score (default: instance if present, else label)");
  cmd->add_option("--batch", o.batch,
                  "Score every labelled PCD of this folder (segmenting each unless --pred-dir)");
  cmd->add_option("--pred-dir", o.pred_dir,
                  "With --batch: read predictions DIR/<scene>.pcd instead of segmenting");
  cmd->add_option("-o,--output", o.output,
                  "With --batch: write scenes.csv, summary.md, summary.json to this folder");
  cmd->add_option("--preset", o.preset, "With --batch: segmentation preset (default, paper)")
      ->check(CLI::IsMember({"default", "paper"}));
  cmd->add_option("--config", o.config, "With --batch: JSON segmentation parameters");
  cmd->add_option("--threads", o.threads, "Worker threads for segmenting (0 = all cores)");
  cmd->add_flag("--json", o.json, "Print JSON instead of a table");
}

// The predicted labels of a PCD: the requested field, or instance, else label.
std::vector<std::uint32_t> read_prediction(const std::string& path, const std::string& field,
                                           std::size_t expected) {
  std::vector<std::uint32_t> labels;
  for (const std::string& f : field.empty() ? std::vector<std::string>{"instance", "label"}
                                            : std::vector<std::string>{field}) {
    labels = proxseg::read_pcd(path, f).label;
    if (!labels.empty()) break;
  }
  if (labels.empty())
    throw InputError(path + ": has no " + (field.empty() ? "instance or label" : field) +
                     " field (expected per-point predicted labels)");
  if (labels.size() != expected)
    throw InputError(path + ": has " + std::to_string(labels.size()) +
                     " points but the ground truth has " + std::to_string(expected) +
                     " (expected the same cloud)");
  return labels;
}

void print_scores(const proxseg::SceneScores& s) {
  std::cout << "scheme   P(paper) R(paper)  V      hom    compl  WOv    objP   objR   objF   "
               "F>=.75 over under lost unassigned objects segments\n";
  for (const auto& [name, x] : {std::pair{"objects", &s.objects}, std::pair{"parts", &s.parts}}) {
    char line[256];
    std::snprintf(line, sizeof line,
                  "%-8s %-8.3f %-9.3f %-6.3f %-6.3f %-6.3f %-6.3f %-6.3f %-6.3f %-6.3f %-6.3f "
                  "%-4d %-5d %-4d %-10d %-7d %d\n",
                  name, x->paper_precision, x->paper_recall, x->v.v, x->v.homogeneity,
                  x->v.completeness, x->weighted_overlap, x->object_precision, x->object_recall,
                  x->object_f, x->detected_075, x->over_segmented, x->under_segmented,
                  x->lost_in_background, x->unassigned_objects, x->truth_objects, x->segments);
    std::cout << line;
  }
}

int run_eval_batch(const EvalOptions& o) {
  proxseg::SegmentParams params = proxseg::preset(o.preset);
  if (!o.config.empty()) params = proxseg::read_params(o.config, params);
  if (o.threads) params.threads = *o.threads;
  proxseg::validate(params);
  const auto files = proxseg::scene_files(o.batch);
  const std::string method = o.pred_dir.empty() ? "proxseg " + o.preset : "predictions";
  std::vector<proxseg::SceneScores> scenes;
  Progress progress(files.size());
  std::size_t unlabelled = 0;
  catch_interrupts();
  for (const auto& file : files) {
    if (interrupted()) break;
    const proxseg::Frame truth = proxseg::read_pcd(file.string());
    if (truth.label.empty()) {
      ++unlabelled;
      progress.step(file.filename().string() + " (no label field, skipped)");
      continue;
    }
    std::vector<std::uint32_t> predicted;
    double seconds = 0;
    if (o.pred_dir.empty()) {
      const auto start = std::chrono::steady_clock::now();
      predicted = proxseg::segment(truth, params).selection.instance;
      seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    } else {
      predicted = read_prediction((std::filesystem::path(o.pred_dir) / file.filename()).string(),
                                  o.field, truth.size());
    }
    proxseg::SceneScores s = proxseg::score_scene(truth, predicted);
    s.scene = file.filename().string();
    s.category = proxseg::scene_category(s.scene);
    s.method = method;
    s.seconds = seconds;
    scenes.push_back(s);
    progress.step(s.scene);
  }
  if (scenes.empty()) throw InputError(o.batch + ": no scene has a label field");
  const auto rows = proxseg::summarize(scenes);
  nlohmann::json summary = {{"folder", o.batch},
                            {"method", method},
                            {"scenes", scenes.size()},
                            {"skipped_unlabelled", unlabelled},
                            {"scenes_total", files.size()},
                            {"interrupted", interrupted()},
                            {"summary", proxseg::summary_json(rows)},
                            {"proxseg", proxseg::build_info()}};
  if (o.pred_dir.empty()) summary["parameters"] = proxseg::to_json(params);
  const std::string markdown = proxseg::summary_markdown(rows);
  if (!o.output.empty()) {
    make_parent((std::filesystem::path(o.output) / "x").string());
    const auto out = std::filesystem::path(o.output);
    proxseg::write_file_atomic((out / "scenes.csv").string(), proxseg::scenes_csv(scenes));
    proxseg::write_file_atomic((out / "summary.md").string(), markdown);
    proxseg::write_file_atomic((out / "summary.json").string(), summary.dump(2) + "\n");
    std::cerr << "proxseg: wrote " << (out / "scenes.csv").string()
              << ", summary.md, summary.json\n";
  }
  if (o.json)
    std::cout << summary.dump(2) << "\n";
  else
    std::cout << markdown;
  return interrupted() ? kInterruptedExit : 0;
}

int run_eval(const EvalOptions& o) {
  if (!o.batch.empty()) {
    if (!o.truth.empty() || !o.predicted.empty())
      throw CLI::ValidationError("--batch takes a folder instead of TRUTH and PREDICTED");
    return run_eval_batch(o);
  }
  if (o.truth.empty() || o.predicted.empty())
    throw CLI::ValidationError("give TRUTH and PREDICTED, or --batch DIR");
  if (!o.pred_dir.empty() || !o.output.empty() || !o.config.empty())
    throw CLI::ValidationError("--pred-dir, --output and --config go with --batch");
  const proxseg::Frame truth = proxseg::read_pcd(o.truth);
  if (truth.label.empty())
    throw InputError(o.truth + ": has no label field (expected ground-truth labels)");
  const auto predicted = read_prediction(o.predicted, o.field, truth.size());
  proxseg::SceneScores s = proxseg::score_scene(truth, predicted);
  if (o.json) {
    std::cout << nlohmann::json{{"truth", o.truth},
                                {"predicted", o.predicted},
                                {"objects", proxseg::scores_json(s.objects)},
                                {"parts", proxseg::scores_json(s.parts)}}
                     .dump(2)
              << "\n";
  } else {
    print_scores(s);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  proxseg::keep_freed_memory();  // batch commands reuse each frame's buffers
  CLI::App app{"proxseg: unsupervised RGB-D segmentation and object recognition"};
  app.set_version_flag("--version", std::string("proxseg ") + proxseg::version() + " (commit " +
                                        proxseg::git_commit() + ")");
  app.require_subcommand(1);
  SegmentCommand segment;
  add_segment(app, segment);
  DbOptions db;
  add_db(app, db);
  RecognizeOptions recognize;
  add_recognize(app, recognize);
  EvalOptions eval;
  add_eval(app, eval);
  SynthOptions synth;
  auto* synth_cmd = app.add_subcommand(
      "synth", "Write the built-in synthetic tabletop scene (with ground truth)");
  synth_cmd->add_option("-o,--output", synth.output, "Output PCD path (--count: a folder)")
      ->required();
  synth_cmd->add_option("--seed", synth.seed, "Seed of the depth noise (--clutter: of the scene)");
  synth_cmd->add_option("--noise", synth.noise, "Depth noise std at 1 m, metres");
  auto* clutter_flag = synth_cmd->add_flag(
      "--clutter", synth.clutter,
      "A seeded cluttered tabletop instead (5-15 LINEMOD meshes, boxes, cylinders; standing, "
      "lying, touching, stacked, leaning; docs/clutter.md); --seed then seeds the whole scene");
  auto* count_opt =
      synth_cmd
          ->add_option("--count", synth.count,
                       "With --clutter: write N scenes, seeds --first-seed.., to the folder "
                       "-o as clutter-SSS.pcd")
          ->check(CLI::Range(1u, 1000000u))
          ->needs(clutter_flag);
  synth_cmd->add_option("--first-seed", synth.first_seed, "With --count: the first seed (1)")
      ->needs(count_opt);
  synth_cmd
      ->add_option("--models", synth.models,
                   "With --clutter: folder of LINEMOD obj_*.ply meshes in mm (default "
                   "../shared/data/lmo/models if present, else boxes and cylinders only)")
      ->needs(clutter_flag);
  count_opt->excludes(synth_cmd->get_option("--seed"));
  try {
    app.parse(argc, argv);
    if (app.got_subcommand("segment")) return run_segment(segment);
    if (app.got_subcommand("synth")) return run_synth(synth);
    if (app.got_subcommand("eval-seg")) return run_eval(eval);
    if (app.got_subcommand("db")) return run_db(db);
    if (app.got_subcommand("recognize")) return run_recognize(recognize);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help (code 0) or the usage error
    return code == 0 ? 0 : 2;
  } catch (const InputError& e) {
    std::cerr << "proxseg: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "proxseg: error: " << e.what() << "\n";
    return 1;
  }
  return 2;
}
