// proxseg command-line tool: proxseg <command> [options]. Logs on stderr, results on stdout or
// files. Exit codes: 0 success, 1 bad input, 2 usage.
#include <proxseg/io.hpp>
#include <proxseg/output.hpp>
#include <proxseg/params.hpp>
#include <proxseg/pipeline.hpp>
#include <proxseg/render.hpp>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <optional>

namespace {

using proxseg::InputError;

struct SegmentOptions {
  std::string input, output, color, depth, intrinsics, meta, config;
  bool no_mrf = false, json = false;
  std::optional<std::string> mrf_method;
  std::optional<double> voxel_size, alpha, prior_weight, wu, wc, colour_weight, texture_weight,
      shape_weight;
  std::optional<int> min_points, pca_dims, threads;
  bool no_colour = false, no_texture = false, no_shape = false;
};

void add_segment(CLI::App& app, SegmentOptions& o) {
  auto* cmd =
      app.add_subcommand("segment", "Segment an RGB-D scene into labelled regions (paper 3.1-3.2)");
  cmd->add_option("input", o.input,
                  "Point cloud (.pcd organized or not, .ply); or use --color/--depth");
  cmd->add_option("-o,--output", o.output,
                  "Output prefix: writes PREFIX.pcd, PREFIX.png, PREFIX.json")
      ->required();
  cmd->add_option("--color", o.color, "Colour image (PNG/JPG) of an RGB-D pair");
  cmd->add_option("--depth", o.depth, "16-bit depth PNG of an RGB-D pair");
  cmd->add_option("--intrinsics", o.intrinsics,
                  "JSON with fx, fy, cx, cy, depth_scale (units per metre)");
  cmd->add_option("--meta", o.meta, "YCB-Video meta JSON (intrinsic_matrix, factor_depth)");
  cmd->add_option("--config", o.config,
                  "JSON parameters (same layout as the report's \"parameters\")");
  cmd->add_flag("--no-mrf", o.no_mrf, "Stop after k-means (no MRF refinement)");
  cmd->add_option("--mrf-method", o.mrf_method, "MRF moves: swap (paper) or expansion")
      ->check(CLI::IsMember({"swap", "expansion"}));
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
  cmd->add_option("--threads", o.threads,
                  "Worker threads (0 = all cores); results do not depend on it");
  cmd->add_flag("--json", o.json, "Print the JSON report on stdout");
}

// Defaults < --config < individual flags.
proxseg::SegmentParams segment_params(const SegmentOptions& o) {
  proxseg::SegmentParams p;
  if (!o.config.empty()) p = proxseg::read_params(o.config, p);
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

int run_segment(const SegmentOptions& o) {
  const bool rgbd = !o.color.empty() || !o.depth.empty();
  if (o.input.empty() == !rgbd)
    throw CLI::ValidationError("give either INPUT or --color and --depth");
  if (rgbd && (o.color.empty() || o.depth.empty()))
    throw CLI::ValidationError("--color and --depth go together");
  if (rgbd && o.intrinsics.empty() == o.meta.empty())
    throw CLI::ValidationError("an RGB-D pair needs exactly one of --intrinsics or --meta");
  for (const std::string& in : {o.input, o.color, o.depth})
    for (const char* ext : {".pcd", ".png", ".json"})
      if (!in.empty() && std::filesystem::exists(in) && std::filesystem::exists(o.output + ext) &&
          std::filesystem::equivalent(in, o.output + ext))
        throw CLI::ValidationError("--output " + o.output + " would overwrite the input " + in);
  const proxseg::SegmentParams params = segment_params(o);
  const proxseg::Frame frame = read_input(o);
  std::cerr << "proxseg: " << frame.valid_count() << " valid points (" << frame.width << "x"
            << frame.height << ")\n";
  const proxseg::SegmentResult result = proxseg::segment(frame, params);
  make_parent(o.output);
  const nlohmann::json report = proxseg::write_segmentation(o.output, frame, params, result);
  if (o.json) {
    std::cout << report.dump(2) << "\n";
  } else {
    std::cout << o.output << ".pcd " << o.output << ".png " << o.output
              << ".json: " << result.voxels.size() << " voxels, " << result.initial_centroids.size()
              << " initial centroids, k = " << result.k() << ", "
              << report["times_ms"]["total"].get<double>() << " ms\n";
  }
  return 0;
}

struct SynthOptions {
  std::string output;
  unsigned seed = 1;
  double noise = proxseg::SynthParams{}.depth_noise;
};

int run_synth(const SynthOptions& o) {
  if (!(o.noise >= 0 && o.noise < 1)) throw InputError("--noise: expected metres in [0, 1)");
  const proxseg::Frame frame = proxseg::synth_scene({o.seed, o.noise});
  make_parent(o.output);
  proxseg::write_pcd(o.output, frame, {{"label", frame.label}});
  std::cout << o.output << ": synthetic scene " << frame.width << "x" << frame.height << ", "
            << frame.valid_count() << " valid points, ground truth in field 'label'\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"proxseg: unsupervised RGB-D segmentation and object recognition"};
  app.require_subcommand(1);
  SegmentOptions segment;
  add_segment(app, segment);
  SynthOptions synth;
  auto* synth_cmd = app.add_subcommand(
      "synth", "Write the built-in synthetic tabletop scene (with ground truth)");
  synth_cmd->add_option("-o,--output", synth.output, "Output PCD path")->required();
  synth_cmd->add_option("--seed", synth.seed, "Seed of the depth noise");
  synth_cmd->add_option("--noise", synth.noise, "Depth noise std at 1 m, metres");
  try {
    app.parse(argc, argv);
    if (app.got_subcommand("segment")) return run_segment(segment);
    if (app.got_subcommand("synth")) return run_synth(synth);
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
