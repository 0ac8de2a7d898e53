// scene_bench's scenes.json, predictions.csv and truths.csv (scene_bench.hpp): per group of
// splits and method the counts, the curve with negatives and the chosen minimum scores; per fold
// the counts; where each method fails.
#include <proxseg/core/version.hpp>
#include <proxseg/io/params.hpp>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "scene_bench.hpp"

namespace proxseg::bench::scenebench {
namespace {

nlohmann::json counts_json(const SceneCounts& c) {
  return {{"scenes", c.scenes},
          {"truths", c.truths},
          {"known", c.known},
          {"unknown", c.unknown},
          {"predictions", c.predictions},
          {"detected", c.detected},
          {"tp", c.tp},
          {"fn", c.fn},
          {"fp", c.fp},
          {"unknown_named", c.unknown_named},
          {"known_unknown", c.known_unknown},
          {"known_unknown_share", c.known_unknown_share()},
          {"pose_ok", c.pose_ok},
          {"detection", c.detection()},
          {"precision", c.precision()},
          {"recall", c.recall()},
          {"f1", c.f1()},
          {"unknown_named_share", c.unknown_named_share()},
          {"pose_rate", c.pose_rate()},
          {"seconds_per_scene", c.seconds_per_scene()}};
}

nlohmann::json point_json(const SceneCurvePoint& p) {
  return {{"min_score", p.min_score},
          {"tp", p.tp},
          {"fp", p.fp},
          {"unknown_named", p.unknown_named},
          {"tpr", p.tpr},
          {"unknown_named_share", p.unknown_named_share},
          {"precision", p.precision},
          {"f1", p.f1}};
}

std::string csv_name(const std::string& s) {
  return s.empty() ? "-" : s;
}

nlohmann::json parameters_json(const Options& o, const Bench& b) {
  nlohmann::json cat = nlohmann::json::array();
  for (const SceneSet& set : b.sets) {
    nlohmann::json entries = nlohmann::json::array();
    for (std::size_t i = 0; i < set.catalogue.entries.size(); ++i)
      entries.push_back({{"name", set.catalogue.entries[i].name},
                         {"kind", to_string(set.catalogue.entries[i].kind)},
                         {"known", set.catalogue.known[i] != 0},
                         {"diameter", set.catalogue.diameters[i]}});
    cat.push_back({{"set", set.name}, {"views", set.db.views.size()}, {"entries", entries}});
  }
  return {{"models", o.models},
          {"set", o.set},
          {"sets", cat},
          {"views_per_object", o.views},
          {"min_objects", b.set_params.min_objects},
          {"max_objects", b.set_params.max_objects},
          {"catalogue_share", b.set_params.catalogue_share},
          {"mesh_share", b.set_params.mesh_share},
          {"segmentation", to_json(b.sp)},
          {"recognition", to_json(b.rp)},
          {"peer", o.peers == "all" ? b.peer_label : ""},
          {"open3d_ransac_iterations", b.o3d.ransac_iterations},
          {"threads", b.team}};
}

// Per group: each method's counts, curve, points at the thresholds and best threshold.
nlohmann::json splits_json(const Bench& b) {
  const std::vector<double> thresholds = {0.3, 0.4, 0.5, 0.6, 0.7, 0.8};
  nlohmann::json splits = nlohmann::json::array();
  for (std::size_t gi = 0; gi < b.groups.size(); ++gi) {
    nlohmann::json js = {{"name", b.groups[gi]}, {"seeds", group_seeds(b, gi)}};
    js["methods"] = nlohmann::json::array();
    for (std::size_t mi = 0; mi < b.methods.size(); ++mi) {
      const Result& r = b.grouped[gi][mi];
      const SceneCounts& c = r.counts;
      nlohmann::json jm = {{"label", b.methods[mi].label}, {"counts", counts_json(c)}};
      jm["curve"] = nlohmann::json::array();
      for (const SceneCurvePoint& p : scene_curve(r.rows, c.known, c.unknown, b.rp))
        jm["curve"].push_back(point_json(p));
      jm["at"] = nlohmann::json::array();
      for (double t : thresholds)
        jm["at"].push_back(point_json(scene_point(r.rows, c.known, c.unknown, t, b.rp)));
      jm["best_threshold"] =
          point_json(best_threshold(scene_curve(r.rows, c.known, c.unknown, b.rp), 0.1));
      js["methods"].push_back(jm);
    }
    splits.push_back(js);
  }
  return splits;
}

nlohmann::json folds_json(const Bench& b) {
  nlohmann::json folds = nlohmann::json::array();
  for (std::size_t si = 0; si < b.splits.size(); ++si)
    for (std::size_t mi = 0; mi < b.methods.size(); ++mi)
      folds.push_back({{"split", b.splits[si].name},
                       {"label", b.methods[mi].label},
                       {"seeds", b.splits[si].seeds},
                       {"counts", counts_json(b.results[si][mi].counts)}});
  return folds;
}

// The minimum score of best F1 with at most 10 % of the unknowns named, chosen on each chooser
// group and applied to every group.
nlohmann::json chosen_json(const Bench& b) {
  nlohmann::json chosen = nlohmann::json::array();
  for (std::size_t ci : choosers(b))
    for (std::size_t mi = 0; mi < b.methods.size(); ++mi) {
      const Result& d = b.grouped[ci][mi];
      const SceneCurvePoint best =
          best_threshold(scene_curve(d.rows, d.counts.known, d.counts.unknown, b.rp), 0.1);
      nlohmann::json jc = {{"label", b.methods[mi].label},
                           {"chosen_on", b.groups[ci]},
                           {"min_score", best.min_score}};
      for (std::size_t gi = 0; gi < b.groups.size(); ++gi) {
        const Result& r = b.grouped[gi][mi];
        jc[b.groups[gi]] =
            point_json(scene_point(r.rows, r.counts.known, r.counts.unknown, best.min_score, b.rp));
      }
      chosen.push_back(jc);
    }
  return chosen;
}

nlohmann::json failures_json(const Bench& b) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t mi = 0; mi < b.methods.size(); ++mi) {
    const Failures f = failures(b, mi);
    out.push_back({{"label", b.methods[mi].label},
                   {"named_wrong", f.wrong},
                   {"called_unknown", f.called_unknown},
                   {"not_detected", f.missed},
                   {"unknown_named", f.unknown_named},
                   {"named_on_nothing", f.on_nothing}});
  }
  return out;
}

}  // namespace

