// `proxseg segment`: one scene, or a folder of scenes with --batch.
#include <proxseg/core/pipeline.hpp>
#include <proxseg/eval/evaluation.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "cli.hpp"

namespace cli {

using proxseg::InputError;

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

namespace {

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

}  // namespace

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
  print_colourless_note(o.input, frame, params);
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

}  // namespace cli
