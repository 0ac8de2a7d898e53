// Segmentation benchmark: proxseg (paper and default presets, plus variants from JSON configs) and
// the PCL peers (LCCP, colour region growing, plane + Euclidean clusters) on the same labelled
// scenes in the same run, each timed per frame; writes docs/results.md (the segmentation part) and
// a per-scene CSV. A second set of labelled scenes (the generated clutter set) can be evaluated in
// the same run: every table then has it beside mOSD learn.
// Usage: seg_bench --data DIR [--clutter DIR] [--out results.md] [--csv scenes.csv] [--scenes N]
//                  [--threads T] [--methods "proxseg default,PCL LCCP"]
//                  [--config NAME=file.json]...
#include "bench_util.hpp"
#include "peers_pcl.hpp"

#include <proxseg/evaluation.hpp>
#include <proxseg/io.hpp>
#include <proxseg/params.hpp>
#include <proxseg/pipeline.hpp>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>

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
  std::string name;  // "mOSD learn", "clutter"
  std::vector<std::filesystem::path> files;
  int done = 0;  // labelled scenes evaluated
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"proxseg segmentation benchmark against PCL's segmenters"};
  std::string data, clutter, out, csv, methods_arg;
  std::vector<std::string> configs;
  int limit = 0, threads = 0;
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
  CLI11_PARSE(app, argc, argv);

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
  // set -> "variant k-means" / "variant k-means+MRF" -> sums
  std::map<std::string, std::map<std::string, Table1>> table1;
  std::string current_set;

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
      ++stage_frames[name];
      const auto truth = proxseg::truth_objects(f);
      const auto km = proxseg::score_segmentation(truth, r.point_labels_kmeans, {1});
      const auto mrf = proxseg::score_segmentation(truth, r.point_labels, {1});
      for (const auto& [row, s] :
           {std::pair{name + " k-means", &km}, std::pair{name + " k-means+MRF", &mrf}}) {
        Table1& t = table1[current_set][row];
        t.precision += s->paper_precision;
        t.recall += s->paper_recall;
        t.v += s->v.v;
        ++t.scenes;
      }
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
    sets.push_back({"mOSD learn", scenes_of(data, limit)});
    if (!clutter.empty()) sets.push_back({"clutter", scenes_of(clutter, limit)});
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
        const Labels labels = run(frame);
        const double s = seconds_since(start);
        proxseg::SceneScores sc = proxseg::score_scene(frame, labels);
        sc.scene = file.filename().string();
        // Every scene of the second set is a clutter scene, whatever its file name.
        sc.category = set.name == "clutter" ? "clutter" : proxseg::scene_category(sc.scene);
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
  const auto rows = proxseg::summarize(scores);
  int done = 0;
  for (const auto& set : sets) done += set.done;

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
    md << " The clutter set is generated by `proxseg synth --clutter` (many objects touching on "
          "one table, mOSD's label convention).";
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
    for (const auto& set : sets) set_rows[set.name] = proxseg::summarize(scores_of_set[set.name]);
    for (const auto& [method, run] : methods)
      for (const auto& set : sets)
        for (const auto& r : set_rows[set.name])
          if (r.category == "all" && r.method == method)
            md << "| " << r.method << " | " << set.name << " | " << r.scenes << " | "
               << fmt(r.objects.object_f) << " | " << fmt(r.objects.detected_075) << " | "
               << fmt(r.objects.v.v) << " | " << fmt(r.objects.weighted_overlap) << " | "
               << fmt(r.objects.lost_in_background_share) << " | " << fmt(r.seconds) << " |\n";
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
    std::map<std::string, double> total;
    for (const auto& stage : stages) {
      md << "| " << stage << " |";
      for (const auto& v : run_variants) {
        const double ms = stage_ms[v][stage] / std::max(1, stage_frames[v]);
        total[v] += ms;
        md << " " << fmt(ms, 1) << " |";
      }
      md << "\n";
    }
    md << "| total (in segment()) |";
    for (const auto& v : run_variants) md << " " << fmt(total[v], 1) << " |";
    md << "\n";
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
  if (!out.empty()) proxseg::write_file_atomic(out, md.str());
  if (!csv.empty()) proxseg::write_file_atomic(csv, proxseg::scenes_csv(scores));
  return 0;
}
