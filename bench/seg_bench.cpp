// Segmentation benchmark: proxseg (paper and default presets, plus variants from JSON configs) and
// the PCL peers (LCCP, colour region growing, plane + Euclidean clusters) on the same labelled
// scenes in the same run, each timed per frame; writes docs/results.md (the segmentation part) and
// a per-scene CSV. A second set of labelled scenes (the generated clutter set) can be evaluated in
// the same run: every table then has it beside mOSD learn. Whole-process wall time: the first
// --process-scenes scenes of each set through `proxseg segment` and bench/lccp_process.cpp (the
// same LCCP as a plain PCL program) as child processes, one process per frame and one per set.
// Usage: seg_bench --data DIR [--clutter DIR] [--out results.md] [--csv scenes.csv] [--scenes N]
//                  [--threads T] [--methods "proxseg default,PCL LCCP"]
//                  [--config NAME=file.json]... [--process-scenes N] [--proxseg PATH]
//                  [--lccp-process PATH]
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/eval/scene_names.hpp>
#include <proxseg/eval/seg_scores.hpp>
#include <proxseg/eval/seg_summary.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/params.hpp>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "bench_main.hpp"
#include "bench_util.hpp"
#include "peers_pcl.hpp"
#include "scene_list.hpp"
#include "seg_bench.hpp"

namespace proxseg::bench::segbench {
namespace {

using Labels = std::vector<std::uint32_t>;
using Method = std::function<Labels(const Frame&)>;
using Variants = std::vector<std::pair<std::string, SegmentParams>>;

// "a, b,c" -> {"a", "b", "c"} (spaces around the commas dropped, empty items skipped).
std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');) {
    const auto b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
    if (b != std::string::npos) out.push_back(item.substr(b, e - b + 1));
  }
  return out;
}

// The directory of this executable (/proc/self/exe; argv[0] when that is unavailable).
std::filesystem::path own_dir(const char* argv0) {
  std::error_code ec;
  std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) exe = std::filesystem::absolute(argv0, ec);
  return exe.parent_path();
}

void add_options(CLI::App& app, Options& o) {
  app.add_option("--data", o.data, "Folder of labelled mOSD scenes")->required();
  app.add_option("--clutter", o.clutter,
                 "Second folder of labelled scenes (the clutter set of `proxseg synth --clutter`), "
                 "evaluated in the same run");
  app.add_option("--out", o.out, "Markdown results file to write");
  app.add_option("--csv", o.csv, "Per-scene CSV to write");
  app.add_option("--scenes", o.limit, "Use only N scenes of each set, spread evenly (0 = all)");
  app.add_option("--threads", o.threads, "Threads for proxseg (0 = all cores)");
  app.add_option("--methods", o.methods,
                 "Comma-separated subset of the methods, e.g. \"proxseg default,PCL LCCP\" "
                 "(default: all; --config variants always run)");
  app.add_option("--config", o.configs,
                 "NAME=file.json: a proxseg variant \"proxseg NAME\", the file read on top of "
                 "preset default (repeatable)");
  app.add_option("--process-scenes", o.process_scenes,
                 "Whole-process wall time on the first N scenes of each set (0 = skip)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--proxseg", o.proxseg_cli, "The proxseg CLI for the whole-process times")
      ->capture_default_str();
  app.add_option("--lccp-process", o.lccp_process,
                 "bench/lccp_process for the whole-process times (PCL LCCP as its own program)")
      ->capture_default_str();
}

// The result files are written at the end: a missing folder is reported before the run (an
// error), and so is a tool of the whole-process times that is not there (a usage error).
void check_paths(const Options& o) {
  for (const std::string& path : {o.out, o.csv}) {
    if (path.empty()) continue;
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir))
      throw InputError(path + ": cannot write (directory " + dir.string() + " does not exist)");
  }
  if (o.process_scenes > 0)
    for (const std::string& tool : {o.proxseg_cli, o.lccp_process})
      if (access(tool.c_str(), X_OK) != 0)
        throw CLI::ValidationError(tool + ": not an executable (build the targets proxseg_cli " +
                                   "and lccp_process, give --proxseg / --lccp-process, or " +
                                   "--process-scenes 0)");
}

