// Cross-validated choice of segmentation parameters: runs every variant of a grid once on every
// scene of mOSD learn (and of the generated clutter set), then, for each fold (one mOSD category,
// or one half of the clutter set by seed parity), picks the variant with the best mean object F on
// all the other scenes and scores it on the fold. The held-out scores, put together, estimate
// what choosing parameters on this data is worth on scenes it has not seen; the in-sample score
// of the best variant overall is the optimistic figure beside it.
// Usage: seg_cv --data DIR [--clutter DIR] --grid grid.json [--out cv.md] [--json cv.json]
//               [--csv scenes.csv] [--scenes N] [--threads T]
// grid.json: {"variants": {"name": {<parameters overrides>}, ...}} and/or
//            {"sweep": {"mrf.pairwise_weight": [0.05, 0.1], "selection.x": [1, 2]}} (Cartesian
//            product; dotted paths into the layout of the report's "parameters"). Every variant is
//            read on top of preset default. A sweep value that is itself a list goes in a list of
//            lists ([[...], [...]]); a single non-list value is a sweep of one.
#include "bench_main.hpp"
#include "bench_util.hpp"
#include "scene_list.hpp"

#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/eval/cross_validation.hpp>
#include <proxseg/eval/scene_names.hpp>
#include <proxseg/eval/seg_scores.hpp>
#include <proxseg/eval/seg_summary.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/params.hpp>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace {

using proxseg::InputError;

using proxseg::bench::Clock;
using proxseg::bench::git_commit;
using proxseg::bench::scenes_of;
using proxseg::bench::SceneSet;
using proxseg::bench::seconds_since;

// v with three digits after the point, or `digits`.
std::string fmt(double v, int digits = 3) {
  return proxseg::bench::fixed(v, digits);
}

struct Variant {
  std::string name;
  nlohmann::json overrides;  // as given (on top of preset default)
  proxseg::SegmentParams params;
};

// Sets a dotted path ("mrf.pairwise_weight") in a JSON object.
void set_path(nlohmann::json& j, const std::string& path, const nlohmann::json& value) {
  nlohmann::json* at = &j;
  std::stringstream in(path);
  std::vector<std::string> parts;
  for (std::string part; std::getline(in, part, '.');) parts.push_back(part);
  if (parts.empty() || std::any_of(parts.begin(), parts.end(), [](auto& p) { return p.empty(); }))
    throw InputError("sweep: bad path \"" + path + "\" (expected e.g. mrf.pairwise_weight)");
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    nlohmann::json& next = (*at)[parts[i]];
    if (next.is_null()) next = nlohmann::json::object();
    if (!next.is_object()) throw InputError("sweep: path \"" + path + "\" crosses a value");
    at = &next;
  }
  (*at)[parts.back()] = value;
}

