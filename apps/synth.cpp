// `proxseg synth`: the built-in synthetic scene, or generated cluttered tabletops (--clutter);
// -o - writes the scene's PCD to stdout.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/eval/clutter.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <CLI/CLI.hpp>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <string>

#include "cli.hpp"

namespace cli {

using proxseg::InputError;

namespace {
constexpr const char* kScene = "Scene";
constexpr const char* kClutter = "Clutter";

// A scene's PCD (with its ground truth in field `label`) to path, or to stdout for -; its summary
// line goes to stdout, or to stderr when stdout holds the cloud.
void write_scene(const std::string& path, const proxseg::Frame& frame, const std::string& about) {
  if (path == "-") {
    std::cout << proxseg::pcd_bytes(frame, {{"label", frame.label}}) << std::flush;
    say() << "<stdout>: " << about << "\n";
    return;
  }
  make_parent(path);
  proxseg::write_pcd(path, frame, {{"label", frame.label}});
  std::cout << path << ": " << about << "\n";
}
}  // namespace

void add_synth(CLI::App& app, SynthOptions& o) {
  auto* cmd = app.add_subcommand("synth", tool_about("synth"));
  cmd->add_option("-o,--output", o.output,
                  "Output PCD path (--count: a folder); - writes the PCD to stdout")
      ->required()
      ->group(group::kOutput);
  cmd->add_option("--seed", o.seed, "Seed of the depth noise (--clutter: of the scene)")
      ->group(kScene);
  cmd->add_option("--noise", o.noise, "Depth noise std at 1 m, metres")->group(kScene);
  auto* clutter_flag =
      cmd->add_flag("--clutter", o.clutter,
                    "A seeded cluttered tabletop instead (5-15 LINEMOD meshes, boxes, cylinders; "
                    "standing, lying, touching, stacked, leaning; docs/clutter.md); --seed then "
                    "seeds the whole scene")
          ->group(kClutter);
  auto* count_opt =
      cmd->add_option("--count", o.count,
                      "With --clutter: write N scenes, seeds --first-seed.., to the folder "
                      "-o as clutter-SSS.pcd")
          ->check(CLI::Range(1u, 1000000u))
          ->needs(clutter_flag)
          ->group(kClutter);
  cmd->add_option("--first-seed", o.first_seed, "With --count: the first seed (1)")
      ->needs(count_opt)
      ->group(kClutter);
  cmd->add_option("--kind", o.kind,
                  "With --clutter: clutter (default), piles (boxes face to face and stacked) or "
                  "occlusion (a low camera over a dense layout); --count names files KIND-SSS.pcd")
      ->check(CLI::IsMember({"clutter", "piles", "occlusion"}))
      ->needs(clutter_flag)
      ->group(kClutter);
  cmd->add_option("--models", o.models,
                  "With --clutter: folder of LINEMOD obj_*.ply meshes in mm (default "
                  "../shared/data/lmo/models if present, else boxes and cylinders only)")
      ->needs(clutter_flag)
      ->group(kClutter);
  count_opt->excludes(cmd->get_option("--seed"));
  help_last(cmd);
}

namespace {

// `synth --clutter`: one scene (-o FILE) or --count scenes (-o DIR/clutter-SSS.pcd).
int run_clutter(const SynthOptions& o) {
  proxseg::ClutterParams p = proxseg::clutter_kind(o.kind);
  p.depth_noise = o.noise;
  p.models_dir = o.models;
  const std::string lmo = "../shared/data/lmo/models";
  if (p.models_dir.empty() && std::filesystem::is_directory(lmo)) p.models_dir = lmo;
  if (p.models_dir.empty())
    say() << "proxseg: note: no LINEMOD meshes at " << lmo
          << " (give --models DIR); boxes and cylinders only\n";
  if (o.count == 0) {
    p.seed = o.seed;
    const proxseg::ClutterScene scene = proxseg::clutter_layout_scene(p);
    write_scene(o.output, scene.frame,
                o.kind + " scene seed " + std::to_string(o.seed) + ", " +
                    proxseg::clutter_summary(scene) + ", ground truth in field 'label'");
    return 0;
  }
  if (o.output == "-")
    throw CLI::ValidationError("--count writes a folder of scenes: -o DIR, not - (stdout)");
  if (o.first_seed + static_cast<std::uint64_t>(o.count) - 1 > 0xffffffffull)
    throw InputError("--first-seed, --count: the seeds must stay below 2^32");
  const std::filesystem::path dir(o.output);
  make_parent((dir / (o.kind + "-000.pcd")).string());
  catch_interrupts();
  Progress progress = progress_bar(o.count);
  const auto start = std::chrono::steady_clock::now();
  std::size_t objects = 0;
  unsigned done = 0;
  for (; done < o.count && !interrupted(); ++done) {
    p.seed = o.first_seed + done;
    char number[16];
    std::snprintf(number, sizeof number, "-%03u.pcd", p.seed);
    const std::string name = o.kind + number;
    const proxseg::ClutterScene scene = proxseg::clutter_layout_scene(p);
    proxseg::write_pcd((dir / name).string(), scene.frame, {{"label", scene.frame.label}});
    objects += scene.objects.size();
    progress.step(name + ": " + proxseg::clutter_summary(scene));
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << o.output << ": " << done << " " << o.kind << " scenes (seeds " << o.first_seed << "-"
            << o.first_seed + (done > 0 ? done - 1 : 0) << "), " << counted(objects, "object")
            << ", " << human_time(s) << (interrupted() ? " (interrupted)" : "") << "\n";
  return interrupted() ? kInterruptedExit : 0;
}

}  // namespace

int run_synth(const SynthOptions& o) {
  if (!(o.noise >= 0 && o.noise < 1)) throw InputError("--noise: expected metres in [0, 1)");
  if (o.clutter) return run_clutter(o);
  const proxseg::Frame frame = proxseg::synth_scene({o.seed, o.noise});
  write_scene(o.output, frame,
              "synthetic scene " + std::to_string(frame.width) + "x" +
                  std::to_string(frame.height) + ", " + std::to_string(frame.valid_count()) +
                  " valid points, ground truth in field 'label'");
  return 0;
}

}  // namespace cli