// proxseg's variants: short name -> parameters, in report order: the presets paper and default,
// then each --config NAME=file.json (a usage error when malformed or unreadable).
Variants read_variants(const Options& o, Measured& m) {
  Variants variants = {{"paper", preset("paper")}, {"default", preset("default")}};
  try {
    for (const auto& c : o.configs) {
      const auto eq = c.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == c.size())
        throw InputError("--config " + c + ": expected NAME=file.json");
      const std::string name = c.substr(0, eq), path = c.substr(eq + 1);
      for (const auto& v : variants)
        if (v.first == name) throw InputError("--config " + c + ": the name " + name + " is taken");
      variants.emplace_back(name, read_params(path, preset("default")));
      m.config_files.emplace_back(name, path);
    }
    for (auto& [name, p] : variants) {
      p.threads = o.threads;
      validate(p);
    }
  } catch (const InputError& e) {
    throw CLI::ValidationError(e.what());
  }
  return variants;
}

// Table 1 scores the paper's labels: a variant that skips them (the default on organized frames)
// is run again with them. All of it is untimed, the rerun's result freed and the scoring
// included: neither is the method's work on the frame.
void add_table1(const Frame& f, const std::string& name, const SegmentParams& params,
                const SegmentResult& r, Stages& st) {
  const auto untimed = Clock::now();
  {
    const SegmentResult* raw = &r;
    SegmentResult labelled;
    if (!r.paper_labels) {
      SegmentParams with = params;
      with.paper_labels = true;
      labelled = segment(f, with);
      raw = &labelled;
    }
    const auto truth = truth_objects(f);
    const auto km = score_segmentation(truth, raw->point_labels_kmeans, {1});
    const auto mrf = score_segmentation(truth, raw->point_labels, {1});
    for (const auto& [row, s] :
         {std::pair{name + " k-means", &km}, std::pair{name + " k-means+MRF", &mrf}}) {
      Table1& t = st.table1[st.current_set][row];
      t.precision += s->paper_precision;
      t.recall += s->paper_recall;
      t.v += s->v.v;
      ++t.scenes;
    }
  }
  st.untimed_seconds += seconds_since(untimed);
}

// proxseg variant `name` on a frame: its labels; its stage times and Table 1 scores into `st`.
Labels run_variant(const Frame& f, const std::string& name, const SegmentParams& params,
                   Stages& st) {
  const SegmentResult r = segment(f, params);
  for (const auto& [stage, ms] : r.times_ms) {
    st.ms[name][stage] += ms;
    if (std::find(st.order.begin(), st.order.end(), stage) == st.order.end())
      st.order.push_back(stage);
  }
  for (const auto& [stage, ms] : r.concurrent_ms) {
    const std::string row = stage + " (second thread, beside Algorithm 1 .. point labels)";
    st.ms[name][row] += ms;
    if (std::find(st.concurrent.begin(), st.concurrent.end(), row) == st.concurrent.end())
      st.concurrent.push_back(row);
  }
  st.ms[name][kTotal] += r.total_ms;
  ++st.frames[name];
  add_table1(f, name, params, r, st);
  return r.selection.instance;
}

// Every method: proxseg's variants, then the PCL peers.
std::vector<std::pair<std::string, Method>> all_methods(const Variants& variants, Stages& st) {
  std::vector<std::pair<std::string, Method>> all;
  for (const auto& [name, params] : variants)
    all.emplace_back("proxseg " + name, [&st, name = name, &params = params](const Frame& f) {
      return run_variant(f, name, params, st);
    });
  all.emplace_back("PCL LCCP", [](const Frame& f) { return peers::lccp(f); });
  all.emplace_back("PCL region growing RGB",
                   [](const Frame& f) { return peers::region_growing_rgb(f); });
  all.emplace_back("PCL plane + Euclidean", [](const Frame& f) { return peers::euclidean(f); });
  return all;
}