// The variants of a grid file, in file order (nlohmann::ordered_json keeps it: ties go to the
// first variant, so the order matters).
std::vector<Variant> read_grid(const std::string& path, int threads) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open (expected a grid JSON file)");
  nlohmann::ordered_json grid;
  try {
    grid = nlohmann::ordered_json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not JSON (" + e.what() + ")");
  }
  if (!grid.is_object()) throw InputError(path + ": expected an object with variants or sweep");
  std::vector<std::pair<std::string, nlohmann::json>> raw;  // name, overrides
  for (const auto& [key, value] : grid.items()) {
    if (key == "variants") {
      if (!value.is_object()) throw InputError(path + ": variants: expected an object of objects");
      for (const auto& [name, o] : value.items()) {
        if (!o.is_object())
          throw InputError(path + ": variants." + name + ": expected an object of parameters");
        raw.emplace_back(name, nlohmann::json::parse(o.dump()));
      }
    } else if (key == "sweep") {
      if (!value.is_object() || value.empty())
        throw InputError(path + ": sweep: expected an object of path -> list of values");
      // Cartesian product, the first path varying slowest.
      std::vector<std::pair<std::string, nlohmann::json>> combos = {{"", nlohmann::json::object()}};
      for (const auto& [dotted, values] : value.items()) {
        const nlohmann::ordered_json list =
            values.is_array() ? values : nlohmann::ordered_json::array({values});
        if (list.empty()) throw InputError(path + ": sweep." + dotted + ": no values");
        std::vector<std::pair<std::string, nlohmann::json>> next;
        for (const auto& [name, overrides] : combos)
          for (const auto& v : list) {
            nlohmann::json o = overrides;
            const nlohmann::json jv = nlohmann::json::parse(v.dump());
            set_path(o, dotted, jv);
            next.emplace_back(name + (name.empty() ? "" : ", ") + dotted + "=" + v.dump(), o);
          }
        combos = std::move(next);
      }
      raw.insert(raw.end(), combos.begin(), combos.end());
    } else {
      throw InputError(path + ": unknown key \"" + key + "\" (expected variants or sweep)");
    }
  }
  if (raw.empty()) throw InputError(path + ": no variants");
  std::vector<Variant> variants;
  for (const auto& [name, o] : raw) {
    for (const auto& v : variants)
      if (v.name == name) throw InputError(path + ": variant " + name + " given twice");
    Variant v{name, o, {}};
    try {
      v.params = proxseg::params_from_json(o, proxseg::preset("default"));
      v.params.threads = threads;
      proxseg::validate(v.params);
    } catch (const InputError& e) {
      throw InputError(path + ": variant " + name + ": " + e.what());
    }
    variants.push_back(std::move(v));
  }
  return variants;
}

struct Scene {
  std::string name, set, category, fold;
  std::vector<proxseg::SceneScores> scores;  // per variant
};

// Mean object F and pooled lost-in-background share of the scenes in a scope, each scored under
// the variant variant_of(scene index).
struct ScopeScore {
  int scenes = 0;
  double f = 0, lost_share = 0;
};
ScopeScore score_scope(const std::vector<Scene>& scenes,
                       const std::function<bool(const Scene&)>& in,
                       const std::function<int(std::size_t)>& variant_of) {
  ScopeScore s;
  long lost = 0, objects = 0;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    if (!in(scenes[i])) continue;
    const proxseg::SegmentationScores& o = scenes[i].scores[variant_of(i)].objects;
    ++s.scenes;
    s.f += o.object_f;
    lost += o.lost_in_background;
    objects += o.truth_objects;
  }
  if (s.scenes) s.f /= s.scenes;
  s.lost_share = objects ? static_cast<double>(lost) / static_cast<double>(objects) : 0.0;
  return s;
}

struct Options {
  std::string data, clutter, grid_path, out, json_path, csv;
  std::string title = "Cross-validated segmentation parameters";
  int limit = 0, threads = 0;
};

void add_options(CLI::App& app, Options& o) {
  app.add_option("--data", o.data, "Folder of labelled mOSD learn scenes")->required();
  app.add_option("--clutter", o.clutter, "Folder of the generated clutter set (optional)");
  app.add_option("--grid", o.grid_path, "Grid JSON: {\"variants\": {...}} or {\"sweep\": {...}}")
      ->required();
  app.add_option("--out", o.out, "Markdown report to write (also printed on stdout)");
  app.add_option("--title", o.title, "Heading of the markdown report");
  app.add_option("--json", o.json_path, "JSON report to write");
  app.add_option("--csv", o.csv, "Per-scene, per-variant scores (CSV) to write");
  app.add_option("--scenes", o.limit, "Use only N scenes of each set, spread evenly (0 = all)");
  app.add_option("--threads", o.threads, "Threads for proxseg (0 = all cores)");
}

// What a run measured: every variant on every labelled scene, and the folds' choices.
struct Run {
  std::vector<Variant> variants;
  std::vector<SceneSet> sets;
  std::vector<Scene> scenes;
  double elapsed = 0;                  // seconds
  std::vector<std::vector<double>> f;  // [scene][variant]: object F
  proxseg::CrossValidation cv;
};

