// The pieces shared by the commands of the proxseg CLI (cli.hpp).
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/version.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>

#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "cli.hpp"

namespace cli {

using proxseg::InputError;

const char* tool_about(const std::string& name) {
  for (const ToolCommand& c : kToolCommands)
    if (name == c.name) return c.about;
  return "";
}

void describe_app(CLI::App& app) {
  app.name("proxseg");
  app.description("proxseg: unsupervised RGB-D segmentation and object recognition");
  app.set_version_flag("--version", std::string("proxseg ") + proxseg::version() + " (commit " +
                                        proxseg::git_commit() + ")");
  app.require_subcommand(1);
}

namespace {
// Without allocating: there may be no memory left for a message.
void say_out_of_memory() {
  const char msg[] = "proxseg: error: out of memory\n";
  [[maybe_unused]] const ssize_t w = ::write(STDERR_FILENO, msg, sizeof msg - 1);
}
}  // namespace

int run_app(CLI::App& app, int argc, char** argv, const std::function<int()>& dispatch) {
  try {
    app.parse(argc, argv);
    return dispatch();
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help (code 0) or the usage error
    return code == 0 ? 0 : 2;
  } catch (const InputError& e) {
    std::cerr << "proxseg: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    say_out_of_memory();
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "proxseg: error: " << e.what() << "\n";
    return 1;
  }
}

int guarded_main(const std::function<int()>& main) {
  try {
    return main();
  } catch (const std::bad_alloc&) {
    say_out_of_memory();
    return 1;
  }
}

std::string input_name(const SegmentOptions& o) {
  if (!o.batch.empty()) return o.batch.front();
  return o.input.empty() ? o.color : o.input;
}

int naming_input(const std::string& input, const char* doing, const std::function<int()>& command) {
  try {
    return command();
  } catch (const InputError&) {
    throw;  // names its file already
  } catch (const CLI::Error&) {
    throw;  // a usage error
  } catch (const std::bad_alloc&) {
    // What the failed step held is freed by now: the message has room.
    throw InputError(input + ": out of memory while " + doing +
                     " (the process could not allocate more; a smaller input, fewer --threads "
                     "or more memory)");
  } catch (const std::exception& e) {  // the system refused something else (a thread, ...)
    throw InputError(input + ": " + e.what() + " (while " + doing + ")");
  }
}

void add_scene_options(CLI::App* cmd, SegmentOptions& o) {
  cmd->add_option("--color", o.color, "Colour image (PNG/JPG) of an RGB-D pair");
  cmd->add_option("--depth", o.depth, "16-bit depth PNG of an RGB-D pair");
  cmd->add_option("--intrinsics", o.intrinsics,
                  "JSON with fx, fy, cx, cy, depth_scale (units per metre)");
  cmd->add_option("--meta", o.meta, "YCB-Video meta JSON (intrinsic_matrix, factor_depth)");
  cmd->add_option("--preset", o.preset,
                  "Base parameters: default (best measured) or paper (the paper's settings)")
      ->check(CLI::IsMember({"default", "paper"}));
  cmd->add_flag("--paper-labels", o.paper_labels,
                "Compute the paper's labels (features, Algorithm 1, k-means, MRF) also where the "
                "default's image-grid selection does not need them; the flags of those stages "
                "below switch them on too");
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
                  "Worker threads (0 = all cores; segment --batch: that many frames at once, one "
                  "thread each); results do not depend on it");
  cmd->add_option("--max-memory", o.max_memory,
                  "Refuse a frame whose segmentation would need more memory than this, in MiB "
                  "(an estimate from its size, checked before it starts; a batch logs it as a "
                  "failed frame and goes on); 0 = no limit");
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
  if (o.max_memory) p.max_memory_mib = *o.max_memory;
  // A flag of stages 2-6 asks for the labels it changes.
  const bool label_flag = o.voxel_size || o.min_points || o.alpha || o.pca_dims || o.prior_weight ||
                          o.wu || o.wc || o.colour_weight || o.texture_weight || o.shape_weight ||
                          o.no_colour || o.no_texture || o.no_shape || o.no_mrf || o.mrf_method ||
                          o.mrf_cycles;
  if (o.paper_labels || label_flag) p.paper_labels = true;
  proxseg::validate(p);
  return p;
}

proxseg::Frame read_input(const SegmentOptions& o) {
  if (!o.input.empty()) return proxseg::read_point_cloud(o.input);
  const proxseg::Intrinsics k =
      o.meta.empty() ? proxseg::read_intrinsics(o.intrinsics) : proxseg::read_ycb_meta(o.meta);
  return proxseg::read_rgbd(o.color, o.depth, k);
}

void print_colourless_note(const std::string& input, const proxseg::Frame& frame,
                           const proxseg::SegmentParams& params) {
  if (const std::string off = proxseg::colourless_note(frame, params.features); !off.empty())
    std::cerr << "proxseg: " << input << " has no colour: " << off << "\n";
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

}  // namespace cli