// --methods: the named ones (and every --config variant), in the report's order; an unknown name
// is a usage error.
std::vector<std::pair<std::string, Method>> select_methods(
    const Options& o, const std::vector<std::pair<std::string, Method>>& all, const Measured& m) {
  if (o.methods.empty()) return all;
  const std::vector<std::string> wanted = split_list(o.methods);
  for (const auto& w : wanted)
    if (std::none_of(all.begin(), all.end(), [&](const auto& x) { return x.first == w; })) {
      std::string known;
      for (const auto& x : all) known += " \"" + x.first + "\"";
      throw CLI::ValidationError("--methods: unknown method \"" + w + "\"; known:" + known);
    }
  std::vector<std::pair<std::string, Method>> methods;
  for (const auto& x : all)
    if (std::find(wanted.begin(), wanted.end(), x.first) != wanted.end() ||
        std::any_of(m.config_files.begin(), m.config_files.end(),
                    [&](const auto& c) { return "proxseg " + c.first == x.first; }))
      methods.push_back(x);
  return methods;
}

// Every method on every labelled scene of every set, timed per frame (the untimed Table 1 work
// taken off), after one untimed run of every method: first-call costs (page faults, lazy init)
// are not the method's per-frame cost.
void run_scenes(const std::vector<std::pair<std::string, Method>>& methods, Measured& m) {
  const Frame warm = read_pcd(m.sets.front().files.front().string());
  for (auto& [name, run] : methods) run(warm);
  m.stages.ms.clear();
  m.stages.frames.clear();
  m.stages.table1.clear();
  std::size_t total_files = 0, step = 0;
  for (const auto& set : m.sets) total_files += set.files.size();
  for (auto& set : m.sets) {
    m.stages.current_set = set.name;
    m.scores_of_set[set.name];
    for (const auto& file : set.files) {
      const std::string at = "[" + std::to_string(++step) + "/" + std::to_string(total_files) +
                             "] " + set.name + ": " + file.filename().string();
      const Frame frame = read_pcd(file.string());
      if (frame.label.empty()) {
        std::cerr << at << " (no label field, skipped)\n";
        continue;
      }
      for (auto& [name, run] : methods) {
        const auto start = Clock::now();
        m.stages.untimed_seconds = 0;
        const Labels labels = run(frame);
        const double seconds = seconds_since(start) - m.stages.untimed_seconds;
        SceneScores sc = score_scene(frame, labels);
        sc.seconds = seconds;
        sc.scene = file.filename().string();
        // A generated scene's kind is its file name's prefix (clutter, piles, occlusion); every
        // other scene of the second set counts as clutter.
        sc.category = scene_category(sc.scene);
        if (set.name == "generated" && sc.category == "other") sc.category = "clutter";
        sc.method = name;
        m.scores.push_back(sc);
        m.scores_of_set[set.name].push_back(sc);
      }
      ++set.done;
      std::cerr << at << "\n";
    }
  }
}

}  // namespace

int run(const Options& o) {
  check_paths(o);
  Measured m;
  const Variants variants = read_variants(o, m);
  const auto methods = select_methods(o, all_methods(variants, m.stages), m);
  for (const auto& x : methods) m.methods.push_back(x.first);
  for (const auto& [name, p] : variants)
    if (std::find(m.methods.begin(), m.methods.end(), "proxseg " + name) != m.methods.end())
      m.run_variants.push_back(name);
  m.sets.push_back({"mOSD learn", scenes_of(o.data, o.limit), 0, o.data});
  if (!o.clutter.empty())
    m.sets.push_back({"generated", scenes_of(o.clutter, o.limit), 0, o.clutter});
  run_scenes(methods, m);
  m.processes = measure_processes(o, m.sets);
  const std::string md = report_markdown(o, m);
  std::cout << md;
  if (!o.out.empty()) write_file_atomic(o.out, md);
  if (!o.csv.empty()) write_file_atomic(o.csv, scenes_csv(m.scores));
  return 0;
}

}  // namespace proxseg::bench::segbench

int main(int argc, char** argv) {
  CLI::App app{"proxseg segmentation benchmark against PCL's segmenters"};
  proxseg::bench::segbench::Options o;
  const std::filesystem::path dir = proxseg::bench::segbench::own_dir(argv[0]);
  o.proxseg_cli = (dir.parent_path() / "proxseg").string();
  o.lccp_process = (dir / "lccp_process").string();
  proxseg::bench::segbench::add_options(app, o);
  return proxseg::bench::main_of("seg_bench", app, argc, argv,
                                 [&] { return proxseg::bench::segbench::run(o); });
}