// Every variant on one scene file (nothing when it has no labels).
std::optional<Scene> run_scene(const SceneSet& set, const std::filesystem::path& file,
                               const std::vector<Variant>& variants, const std::string& step) {
  const proxseg::Frame frame = proxseg::read_pcd(file.string());
  Scene sc;
  sc.name = file.filename().string();
  sc.set = set.name;
  if (frame.label.empty()) {
    std::cerr << step << sc.name << " (no label field, skipped)\n";
    return std::nullopt;
  }
  // Generated scenes (clutter-, piles-, occlusion-NNN.pcd): their kind in halves by seed
  // parity; mOSD learn scenes: their category.
  sc.category = proxseg::scene_category(sc.name);
  sc.fold = proxseg::scene_fold(sc.name);
  if (set.name == "generated" && sc.category == "other") sc.category = sc.fold = "clutter";
  std::ostringstream line;
  for (const auto& v : variants) {
    const auto start = Clock::now();
    const auto labels = proxseg::segment(frame, v.params).selection.instance;
    const double seconds = seconds_since(start);
    proxseg::SceneScores s = proxseg::score_scene(frame, labels);
    s.scene = sc.name;
    s.category = sc.category;
    s.method = v.name;
    s.seconds = seconds;
    line << " " << fmt(s.objects.object_f);
    sc.scores.push_back(s);
  }
  std::cerr << step << set.name << ": " << sc.name << " (" << sc.fold << ") F" << line.str()
            << "\n";
  return sc;
}

// Every variant once on every scene, scenes one after the other (proxseg uses the cores); then
// the folds' choices.
void run_variants(Run& r) {
  std::size_t total = 0;
  for (const auto& s : r.sets) total += s.files.size();
  std::cerr << "seg_cv: " << r.variants.size() << " variants x " << total << " scenes\n";
  std::size_t step = 0;
  const auto started = Clock::now();
  for (const auto& set : r.sets)
    for (const auto& file : set.files) {
      const std::string at = "[" + std::to_string(++step) + "/" + std::to_string(total) + "] ";
      if (auto sc = run_scene(set, file, r.variants, at)) r.scenes.push_back(std::move(*sc));
    }
  r.elapsed = seconds_since(started);
  r.f.resize(r.scenes.size());
  std::vector<std::string> fold_of(r.scenes.size());
  for (std::size_t i = 0; i < r.scenes.size(); ++i) {
    for (const auto& s : r.scenes[i].scores) r.f[i].push_back(s.objects.object_f);
    fold_of[i] = r.scenes[i].fold;
  }
  try {
    r.cv = proxseg::cross_validate(r.f, fold_of);
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + " (" + std::to_string(r.scenes.size()) +
                     " labelled scenes; use more scenes so that at least two folds have some)");
  }
}

using Scopes = std::vector<std::pair<std::string, std::function<bool(const Scene&)>>>;

// Scopes of the result table: all scenes, each set, each mOSD category.
Scopes scopes_of(const Run& r) {
  Scopes scopes = {{"all", [](const Scene&) { return true; }}};
  for (const auto& set : r.sets)
    if (r.sets.size() > 1)
      scopes.emplace_back(set.name, [name = set.name](const Scene& s) { return s.set == name; });
  for (const std::string c :
       {"boxes", "stacked", "occluded", "cylindric", "other", "clutter", "piles", "occlusion"})
    if (std::any_of(r.scenes.begin(), r.scenes.end(),
                    [&](const Scene& s) { return s.category == c; }))
      scopes.emplace_back(c, [c](const Scene& s) { return s.category == c; });
  return scopes;
}

