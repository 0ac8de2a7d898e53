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
#include "bench_util.hpp"
#include "peers_pcl.hpp"

#include <proxseg/core/pipeline.hpp>
#include <proxseg/eval/scene_names.hpp>
#include <proxseg/eval/seg_scores.hpp>
#include <proxseg/eval/seg_summary.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/memory.hpp>
#include <proxseg/io/params.hpp>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace {

using proxseg::Frame;
using Labels = std::vector<std::uint32_t>;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string fmt(double v, int digits = 3) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// Table 1 of the paper: the paper's precision / recall and V-measure of the raw labels, before and
// after the MRF, per preset (sums over scenes).
struct Table1 {
  double precision = 0, recall = 0, v = 0;
  int scenes = 0;
};

// Every scene of the folder, or N of them spread evenly so every category is represented.
std::vector<std::filesystem::path> scenes_of(const std::string& dir, int limit) {
  std::vector<std::filesystem::path> files = proxseg::scene_files(dir);
  if (limit > 0 && static_cast<int>(files.size()) > limit) {
    std::vector<std::filesystem::path> spread;
    for (int i = 0; i < limit; ++i) spread.push_back(files[i * files.size() / limit]);
    files = spread;
  }
  return files;
}

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

struct SceneSet {
  std::string name;  // "mOSD learn", "generated"
  std::vector<std::filesystem::path> files;
  int done = 0;     // labelled scenes evaluated
  std::string dir;  // the folder
};

// Seconds a process took: wall from spawn to exit, CPU = user + sys (its own and its threads').
struct ProcessCost {
  double wall = 0, cpu = 0;
  ProcessCost& operator+=(const ProcessCost& o) {
    wall += o.wall, cpu += o.cpu;
    return *this;
  }
};

// Runs args[0] with args (no shell), stdin, stdout and stderr on /dev/null, and waits for it
// (wait4, for its CPU time). std::runtime_error if it cannot start or exits other than with
// `expected_exit`.
ProcessCost run_process(const std::vector<std::string>& args, int expected_exit = 0) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int err = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) throw std::runtime_error(args[0] + ": cannot start (" + std::strerror(err) + ")");
  int status = 0;
  struct rusage usage {};
  while (wait4(pid, &status, 0, &usage) < 0)
    if (errno != EINTR) throw std::runtime_error(args[0] + ": wait4: " + std::strerror(errno));
  auto secs = [](const timeval& t) { return t.tv_sec + t.tv_usec * 1e-6; };
  const ProcessCost cost{seconds_since(start), secs(usage.ru_utime) + secs(usage.ru_stime)};
  if (!WIFEXITED(status) || WEXITSTATUS(status) != expected_exit) {
    std::string cmd;
    for (const auto& a : args) cmd += (cmd.empty() ? "" : " ") + a;
    throw std::runtime_error(
        cmd + (WIFEXITED(status) ? ": exit status " + std::to_string(WEXITSTATUS(status))
                                 : ": killed by signal " + std::to_string(WTERMSIG(status))));
  }
  return cost;
}

// A fresh directory under the system's temporary directory, removed with everything in it.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    std::string t = (std::filesystem::temp_directory_path() / "seg_bench-XXXXXX").string();
    if (!mkdtemp(t.data())) throw std::runtime_error(t + ": " + std::strerror(errno));
    path = t;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

// Whole-process seconds per frame of one set and mode, for proxseg and lccp_process.
struct ProcessTimes {
  std::string set, mode;
  int frames = 0;
  ProcessCost proxseg, lccp;  // sums over the frames
};

// The directory of this executable (/proc/self/exe; argv[0] when that is unavailable).
std::filesystem::path own_dir(const char* argv0) {
  std::error_code ec;
  std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) exe = std::filesystem::absolute(argv0, ec);
  return exe.parent_path();
}

}  // namespace

