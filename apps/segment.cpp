// `proxseg segment`: one scene, or a dataset with --batch (batch.cpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/io/batch.hpp>
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
#include <thread>
#include <vector>

#include "cli.hpp"

namespace cli {

using proxseg::InputError;

void add_segment(CLI::App& app, SegmentCommand& o) {
  auto* cmd = app.add_subcommand(
      "segment", "Segment an RGB-D scene into regions and candidate objects (paper 3.1-3.3)");
  add_input_options(cmd, o, "Point cloud");
  cmd->add_option("-o,--output", o.output,
                  "Output prefix: writes PREFIX.pcd, PREFIX.png, PREFIX.json (with --batch: a "
                  "folder); - prints the JSON report on stdout and writes nothing")
      ->group(group::kOutput);
  o.outputs_flag =
      cmd->add_option("--outputs", o.outputs,
                      "What to write, comma-separated: labels (PREFIX.label.png and "
                      "PREFIX.instance.png, 16-bit), pcd (binary_compressed), png, json, html "
                      "(the 3D page, proxseg view); or all; or none (nothing written, the summary "
                      "printed)")
          ->capture_default_str()
          ->group(group::kOutput);
  cmd->add_option("--candidates-dir", o.candidates_dir,
                  "Also write one PCD per candidate object to this directory")
      ->group(group::kOutput);
  cmd->add_flag("--json", o.json,
                "Print the JSON report on stdout (without -o: it alone, no file written)")
      ->group(group::kOutput);
  add_batch_options(cmd, o);
  add_parameter_options(
      cmd, o, o.config,
      "JSON parameters over the preset (same layout as the report's \"parameters\")", false);
  help_last(cmd);
}

namespace {

// The one line on stdout without --json: what was written (or the input, when nothing was) and
// what was found.
void print_summary(const SegmentCommand& o, const SceneDestination& to,
                   const proxseg::SegmentResult& result, const nlohmann::json& report) {
  std::string written;
  if (!to.prefix.empty())
    for (const auto& f : proxseg::output_files(to.prefix, to.files, false))
      written += (written.empty() ? "" : " ") + f;
  std::cout << (written.empty() ? input_name(o) : written) << ": ";
  if (result.paper_labels)
    std::cout << result.voxels.size() << " voxels, " << result.initial_centroids.size()
              << " initial centroids, k = " << result.k() << ", ";
  else
    std::cout << counted(result.label_sizes.size() - 1, "surface") << ", ";
  std::cout << counted(report["selection"]["candidates"].get<std::size_t>(), "candidate") << ", "
            << human_ms(report["times_ms"]["total"].get<double>()) << "\n";
}

// segment --batch: the frames side by side, one thread each (as many as the threads asked for):
// a frame's stages do not keep two cores busy, reading and writing least of all. Results do not
// depend on it.
int run_segment_batch(const SegmentCommand& o, const proxseg::SegmentParams& params) {
  check_batch_output(o.output);
  if (!o.candidates_dir.empty())
    throw CLI::ValidationError("--candidates-dir goes without --batch");
  const proxseg::OutputSet outputs = outputs_option(o.outputs);
  const int workers = params.threads > 0
                          ? params.threads
                          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const proxseg::SegmentJob job{o.output, outputs, params, workers > 1 ? 1 : 0};
  return run_batch(
      o, o.output, o.json,
      {{"command", "segment"},
       {"outputs", proxseg::to_string(outputs)},
       {"parameters", proxseg::to_json(params)}},
      [&](const proxseg::FrameSource& f) { return proxseg::segment_frame(f, job); }, workers);
}

}  // namespace

int run_segment(const SegmentCommand& o) {
  check_batch_options(o);
  const SceneDestination to =
      o.batch.empty() ? scene_destination(o, o.output, o.json, true) : SceneDestination{};
  if (o.batch.empty()) check_scene_options(o, proxseg::output_files(to.prefix, to.files, false));
  no_stdin(o.candidates_dir, "--candidates-dir", "it is the folder of the candidates' PCDs");
  proxseg::SegmentParams base = proxseg::preset(o.preset);
  std::vector<std::string> renamed;
  if (!o.config.empty()) base = proxseg::read_params(o.config, base, &renamed);
  warn_renamed(renamed);
  const proxseg::SegmentParams params = segment_params(o, base);
  if (!o.batch.empty()) return run_segment_batch(o, params);
  // Before the work: an output that cannot be written fails at once.
  if (!to.prefix.empty()) make_parent(to.prefix);
  if (!o.candidates_dir.empty())
    make_parent((std::filesystem::path(o.candidates_dir) / "candidate").string());
  const proxseg::Frame frame = read_input(o);
  say() << "proxseg: " << frame.valid_count() << " valid points (" << frame.width << "x"
        << frame.height << ")\n";
  print_colourless_note(input_name(o), frame, params);
  proxseg::check_memory(frame, params, input_name(o));
  const proxseg::SegmentResult result = proxseg::segment(frame, params);
  const nlohmann::json report =
      proxseg::write_segmentation(to.prefix, frame, params, result, to.files);
  if (const auto far = report["input"]["out_of_range_points"].get<std::size_t>(); far > 0)
    std::cerr << "proxseg: warning: " << far
              << " points too far out to voxelise (coordinates beyond 1e9 voxels) are unlabelled\n";
  if (!o.candidates_dir.empty()) {
    const auto files = proxseg::write_candidates(o.candidates_dir, frame, result);
    say() << "proxseg: " << files.size() << " candidate clouds in " << o.candidates_dir << "\n";
  }
  if (to.report_to_stdout)
    std::cout << proxseg::json_text(report, 2) << "\n";
  else
    print_summary(o, to, result, report);
  return 0;
}

}  // namespace cli