void md_header(std::ostream& md, const Options& o, const Run& r) {
  md << "## " << o.title << "\n\n"
     << "Generated by `bench/seg_cv` at commit " << git_commit() << " from `" << o.grid_path
     << "`: " << r.variants.size() << " variants (each on top of preset default) on ";
  for (std::size_t i = 0; i < r.sets.size(); ++i) {
    int n = 0;
    for (const auto& s : r.scenes) n += s.set == r.sets[i].name;
    md << (i ? " and " : "") << n << " " << r.sets[i].name << " scenes";
  }
  md << " (" << fmt(r.elapsed / 60, 1) << " min). Folds: leave one mOSD category out"
     << (r.sets.size() > 1
             ? "; each generated kind (clutter, piles, occlusion) in two halves by seed parity"
             : "")
     << ". For each fold the variant with the best mean object F on all other scenes is chosen "
        "(ties -> the first) and scored on the fold.\n\n";
}

// The result table per scope, cross-validated and in-sample; report["cross_validated"] and
// report["in_sample"].
void result(std::ostream& md, const Run& r, nlohmann::json& report) {
  const auto cv_variant = [&](std::size_t i) { return r.cv.scene_variant[i]; };
  const auto best_variant = [&](std::size_t) { return r.cv.best_in_sample; };
  md << "### Result\n\n"
     << "Cross-validated: every scene scored under the variant chosen without its fold. In-sample: "
        "the variant with the best mean object F over all scenes (`"
     << r.variants[r.cv.best_in_sample].name
     << "`), scored on the same scenes it was chosen on (optimistic).\n\n"
     << "| scenes in | scenes | CV object F | CV lost in bg | in-sample object F | in-sample lost "
        "in bg |\n|---|---|---|---|---|---|\n";
  nlohmann::json j_cv = nlohmann::json::object(), j_in = nlohmann::json::object();
  for (const auto& [label, in] : scopes_of(r)) {
    const ScopeScore c = score_scope(r.scenes, in, cv_variant),
                     b = score_scope(r.scenes, in, best_variant);
    md << "| " << label << " | " << c.scenes << " | " << fmt(c.f) << " | " << fmt(c.lost_share)
       << " | " << fmt(b.f) << " | " << fmt(b.lost_share) << " |\n";
    j_cv[label] = {
        {"scenes", c.scenes}, {"object_f", c.f}, {"lost_in_background_share", c.lost_share}};
    j_in[label] = {
        {"scenes", b.scenes}, {"object_f", b.f}, {"lost_in_background_share", b.lost_share}};
  }
  report["cross_validated"] = j_cv;
  report["in_sample"] = {{"variant", r.variants[r.cv.best_in_sample].name}, {"scopes", j_in}};
}

// The folds' chosen variants; report["folds"].
void folds(std::ostream& md, const Run& r, nlohmann::json& report) {
  md << "\n### Folds\n\n| fold | scenes | chosen variant | training F | held-out F |\n"
     << "|---|---|---|---|---|\n";
  nlohmann::json j_folds = nlohmann::json::array();
  for (std::size_t k = 0; k < r.cv.folds.size(); ++k) {
    const std::string& chosen = r.variants[r.cv.chosen[k]].name;
    md << "| " << r.cv.folds[k] << " | " << r.cv.fold_scenes[k] << " | " << chosen << " | "
       << fmt(r.cv.training[k]) << " | " << fmt(r.cv.held_out[k]) << " |\n";
    j_folds.push_back({{"fold", r.cv.folds[k]},
                       {"scenes", r.cv.fold_scenes[k]},
                       {"chosen", chosen},
                       {"training_object_f", r.cv.training[k]},
                       {"held_out_object_f", r.cv.held_out[k]}});
  }
  report["folds"] = j_folds;
}