int main(int argc, char** argv) {
  // The same allocator settings for every method of this process (proxseg's CLI sets them too).
  proxseg::keep_freed_memory();
  CLI::App app{"proxseg segmentation benchmark against PCL's segmenters"};
  std::string data, clutter, out, csv, methods_arg;
  std::vector<std::string> configs;
  int limit = 0, threads = 0, process_scenes = 10;
  std::string proxseg_cli = (own_dir(argv[0]).parent_path() / "proxseg").string();
  std::string lccp_process = (own_dir(argv[0]) / "lccp_process").string();
  app.add_option("--data", data, "Folder of labelled mOSD scenes")->required();
  app.add_option("--clutter", clutter,
                 "Second folder of labelled scenes (the clutter set of `proxseg synth --clutter`), "
                 "evaluated in the same run");
  app.add_option("--out", out, "Markdown results file to write");
  app.add_option("--csv", csv, "Per-scene CSV to write");
  app.add_option("--scenes", limit, "Use only N scenes of each set, spread evenly (0 = all)");
  app.add_option("--threads", threads, "Threads for proxseg (0 = all cores)");
  app.add_option("--methods", methods_arg,
                 "Comma-separated subset of the methods, e.g. \"proxseg default,PCL LCCP\" "
                 "(default: all; --config variants always run)");
  app.add_option("--config", configs,
                 "NAME=file.json: a proxseg variant \"proxseg NAME\", the file read on top of "
                 "preset default (repeatable)");
  app.add_option("--process-scenes", process_scenes,
                 "Whole-process wall time on the first N scenes of each set (0 = skip)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--proxseg", proxseg_cli, "The proxseg CLI for the whole-process times")
      ->capture_default_str();
  app.add_option("--lccp-process", lccp_process,
                 "bench/lccp_process for the whole-process times (PCL LCCP as its own program)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  // The result files are written at the end: a missing folder is reported before the run.
  for (const std::string& path : {out, csv}) {
    if (path.empty()) continue;
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir)) {
      std::cerr << "seg_bench: " << path << ": cannot write (directory " << dir.string()
                << " does not exist)\n";
      return 1;
    }
  }
  if (process_scenes > 0)
    for (const std::string& tool : {proxseg_cli, lccp_process})
      if (access(tool.c_str(), X_OK) != 0) {
        std::cerr << "seg_bench: " << tool << ": not an executable (build the targets proxseg_cli "
                  << "and lccp_process, give --proxseg / --lccp-process, or --process-scenes 0)\n";
        return 2;
      }

  // proxseg variants: short name -> parameters, in report order.
  std::vector<std::pair<std::string, proxseg::SegmentParams>> variants = {
      {"paper", proxseg::preset("paper")}, {"default", proxseg::preset("default")}};
  std::vector<std::pair<std::string, std::string>> config_files;  // name, path
  std::vector<std::string> config_names;
  try {
    for (const auto& c : configs) {
      const auto eq = c.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == c.size())
        throw proxseg::InputError("--config " + c + ": expected NAME=file.json");
      const std::string name = c.substr(0, eq), path = c.substr(eq + 1);
      for (const auto& v : variants)
        if (v.first == name)
          throw proxseg::InputError("--config " + c + ": the name " + name + " is taken");
      variants.emplace_back(name, proxseg::read_params(path, proxseg::preset("default")));
      config_files.emplace_back(name, path);
      config_names.push_back("proxseg " + name);
    }
    for (auto& [name, p] : variants) {
      p.threads = threads;
      proxseg::validate(p);
    }
  } catch (const proxseg::InputError& e) {
    std::cerr << "seg_bench: " << e.what() << "\n";
    return 2;
  }

  std::map<std::string, std::map<std::string, double>> stage_ms;  // variant -> stage -> sum
  std::map<std::string, int> stage_frames;                        // variant -> frames timed
  std::vector<std::string> stages;                                // in pipeline order
  std::vector<std::string> concurrent;  // stages on a second thread, not in the sequence
  const std::string kTotal = "total (segment() wall time)";
  // set -> "variant k-means" / "variant k-means+MRF" -> sums
  std::map<std::string, std::map<std::string, Table1>> table1;
  std::string current_set;
  // Time a method spent on work outside its own answer (the Table 1 rerun below), taken off its
  // time per frame.
  double untimed_seconds = 0;

  using Method = std::function<Labels(const Frame&)>;
  std::vector<std::pair<std::string, Method>> all_methods;
  for (std::size_t vi = 0; vi < variants.size(); ++vi) {
    const std::string name = variants[vi].first;
    all_methods.emplace_back("proxseg " + name, [&, vi, name](const Frame& f) {
      const proxseg::SegmentResult r = proxseg::segment(f, variants[vi].second);
      for (const auto& [stage, ms] : r.times_ms) {
        stage_ms[name][stage] += ms;
        if (std::find(stages.begin(), stages.end(), stage) == stages.end()) stages.push_back(stage);
      }
      for (const auto& [stage, ms] : r.concurrent_ms) {
        const std::string row = stage + " (second thread, beside Algorithm 1 .. point labels)";
        stage_ms[name][row] += ms;
        if (std::find(concurrent.begin(), concurrent.end(), row) == concurrent.end())
          concurrent.push_back(row);
      }
      stage_ms[name][kTotal] += r.total_ms;
      ++stage_frames[name];
      // Table 1 scores the paper's labels: a variant that skips them (the default on organized
      // frames) is run again with them. All of it is untimed, the rerun's result freed and the
      // scoring included: neither is the method's work on the frame.
      const auto untimed = std::chrono::steady_clock::now();
      {
        const proxseg::SegmentResult* raw = &r;
        proxseg::SegmentResult labelled;
        if (!r.paper_labels) {
          proxseg::SegmentParams with = variants[vi].second;
          with.paper_labels = true;
          labelled = proxseg::segment(f, with);
          raw = &labelled;
        }
        const auto truth = proxseg::truth_objects(f);
        const auto km = proxseg::score_segmentation(truth, raw->point_labels_kmeans, {1});
        const auto mrf = proxseg::score_segmentation(truth, raw->point_labels, {1});
        for (const auto& [row, s] :
             {std::pair{name + " k-means", &km}, std::pair{name + " k-means+MRF", &mrf}}) {
          Table1& t = table1[current_set][row];
          t.precision += s->paper_precision;
          t.recall += s->paper_recall;
          t.v += s->v.v;
          ++t.scenes;
        }
      }
      untimed_seconds += seconds_since(untimed);
      return r.selection.instance;
    });
  }
  all_methods.emplace_back("PCL LCCP", [](const Frame& f) { return proxseg::peers::lccp(f); });
  all_methods.emplace_back("PCL region growing RGB",
                           [](const Frame& f) { return proxseg::peers::region_growing_rgb(f); });
  all_methods.emplace_back("PCL plane + Euclidean",
                           [](const Frame& f) { return proxseg::peers::euclidean(f); });

  // --methods: the named ones (and every --config variant), in the report's order.
  std::vector<std::pair<std::string, Method>> methods;
  if (methods_arg.empty()) {
    methods = all_methods;
  } else {
    const std::vector<std::string> wanted = split_list(methods_arg);
    for (const auto& w : wanted)
      if (std::none_of(all_methods.begin(), all_methods.end(),
                       [&](const auto& m) { return m.first == w; })) {
        std::cerr << "seg_bench: --methods: unknown method \"" << w << "\"; known:";
        for (const auto& m : all_methods) std::cerr << " \"" << m.first << "\"";
        std::cerr << "\n";
        return 2;
      }
    for (const auto& m : all_methods)
      if (std::find(wanted.begin(), wanted.end(), m.first) != wanted.end() ||
          std::find(config_names.begin(), config_names.end(), m.first) != config_names.end())
        methods.push_back(m);
  }
  // The proxseg variants that run, for the Table 1 and stage-time tables.
  std::vector<std::string> run_variants;
  for (const auto& [name, p] : variants)
    if (std::any_of(methods.begin(), methods.end(),
                    [&](const auto& m) { return m.first == "proxseg " + name; }))
      run_variants.push_back(name);

  std::vector<SceneSet> sets;
  try {
    sets.push_back({"mOSD learn", scenes_of(data, limit), 0, data});
    if (!clutter.empty()) sets.push_back({"generated", scenes_of(clutter, limit), 0, clutter});
  } catch (const proxseg::InputError& e) {
    std::cerr << "seg_bench: " << e.what() << "\n";
    return 1;
  }
  std::size_t total_files = 0;
  for (const auto& set : sets) total_files += set.files.size();

  // One untimed run of every method first: first-call costs (page faults, lazy init) are not
  // the method's per-frame cost.
  {
    const Frame warm = proxseg::read_pcd(sets.front().files.front().string());
    for (auto& [name, run] : methods) run(warm);
    stage_ms.clear();
    stage_frames.clear();
    table1.clear();
  }
  std::vector<proxseg::SceneScores> scores;
  std::map<std::string, std::vector<proxseg::SceneScores>> scores_of_set;
  std::size_t step = 0;
  for (auto& set : sets) {
    current_set = set.name;
    for (const auto& file : set.files) {
      ++step;
      const Frame frame = proxseg::read_pcd(file.string());
      if (frame.label.empty()) {
        std::cerr << "[" << step << "/" << total_files << "] " << set.name << ": "
                  << file.filename().string() << " (no label field, skipped)\n";
        continue;
      }
      for (auto& [name, run] : methods) {
        const auto start = std::chrono::steady_clock::now();
        untimed_seconds = 0;
        const Labels labels = run(frame);
        const double s = seconds_since(start) - untimed_seconds;
        proxseg::SceneScores sc = proxseg::score_scene(frame, labels);
        sc.scene = file.filename().string();
        // A generated scene's kind is its file name's prefix (clutter, piles, occlusion); every
        // other scene of the second set counts as clutter.
        sc.category = proxseg::scene_category(sc.scene);
        if (set.name == "generated" && sc.category == "other") sc.category = "clutter";
        sc.method = name;
        sc.seconds = s;
        scores.push_back(sc);
        scores_of_set[set.name].push_back(sc);
      }
      ++set.done;
      std::cerr << "[" << step << "/" << total_files << "] " << set.name << ": "
                << file.filename().string() << "\n";
    }
  }
  const auto rows = proxseg::summary_rows(scores);
  int done = 0;
  for (const auto& set : sets) done += set.done;

  // Whole-process wall time: each tool as its own process (read the PCD, segment, write the
  // outputs), timed from spawn to exit; outputs go to a temporary directory removed at the end.
  std::vector<ProcessTimes> process_times;
  ProcessCost startup_proxseg, startup_lccp;  // sums over 5 runs
  if (process_scenes > 0) {
    try {
      const TempDir tmp;
      const std::vector<std::string> thread_args =
          threads > 0 ? std::vector<std::string>{"--threads", std::to_string(threads)}
                      : std::vector<std::string>{};
      auto proxseg_one = [&](const std::filesystem::path& scene, const std::string& prefix) {
        std::vector<std::string> args = {proxseg_cli, "segment", scene.string(), "-o", prefix};
        args.insert(args.end(), thread_args.begin(), thread_args.end());
        return run_process(args);
      };
      auto clear = [&] {
        for (const auto& e : std::filesystem::directory_iterator(tmp.path))
          std::filesystem::remove_all(e.path());
      };
      // Start-up alone: the help text, and lccp_process without arguments (usage, exit 2).
      for (int i = 0; i < 5; ++i) {
        startup_proxseg += run_process({proxseg_cli, "--help"});
        startup_lccp += run_process({lccp_process}, 2);
      }
      for (std::size_t si = 0; si < sets.size(); ++si) {
        std::vector<std::filesystem::path> files = proxseg::scene_files(sets[si].dir);
        if (static_cast<int>(files.size()) > process_scenes) files.resize(process_scenes);
        const int n = static_cast<int>(files.size());
        // Both tools find the files in the page cache: each is read once first.
        for (const auto& f : files)
          std::ifstream(f, std::ios::binary).ignore(std::numeric_limits<std::streamsize>::max());
        // One untimed run of each.
        proxseg_one(files.front(), (tmp.path / "warm").string());
        run_process({lccp_process, files.front().string(), "-o", tmp.path.string()});
        clear();

        ProcessTimes single{sets[si].name, "one process per frame", n, {}, {}};
        for (int i = 0; i < n; ++i) {
          const auto& f = files[i];
          auto run_proxseg = [&] {
            single.proxseg += proxseg_one(f, (tmp.path / ("p-" + f.stem().string())).string());
          };
          auto run_lccp = [&] {
            single.lccp += run_process({lccp_process, f.string(), "-o", tmp.path.string()});
          };
          if (i % 2 == 0) {  // alternating which tool goes first
            run_proxseg();
            run_lccp();
          } else {
            run_lccp();
            run_proxseg();
          }
          clear();
          std::cerr << "[process " << i + 1 << "/" << n << "] " << sets[si].name << ": "
                    << f.filename().string() << " proxseg " << fmt(single.proxseg.wall / (i + 1))
                    << " s, lccp_process " << fmt(single.lccp.wall / (i + 1))
                    << " s per frame (wall)\n";
        }
        process_times.push_back(single);

        // One process for the n frames: proxseg's --batch takes a folder, so a folder of links.
        ProcessTimes batch{
            sets[si].name, "one process for " + std::to_string(n) + " frames", n, {}, {}};
        const std::filesystem::path in = tmp.path / "in";
        std::filesystem::create_directory(in);
        std::vector<std::string> lccp_args = {lccp_process};
        for (const auto& f : files) {
          std::filesystem::create_symlink(std::filesystem::absolute(f), in / f.filename());
          lccp_args.push_back(f.string());
        }
        lccp_args.insert(lccp_args.end(), {"-o", (tmp.path / "l-batch").string()});
        std::vector<std::string> proxseg_args = {
            proxseg_cli, "segment", "--batch", in.string(), "-o", (tmp.path / "p-batch").string()};
        proxseg_args.insert(proxseg_args.end(), thread_args.begin(), thread_args.end());
        if (si % 2 == 0) {
          batch.proxseg = run_process(proxseg_args);
          batch.lccp = run_process(lccp_args);
        } else {
          batch.lccp = run_process(lccp_args);
          batch.proxseg = run_process(proxseg_args);
        }
        clear();
        std::cerr << "[process batch] " << sets[si].name << ": proxseg "
                  << fmt(batch.proxseg.wall / n) << " s, lccp_process " << fmt(batch.lccp.wall / n)
                  << " s per frame (wall)\n";
        process_times.push_back(batch);
      }
    } catch (const std::exception& e) {  // a tool failed, or the temporary directory
      std::cerr << "seg_bench: whole-process timing: " << e.what() << "\n";
      return 1;
    }
  }

  std::ostringstream md;
  md << "## Segmentation (";
  for (std::size_t i = 0; i < sets.size(); ++i)
    md << (i ? "; " : "") << sets[i].name << ", " << sets[i].done << " scenes";
  md << ")\n\n"
     << "Generated by `make bench-seg` (bench/seg_bench.cpp) at commit "
     << proxseg::bench::git_commit()
     << ", all methods on the same scenes in the same run, timed per frame (wall clock, "
     << "2-core machine). Metrics are defined in docs/metrics.md; \"objects\" scheme unless "
        "noted. \"lost in bg\": share of the truth objects whose majority segment is mostly "
        "table (pooled over the scenes).";
  if (sets.size() > 1)
    md << " The generated scenes are made by `proxseg synth --clutter --kind clutter|piles|"
          "occlusion` (cluttered tabletops; boxes face to face in piles; a low camera with objects "
          "in front of others: docs/clutter.md), mOSD's label convention; their rows by kind are "
          "in the per-category table.";
  md << "\n\n";
  md << "### Summary ("
     << (sets.size() > 1 ? std::to_string(done) + " scenes, both sets" : std::string("all scenes"))
     << ")\n\n"
     << "| method | object F | F>=0.75 | V-measure | WOv | lost in bg | s/frame |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows)
    if (r.category == "all")
      md << "| " << r.method << " | " << fmt(r.objects.object_f) << " | "
         << fmt(r.objects.detected_075) << " | " << fmt(r.objects.v.v) << " | "
         << fmt(r.objects.weighted_overlap) << " | " << fmt(r.objects.lost_in_background_share)
         << " | " << fmt(r.seconds) << " |\n";
  if (sets.size() > 1) {
    md << "\n### Per set\n\n"
       << "| method | set | scenes | object F | F>=0.75 | V-measure | WOv | lost in bg | "
          "s/frame |\n|---|---|---|---|---|---|---|---|---|\n";
    std::map<std::string, std::vector<proxseg::SummaryRow>> set_rows;
    for (const auto& set : sets)
      set_rows[set.name] = proxseg::summary_rows(scores_of_set[set.name]);
    for (const auto& [method, run] : methods)
      for (const auto& set : sets)
        for (const auto& r : set_rows[set.name])
          if (r.category == "all" && r.method == method)
            md << "| " << r.method << " | " << set.name << " | " << r.scenes << " | "
               << fmt(r.objects.object_f) << " | " << fmt(r.objects.detected_075) << " | "
               << fmt(r.objects.v.v) << " | " << fmt(r.objects.weighted_overlap) << " | "
               << fmt(r.objects.lost_in_background_share) << " | " << fmt(r.seconds) << " |\n";
  }
  // Algorithm time against LCCP (the acceptance: at most half of LCCP's time per frame).
  const auto mean_seconds = [](const std::vector<proxseg::SummaryRow>& rs, const std::string& m) {
    for (const auto& r : rs)
      if (r.category == "all" && r.method == m) return r.seconds;
    return 0.0;
  };
  if (mean_seconds(rows, "proxseg default") > 0 && mean_seconds(rows, "PCL LCCP") > 0) {
    md << "\n### Algorithm time against LCCP (in process, s/frame)\n\n"
       << "proxseg's segment() (preset default) and the PCL LCCP peer on the same frames in "
          "memory, reading and writing excluded.\n\n"
       << "| set | scenes | proxseg default | PCL LCCP | proxseg / LCCP |\n|---|---|---|---|---|\n";
    std::vector<std::pair<std::string, std::vector<proxseg::SummaryRow>>> per_set;
    for (const auto& set : sets)
      per_set.emplace_back(set.name, proxseg::summary_rows(scores_of_set[set.name]));
    if (sets.size() > 1) per_set.emplace_back("both sets", rows);
    for (const auto& [name, rs] : per_set) {
      const double p = mean_seconds(rs, "proxseg default"), l = mean_seconds(rs, "PCL LCCP");
      int n = 0;
      for (const auto& r : rs)
        if (r.category == "all" && r.method == "PCL LCCP") n = r.scenes;
      md << "| " << name << " | " << n << " | " << fmt(p) << " | " << fmt(l) << " | "
         << (l > 0 ? fmt(p / l, 2) : "-") << " |\n";
    }
  }
  if (!process_times.empty()) {
    md << "\n### Whole-process time per frame (wall and CPU)\n\n"
       << "Each process reads the PCD, segments it and writes its outputs: `proxseg segment` "
          "(preset default) writes the labelled PCD, the PNG picture and the JSON report; "
          "`lccp_process` (bench/lccp_process.cpp, PCL only: the PCL LCCP above, same parameters "
          "and labels) writes a labelled PCD. Wall time from spawn to exit (posix_spawn + "
          "wait4), CPU time = user + sys of the process and its threads (wait4), on the first "
       << process_scenes
       << " scenes of each set (files already in the page cache), after one untimed run of "
          "each; one process per frame alternates which tool goes first. Start-up alone (mean "
          "of 5): `proxseg --help` "
       << fmt(startup_proxseg.wall / 5) << " s wall / " << fmt(startup_proxseg.cpu / 5)
       << " s CPU, `lccp_process` without arguments " << fmt(startup_lccp.wall / 5) << " / "
       << fmt(startup_lccp.cpu / 5) << " s.\n\n"
       << "| set | mode | proxseg wall s/frame | LCCP wall s/frame | wall proxseg / LCCP | "
          "proxseg CPU s/frame | LCCP CPU s/frame | CPU proxseg / LCCP |\n"
       << "|---|---|---|---|---|---|---|---|\n";
    std::vector<ProcessTimes> table = process_times;
    if (sets.size() > 1)
      for (const bool single : {true, false}) {
        ProcessTimes both{
            "both sets", single ? "one process per frame" : "one process per set", 0, {}, {}};
        for (const auto& t : process_times)
          if ((t.mode == "one process per frame") == single) {
            both.frames += t.frames;
            both.proxseg += t.proxseg;
            both.lccp += t.lccp;
          }
        table.push_back(both);
      }
    for (const auto& t : table) {
      const double n = std::max(1, t.frames);
      md << "| " << t.set << " | " << t.mode;
      for (const auto& [p, l] : {std::pair{t.proxseg.wall / n, t.lccp.wall / n},
                                 std::pair{t.proxseg.cpu / n, t.lccp.cpu / n}})
        md << " | " << fmt(p) << " | " << fmt(l) << " | " << (l > 0 ? fmt(p / l, 2) : "-");
      md << " |\n";
    }
  }
  if (!run_variants.empty()) {
    md << "\n### The paper's Table 1 protocol (raw labels, before selection)\n\n"
       << "Each predicted label mapped to the ground-truth region holding most of its points; "
          "precision and recall macro-averaged over regions (table included). Paper (its own 13 "
          "scenes): k-means 61.3 / 61.3 / 0.17, k-means+MRF 58.2 / 76.7 / 0.35.\n\n"
       << (sets.size() > 1 ? "| set " : "")
       << "| preset | labels | precision (%) | recall (%) | V-measure |\n"
       << (sets.size() > 1 ? "|---" : "") << "|---|---|---|---|---|\n";
    for (const auto& set : sets)
      for (const auto& preset : run_variants)
        for (const std::string stage : {"k-means", "k-means+MRF"}) {
          const Table1& t = table1[set.name][preset + " " + stage];
          const double n = std::max(1, t.scenes);
          if (sets.size() > 1) md << "| " << set.name << " ";
          md << "| " << preset << " | " << stage << " | " << fmt(100 * t.precision / n, 1) << " | "
             << fmt(100 * t.recall / n, 1) << " | " << fmt(t.v / n, 2) << " |\n";
        }
  }
  md << "\n### Every metric, per category\n\n" << proxseg::summary_markdown(rows);
  if (!run_variants.empty()) {
    md << "\n### proxseg stage times (ms per frame, mean"
       << (sets.size() > 1 ? " over both sets" : "") << ")\n\n| stage |";
    for (const auto& v : run_variants) md << " " << v << " |";
    md << "\n|---|";
    for (std::size_t i = 0; i < run_variants.size(); ++i) md << "---|";
    md << "\n";
    std::vector<std::string> rows = stages;
    rows.insert(rows.end(), concurrent.begin(), concurrent.end());
    rows.push_back(kTotal);
    for (const auto& stage : rows) {
      md << "| " << stage << " |";
      for (const auto& v : run_variants)
        md << " " << fmt(stage_ms[v][stage] / std::max(1, stage_frames[v]), 1) << " |";
      md << "\n";
    }
  }
  md << "\nPresets: `paper` = the paper's settings (w_c = 0.275, alpha-beta swap, 2 cm voxels, "
        "alpha = 0.85); `default` = the best measured settings (docs/method.md).";
  for (const auto& [name, path] : config_files) {
    std::string body;
    try {
      std::ifstream in(path);
      body = nlohmann::json::parse(in).dump();
    } catch (const std::exception&) {
      body = "(unreadable)";
    }
    md << " `" << name << "` = default with `" << body << "` (" << path << ").";
  }
  md << " Peers: PCL 1.13 supervoxels + LCCP (voxel 0.0075, seed 0.03, colour 0, spatial 1, "
        "normal 4, concavity 10 deg, smoothness 0.1, sanity on, extended convexity off), "
        "RegionGrowingRGB (tutorial values), RANSAC plane (2 cm) + Euclidean clusters (2 cm) as "
        "in PCL's tutorials.\n";

  std::cout << md.str();
  try {
    if (!out.empty()) proxseg::write_file_atomic(out, md.str());
    if (!csv.empty()) proxseg::write_file_atomic(csv, proxseg::scenes_csv(scores));
  } catch (const proxseg::InputError& e) {
    std::cerr << "seg_bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
