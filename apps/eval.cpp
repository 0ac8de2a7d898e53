// `proxseg eval-seg`: a segmentation scored against ground truth (docs/metrics.md).
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/eval/scene_names.hpp>
#include <proxseg/eval/seg_scores.hpp>
#include <proxseg/eval/seg_summary.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "cli.hpp"

namespace cli {

using proxseg::InputError;

void add_eval(CLI::App& app, EvalOptions& o) {
  auto* cmd = app.add_subcommand("eval-seg", tool_about("eval-seg"));
  cmd->add_option("truth", o.truth, "Ground-truth PCD with a label field (e.g. mOSD)");
  cmd->add_option("predicted", o.predicted,
                  "Predicted PCD of the same cloud (proxseg output or any PCD with the field)");
  cmd->add_option("--field", o.field,
                  "Predicted field to score (default: instance if present, else label)")
      ->group(group::kInput);
  cmd->add_flag("--json", o.json, "Print JSON instead of a table")->group(group::kOutput);
  cmd->add_option("--batch", o.batch,
                  "Score every labelled PCD of this folder (segmenting each unless --pred-dir)")
      ->group(group::kBatch);
  cmd->add_option("--pred-dir", o.pred_dir,
                  "With --batch: read predictions DIR/<scene>.pcd instead of segmenting")
      ->group(group::kBatch);
  cmd->add_option("-o,--output", o.output,
                  "With --batch: write scenes.csv, summary.md, summary.json to this folder")
      ->group(group::kBatch);
  cmd->add_option("--preset", o.preset, "With --batch: segmentation preset (default, paper)")
      ->check(CLI::IsMember({"default", "paper"}))
      ->group(group::kParameters);
  cmd->add_option("--config", o.config, "With --batch: JSON segmentation parameters")
      ->group(group::kParameters);
  cmd->add_option("--threads", o.threads, "Worker threads for segmenting (0 = all cores)")
      ->group(group::kResources);
  help_last(cmd);
}

namespace {

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
  std::vector<std::string> renamed;
  if (!o.config.empty()) params = proxseg::read_params(o.config, params, &renamed);
  warn_renamed(renamed);
  if (o.threads) params.threads = *o.threads;
  proxseg::validate(params);
  const auto files = proxseg::scene_files(o.batch);
  const std::string method = o.pred_dir.empty() ? "proxseg " + o.preset : "predictions";
  std::vector<proxseg::SceneScores> scenes;
  Progress progress = progress_bar(files.size());
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
  const auto rows = proxseg::summary_rows(scenes);
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
    proxseg::write_file_atomic((out / "summary.json").string(),
                               proxseg::json_text(summary, 2) + "\n");
    say() << "proxseg: wrote " << (out / "scenes.csv").string() << ", summary.md, summary.json\n";
  }
  if (o.json)
    std::cout << proxseg::json_text(summary, 2) << "\n";
  else
    std::cout << markdown;
  return interrupted() ? kInterruptedExit : 0;
}

}  // namespace

int run_eval(const EvalOptions& o) {
  no_stdin(o.truth, "TRUTH", "eval-seg reads labelled PCD files by name");
  no_stdin(o.predicted, "PREDICTED", "eval-seg reads labelled PCD files by name");
  no_stdin(o.batch, "--batch", "it is a folder of labelled PCD files");
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
    const nlohmann::json scores = {{"truth", o.truth},
                                   {"predicted", o.predicted},
                                   {"objects", proxseg::scores_json(s.objects)},
                                   {"parts", proxseg::scores_json(s.parts)}};
    std::cout << proxseg::json_text(scores, 2) << "\n";
  } else {
    print_scores(s);
  }
  return 0;
}

}  // namespace cli
