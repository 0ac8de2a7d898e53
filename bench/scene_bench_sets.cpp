// scene_bench's scene sets and splits (scene_bench.hpp): the seeds of --dev-seeds and
// --report-seeds, and the LINEMOD catalogue or the object folds of --set objects with their
// databases.
#include <proxseg/eval/object_set.hpp>

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene_bench.hpp"

namespace proxseg::bench::scenebench {
namespace {

// Seeds of fold f's split: the first seed + 1000 f onwards, so that folds draw other scenes.
std::vector<std::uint32_t> fold_seeds(std::uint32_t first, int count, int fold) {
  return seed_range(first + 1000u * static_cast<std::uint32_t>(fold), count);
}

}  // namespace

std::vector<std::uint32_t> parse_seeds(const std::string& spec, const std::string& option) {
  std::vector<std::uint32_t> seeds;
  std::stringstream in(spec);
  for (std::string item; std::getline(in, item, ',');) {
    const auto dash = item.find('-');
    try {
      std::size_t used = 0;
      const unsigned long a = std::stoul(item.substr(0, dash), &used);
      if (used != item.substr(0, dash).size()) throw std::invalid_argument(item);
      unsigned long b = a;
      if (dash != std::string::npos) {
        b = std::stoul(item.substr(dash + 1), &used);
        if (used != item.size() - dash - 1) throw std::invalid_argument(item);
      }
      if (b < a || b - a > 100000 || b > 0xffffffffUL) throw std::invalid_argument(item);
      for (unsigned long s = a; s <= b; ++s) seeds.push_back(static_cast<std::uint32_t>(s));
    } catch (const std::exception&) {
      throw CLI::ValidationError(option + ": expected seeds like 1-20 or 3,5,101-103, got '" +
                                 spec + "'");
    }
  }
  if (seeds.empty()) throw CLI::ValidationError(option + ": no seeds");
  return seeds;
}

// "1-20" for a run of consecutive seeds, else the list.
std::string seeds_text(const std::vector<std::uint32_t>& seeds) {
  bool run = true;
  for (std::size_t i = 1; i < seeds.size(); ++i) run = run && seeds[i] == seeds[i - 1] + 1;
  if (run && seeds.size() > 1)
    return std::to_string(seeds.front()) + "-" + std::to_string(seeds.back());
  std::string s;
  for (auto x : seeds) s += (s.empty() ? "" : ",") + std::to_string(x);
  return s;
}

void make_splits(const Options& o, const DescriptorParams& descriptor, std::vector<SceneSet>& sets,
                 std::vector<Split>& splits) {
  if (o.set == "lmo") {
    SceneSet set{"lmo", scene_catalogue(o.models), {}};
    set.db = scene_database(set.catalogue, o.views, descriptor);
    sets.push_back(std::move(set));
    if (o.scenes > 0) {
      splits.push_back({"scenes", "scenes", seed_range(o.first_seed, o.scenes), 0});
    } else {
      splits.push_back({"dev", "dev", parse_seeds(o.dev_seeds, "--dev-seeds"), 0});
      splits.push_back({"report", "report", parse_seeds(o.report_seeds, "--report-seeds"), 0});
    }
    return;
  }
  if (o.set != "objects")
    throw CLI::ValidationError("--set: expected lmo or objects, got '" + o.set + "'");
  ObjectPoolParams pp;
  pp.linemod_dir = o.models;
  pp.ycbv_dir = o.ycbv;
  pp.textured_dir = o.textured;
  const std::vector<PoolObject> pool = object_pool(pp);
  ObjectFoldParams fp;
  fp.known = o.fold_known;
  fp.unknown = o.fold_unknown;
  const std::vector<ObjectFold> folds = object_folds(pool, fp);
  CaptureParams capture;
  capture.views = o.views;
  std::vector<int> per_half(2, 0);
  for (std::size_t f = 0; f < folds.size(); ++f) {
    if (o.max_folds > 0 && per_half[folds[f].half]++ >= o.max_folds) continue;
    SceneSet set{folds[f].name, fold_catalogue(pool, folds[f]), {}};
    set.db = captured_database(set.catalogue, capture, descriptor);
    const std::string half(1, char('A' + folds[f].half));
    const int idx = static_cast<int>(sets.size());
    sets.push_back(std::move(set));
    splits.push_back({folds[f].name + " dev", half + " dev",
                      fold_seeds(1, o.fold_scenes, static_cast<int>(f)), idx});
    const int report = o.fold_report_scenes < 0 ? o.fold_scenes : o.fold_report_scenes;
    if (report > 0)
      splits.push_back({folds[f].name + " report", half + " report",
                        fold_seeds(101, report, static_cast<int>(f)), idx});
  }
}

}  // namespace proxseg::bench::scenebench