std::vector<std::uint32_t> group_seeds(const Bench& b, std::size_t gi) {
  std::vector<std::uint32_t> seeds;
  for (const Split& sp : b.splits)
    if (sp.group == b.groups[gi]) seeds.insert(seeds.end(), sp.seeds.begin(), sp.seeds.end());
  return seeds;
}

std::vector<std::size_t> choosers(const Bench& b) {
  std::vector<std::size_t> out;
  for (std::size_t gi = 0; gi < b.groups.size(); ++gi)
    if (b.groups[gi].size() >= 3 && b.groups[gi].compare(b.groups[gi].size() - 3, 3, "dev") == 0)
      out.push_back(gi);
  if (out.empty()) out.push_back(0);
  return out;
}

Failures failures(const Bench& b, std::size_t mi) {
  Failures f;
  for (std::size_t si = 0; si < b.splits.size(); ++si) {
    const Result& r = b.results[si][mi];
    for (const TruthRow& t : r.truths) {
      if (t.prediction < 0) {
        ++f.missed[t.truth.name];
      } else if (t.truth.known && t.name == "unknown") {
        ++f.called_unknown[t.truth.name];
      } else if (t.truth.known && t.name != t.truth.name) {
        ++f.wrong[t.truth.name + " -> " + t.name];
      } else if (!t.truth.known && t.name != "unknown") {
        ++f.unknown_named[t.truth.name + " -> " + t.name];
      }
    }
    for (const PredictionRow& p : r.rows)
      if (p.truth < 0 && p.name != "unknown") ++f.on_nothing[p.name];
  }
  return f;
}

nlohmann::json report_json(const Options& o, const Bench& b) {
  nlohmann::json summary;
  summary["proxseg"] = {{"version", version()}, {"commit", proxseg::git_commit()}};
  summary["load_average"] = {{"before", b.load_before}, {"after", b.load_after}};
  summary["parameters"] = parameters_json(o, b);
  summary["splits"] = splits_json(b);
  if (o.set != "lmo") summary["folds"] = folds_json(b);
  summary["chosen_threshold"] = chosen_json(b);
  summary["failures"] = failures_json(b);
  return summary;
}

std::string predictions_csv(const Bench& b) {
  std::ostringstream csv;
  csv << "method,split,scene,prediction,points,truth,truth_name,truth_known,iou,name,best,score,"
         "runner_up,colour,add_s_m,pose_ok\n";
  for (std::size_t si = 0; si < b.splits.size(); ++si)
    for (std::size_t mi = 0; mi < b.methods.size(); ++mi) {
      const Result& r = b.results[si][mi];
      for (std::size_t j = 0; j < r.rows.size(); ++j) {
        const PredictionRow& p = r.rows[j];
        csv << '"' << b.methods[mi].label << "\"," << b.splits[si].name << "," << p.scene << ","
            << p.prediction << "," << r.points[j] << "," << p.truth << "," << csv_name(p.truth_name)
            << "," << p.truth_known << "," << fixed(p.iou, 3) << "," << p.name << ","
            << csv_name(p.best) << "," << fixed(p.score, 4) << "," << fixed(p.runner_up, 4) << ","
            << (p.colour < 0 ? "" : fixed(p.colour, 4)) << ","
            << (p.add_s < 0 ? "" : fixed(p.add_s, 4)) << "," << p.pose_ok << "\n";
      }
    }
  return csv.str();
}

std::string truths_csv(const Bench& b) {
  std::ostringstream csv;
  csv << "method,split,scene,label,name,catalogue,known,points,prediction,iou,answer,score\n";
  for (std::size_t si = 0; si < b.splits.size(); ++si)
    for (std::size_t mi = 0; mi < b.methods.size(); ++mi)
      for (const TruthRow& t : b.results[si][mi].truths)
        csv << '"' << b.methods[mi].label << "\"," << b.splits[si].name << "," << t.scene << ","
            << t.truth.label << "," << t.truth.name << "," << t.truth.catalogue << ","
            << t.truth.known << "," << t.truth.points.size() << "," << t.prediction << ","
            << fixed(t.iou, 3) << "," << csv_name(t.name) << "," << fixed(t.score, 4) << "\n";
  return csv.str();
}

}  // namespace proxseg::bench::scenebench
