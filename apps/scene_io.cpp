// Where the scene of `segment` and `recognize` comes from and where its results go: INPUT, or -
// for standard input (PCD or PLY by content), or an RGB-D pair; -o PREFIX for files, or -o - for
// the JSON report on stdout; --outputs and --json (cli.hpp, docs/cli.md).
#include <proxseg/core/errors.hpp>
#include <proxseg/core/parameters.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "cli.hpp"

namespace cli {

std::string cloud_name(const std::string& path) {
  return path == "-" ? proxseg::kStdinName : path;
}

std::string input_name(const SegmentOptions& o) {
  if (!o.batch.empty()) return o.batch.front();
  return o.input.empty() ? o.colour : cloud_name(o.input);
}

void add_input_options(CLI::App* cmd, SegmentOptions& o, const std::string& input_help) {
  cmd->add_option("input", o.input,
                  input_help +
                      " (.pcd organized or not, .ply), or - for standard input (PCD or PLY, told "
                      "apart by content); or an RGB-D pair: --colour and --depth")
      ->group(group::kInput);
  cmd->add_option("--colour", o.colour, "Colour image (PNG/JPG) of an RGB-D pair")
      ->group(group::kInput);
  cmd->add_option("--color", o.colour)->group("");  // the other spelling
  cmd->add_option("--depth", o.depth, "16-bit depth PNG of an RGB-D pair")->group(group::kInput);
  cmd->add_option("--intrinsics", o.intrinsics,
                  "JSON with fx, fy, cx, cy, depth_scale (units per metre)")
      ->group(group::kInput);
  cmd->add_option("--meta", o.meta, "YCB-Video meta JSON (intrinsic_matrix, factor_depth)")
      ->group(group::kInput);
}

void add_parameter_options(CLI::App* cmd, SegmentOptions& o, std::string& config,
                           const std::string& config_help, bool recognition) {
  cmd->add_option("--preset", o.preset,
                  "Base parameters: default (best measured) or paper (the paper's settings)")
      ->check(CLI::IsMember({"default", "paper"}))
      ->capture_default_str()
      ->group(group::kParameters);
  cmd->add_option("--config", config, config_help)->group(group::kParameters);
  add_parameter_flags(cmd, o.params, recognition);
}

// Preset < --config < the parameter flags.
proxseg::SegmentParams segment_params(const SegmentOptions& o, proxseg::SegmentParams p) {
  apply_parameter_flags(o.params, p, nullptr);
  proxseg::validate(p);
  return p;
}

proxseg::Frame read_cloud(const std::string& path) {
  return path == "-" ? proxseg::read_point_cloud_stdin() : proxseg::read_point_cloud(path);
}

proxseg::Frame read_input(const SegmentOptions& o) {
  if (!o.input.empty()) return read_cloud(o.input);
  const proxseg::Intrinsics k =
      o.meta.empty() ? proxseg::read_intrinsics(o.intrinsics) : proxseg::read_ycb_meta(o.meta);
  return proxseg::read_rgbd(o.colour, o.depth, k);
}

void no_stdin(const std::string& value, const std::string& flag, const std::string& what) {
  if (value == "-")
    throw CLI::ValidationError(flag + " takes a file here, not - (standard input): " + what);
}

void check_scene_options(const SegmentOptions& o, const std::vector<std::string>& outputs) {
  const bool rgbd = !o.colour.empty() || !o.depth.empty();
  if (o.input.empty() == !rgbd)
    throw CLI::ValidationError("give either INPUT or --colour and --depth");
  if (rgbd && (o.colour.empty() || o.depth.empty()))
    throw CLI::ValidationError("--colour and --depth go together");
  if (rgbd && o.intrinsics.empty() == o.meta.empty())
    throw CLI::ValidationError("an RGB-D pair needs exactly one of --intrinsics or --meta");
  const std::string one_cloud = "- is for one cloud, INPUT";
  no_stdin(o.colour, "--colour", "an RGB-D pair is two image files; " + one_cloud);
  no_stdin(o.depth, "--depth", "an RGB-D pair is two image files; " + one_cloud);
  no_stdin(o.intrinsics, "--intrinsics", one_cloud);
  no_stdin(o.meta, "--meta", one_cloud);
  for (const std::string& in : {o.input, o.colour, o.depth})
    for (const std::string& out : outputs)
      if (!in.empty() && std::filesystem::exists(in) && std::filesystem::exists(out) &&
          std::filesystem::equivalent(in, out))
        throw CLI::ValidationError("--output would overwrite the input " + in);
}

namespace {

// The kinds of outputs that are files of their own (all but json), as --outputs names them.
std::string file_kinds(const proxseg::OutputSet& s) {
  proxseg::OutputSet files = s;
  files.json = false;
  return proxseg::to_string(files);
}

bool writes_nothing(const proxseg::OutputSet& s) {
  return !s.labels && !s.pcd && !s.png && !s.json && !s.html;
}

}  // namespace

SceneDestination scene_destination(const SegmentOptions& o, const std::string& output, bool json,
                                   bool prefix_required) {
  const bool given = o.outputs_flag && o.outputs_flag->count() > 0;
  const proxseg::OutputSet asked = outputs_option(o.outputs);
  const std::string files = given ? file_kinds(asked) : "";
  SceneDestination d;
  if (output == "-") {
    if (given && !files.empty() && files != "none")
      throw CLI::ValidationError(
          "-o - writes only the JSON report, to stdout: --outputs " + files +
          " are files and need a prefix (-o PREFIX), or give --outputs json");
    if (given && !asked.json)
      throw CLI::ValidationError(
          "-o - writes the JSON report to stdout, which --outputs none leaves out: give "
          "--outputs json, or no -o");
    d.report_to_stdout = true;
    return d;
  }
  if (output.empty()) {
    if (given && !files.empty() && files != "none")
      throw CLI::ValidationError("--outputs " + files +
                                 ": files need a prefix (-o PREFIX); without one only the JSON "
                                 "report is printed (--json, or -o -)");
    d.report_to_stdout = json;
    if (!json && !(given && writes_nothing(asked)) && prefix_required)
      throw CLI::ValidationError(
          "--output is required: -o PREFIX for the files, -o - (or --json) for the JSON report "
          "on stdout alone, or --outputs none to write nothing");
    return d;
  }
  d.prefix = writes_nothing(asked) ? "" : output;  // --outputs none: not even its folder
  d.files = asked;
  d.report_to_stdout = json;
  return d;
}

}  // namespace cli