// Every variant's mean object F per fold, and its overrides; report["variants"].
void variants_table(std::ostream& md, const Run& r, nlohmann::json& report) {
  const std::size_t nv = r.variants.size(), nf = r.cv.folds.size();
  md << "\n### Mean object F of every variant per fold\n\n| variant |";
  for (const auto& fold : r.cv.folds) md << " " << fold << " |";
  md << " all | lost in bg | s/frame |\n|---|";
  for (std::size_t k = 0; k < nf + 3; ++k) md << "---|";
  md << "\n";
  nlohmann::json j_variants = nlohmann::json::array();
  for (std::size_t v = 0; v < nv; ++v) {
    const ScopeScore all = score_scope(
        r.scenes, [](const Scene&) { return true; },
        [v](std::size_t) { return static_cast<int>(v); });
    double seconds = 0;
    for (const auto& s : r.scenes) seconds += s.scores[v].seconds / r.scenes.size();
    md << "| " << r.variants[v].name
       << (static_cast<int>(v) == r.cv.best_in_sample ? " (best)" : "") << " |";
    nlohmann::json per_fold = nlohmann::json::object();
    for (std::size_t k = 0; k < nf; ++k) {
      md << " " << fmt(r.cv.fold_means[k][v]) << " |";
      per_fold[r.cv.folds[k]] = r.cv.fold_means[k][v];
    }
    md << " " << fmt(r.cv.variant_means[v]) << " | " << fmt(all.lost_share) << " | " << fmt(seconds)
       << " |\n";
    j_variants.push_back({{"name", r.variants[v].name},
                          {"overrides", r.variants[v].overrides},
                          {"object_f", r.cv.variant_means[v]},
                          {"object_f_per_fold", per_fold},
                          {"lost_in_background_share", all.lost_share},
                          {"seconds_per_frame", seconds}});
  }
  md << "\nVariants (overrides of preset default):\n\n";
  for (const auto& v : r.variants) md << "- `" << v.name << "`: `" << v.overrides.dump() << "`\n";
  report["variants"] = j_variants;
}

nlohmann::json scenes_json(const Run& r) {
  nlohmann::json j_scenes = nlohmann::json::array();
  for (std::size_t i = 0; i < r.scenes.size(); ++i) {
    nlohmann::json per_variant = nlohmann::json::object();
    for (std::size_t v = 0; v < r.variants.size(); ++v) per_variant[r.variants[v].name] = r.f[i][v];
    j_scenes.push_back({{"scene", r.scenes[i].name},
                        {"set", r.scenes[i].set},
                        {"fold", r.scenes[i].fold},
                        {"chosen", r.variants[r.cv.scene_variant[i]].name},
                        {"held_out_object_f", r.cv.scene_score[i]},
                        {"object_f", per_variant}});
  }
  return j_scenes;
}

// The report on stdout, and the files asked for.
int write_outputs(const Options& o, const Run& r, const std::string& md,
                  const nlohmann::json& report) {
  std::cout << md;
  try {
    if (!o.out.empty()) proxseg::write_file_atomic(o.out, md);
    if (!o.json_path.empty()) proxseg::write_file_atomic(o.json_path, report.dump(2) + "\n");
    if (!o.csv.empty()) {
      std::vector<proxseg::SceneScores> all;
      for (const auto& s : r.scenes) all.insert(all.end(), s.scores.begin(), s.scores.end());
      proxseg::write_file_atomic(o.csv, proxseg::scenes_csv(all));
    }
  } catch (const std::exception& e) {
    std::cerr << "seg_cv: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

int run(const Options& o) {
  Run r;
  r.variants = read_grid(o.grid_path, o.threads);
  r.sets.push_back({"mOSD learn", scenes_of(o.data, o.limit)});
  if (!o.clutter.empty()) r.sets.push_back({"generated", scenes_of(o.clutter, o.limit)});
  run_variants(r);
  std::ostringstream md;
  nlohmann::json report = {
      {"grid", o.grid_path}, {"commit", git_commit()}, {"criterion", "object_f"}};
  md_header(md, o, r);
  result(md, r, report);
  folds(md, r, report);
  variants_table(md, r, report);
  report["scenes"] = scenes_json(r);
  return write_outputs(o, r, md.str(), report);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Cross-validated choice of proxseg's segmentation parameters"};
  Options o;
  add_options(app, o);
  return proxseg::bench::main_of("seg_cv", app, argc, argv, [&] { return run(o); });
}
