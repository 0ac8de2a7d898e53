// real_bench (`make bench-real`): real YCB-Video scenes, each one fold (its frames are one scene
// seen several times), against a database of the 21 YCB-Video models (real_eval.hpp). Per fold
// and method: labelled objects (>= 200 pixels) segmented at IoU >= 0.5, named right, pose within
// ADD-S 10 % of the diameter, names given to no such object, leave-one-out (each object's model
// missing in turn: it must come out unknown, the others still named) and seconds per frame.
// proxseg's variants (--grid) are chosen on one fold and reported on the other; the peers run on
// the same frames: PCL LCCP segments, the Open3D FPFH + RANSAC + ICP and OpenCV PPF peers
// recognise proxseg's candidates, named with proxseg's rule (peer_naming.hpp). Writes
// OUT/real.md, real.json and objects.csv. Exit codes: 0 ok, 1 bad input, 2 usage.
// Usage: real_bench [--ycbv DIR] [--folds LIST] [--grid FILE] [--peers all|none] [--threads T]
//                   -o OUT [--json]
#include <proxseg/core/errors.hpp>
#include <proxseg/core/parameters.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/eval/real_eval.hpp>
#include <proxseg/eval/sensor_figures.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench_main.hpp"
#include "bench_util.hpp"
#ifdef PROXSEG_WITH_PEERS
#include "peer_naming.hpp"
#include "peers_pcl.hpp"
#include "peers_rec.hpp"
#endif

namespace {

using proxseg::InputError;
using proxseg::RealCounts;
using proxseg::bench::Clock;
using proxseg::bench::fixed;
using proxseg::bench::seconds_since;

struct Options {
  std::string ycbv = "../shared/data/ycbv", folds = "frames,video0001", grid, output;
  std::string peers = "all";
  int threads = 0, peer_ransac = 10000;
  bool json = false;
};

// A variant of proxseg's parameters (--grid: a JSON array of {"name", "segment": {key: value},
// "recognition": {key: value}}, keys as in `proxseg recognize --config`).
struct Variant {
  std::string name;
  proxseg::SegmentParams segment;
  proxseg::RecognitionParams recognition;
};

std::vector<Variant> read_grid(const std::string& path, const Options& o) {
  std::vector<Variant> out;
  nlohmann::json grid = nlohmann::json::array({{{"name", "default"}}});
  if (!path.empty()) {
    std::ifstream in(path);
    if (!in) throw InputError(path + ": cannot open (expected a JSON array of variants)");
    grid = nlohmann::json::parse(in, nullptr, false);
    if (!grid.is_array() || grid.empty())
      throw InputError(path + ": expected a non-empty JSON array of variants");
  }
  for (const auto& g : grid) {
    if (!g.is_object() || !g.contains("name") || !g["name"].is_string())
      throw InputError(path + ": every variant needs a \"name\" (string)");
    Variant v{g["name"].get<std::string>(), {}, {}};
    try {
      v.segment = proxseg::params_from_json(g.value("segment", nlohmann::json::object()));
      v.recognition =
          proxseg::recognition_params_from_json(g.value("recognition", nlohmann::json::object()));
      v.segment.threads = v.recognition.threads = o.threads;
      proxseg::validate(v.segment);
      proxseg::validate(v.recognition);
    } catch (const InputError& e) {
      throw InputError(path + ": variant " + v.name + ": " + e.what());
    }
    out.push_back(std::move(v));
  }
  return out;
}

// The frames of a fold, read once.
struct Fold {
  std::string name;
  std::vector<std::string> stems;
  std::vector<proxseg::YcbFrame> frames;
};

Fold read_fold(const std::string& ycbv, const std::string& name, const proxseg::YcbModels& models) {
  Fold f{name, {}, {}};
  const std::string dir = (std::filesystem::path(ycbv) / name).string();
  f.stems = proxseg::ycb_frame_stems(dir);
  for (const std::string& s : f.stems)
    f.frames.push_back(proxseg::read_ycb_frame(dir, s, models.classes));
  return f;
}

// One row of objects.csv.
struct ObjectRow {
  std::string fold, method, frame;
  proxseg::RealObjectScore score;
};

// Everything a method did on a fold.
struct FoldResult {
  RealCounts counts;
  std::vector<ObjectRow> rows;
  std::vector<std::string> notes;  // other names and leave-one-out failures, "frame: what"
};

using proxseg::DatabaseRecognizer;
using proxseg::FrameRecognizer;

FoldResult run_fold(const Fold& fold, const std::string& method, const FrameRecognizer& make,
                    const proxseg::Database& db, const proxseg::YcbModels& models) {
  FoldResult out;
  for (std::size_t k = 0; k < fold.frames.size(); ++k) {
    proxseg::RealFrameResult r =
        proxseg::evaluate_real_frame(fold.frames[k], fold.stems[k], make, db, models);
    out.counts += r.counts;
    for (const auto& o : r.objects) out.rows.push_back({fold.name, method, fold.stems[k], o});
    out.notes.insert(out.notes.end(), r.notes.begin(), r.notes.end());
  }
  return out;
}

#ifdef PROXSEG_WITH_PEERS
// Segmentation alone: the labelled objects a method's segments hold at IoU >= 0.5.
using Segmenter = std::function<std::vector<std::uint32_t>(const proxseg::Frame&)>;
FoldResult run_segmenter(const Fold& fold, const std::string& method, const Segmenter& segment) {
  FoldResult out;
  for (std::size_t k = 0; k < fold.frames.size(); ++k) {
    const auto start = Clock::now();
    const std::vector<std::uint32_t> labels = segment(fold.frames[k].frame);
    out.counts.seconds += seconds_since(start);
    ++out.counts.frames;
    for (const auto& s : proxseg::score_segments(fold.frames[k], labels)) {
      ++out.counts.objects;
      out.counts.segmented += s.segmented;
      out.rows.push_back({fold.name, method, fold.stems[k], s});
    }
  }
  return out;
}
#endif

#ifdef PROXSEG_WITH_PEERS
// A registration peer on proxseg's candidates (the default segmentation's selection, background
// left out): each described like proxseg's candidates, aligned to every view once and named with
// proxseg's rule; leave-one-out names the same alignments without the missing object's views.
using Aligner = std::function<std::vector<proxseg::peers::PeerAlignment>(const proxseg::Cloud&)>;
FrameRecognizer peer_method(const Aligner& align, const proxseg::Database& full,
                            const proxseg::RecognitionParams& rp, int threads) {
  return [align, &full, &rp, threads](const proxseg::YcbFrame& y) -> DatabaseRecognizer {
    struct Aligned {
      proxseg::SceneObject object;
      proxseg::Cloud cloud;
      std::vector<proxseg::peers::PeerAlignment> alignments;
    };
    auto candidates = std::make_shared<std::vector<Aligned>>();
    const proxseg::SegmentResult seg = proxseg::segment(y.frame, proxseg::SegmentParams{});
    for (const proxseg::Candidate& c : seg.selection.components) {
      if (c.background) continue;
      std::vector<Eigen::Vector3d> xyz;
      std::vector<proxseg::Rgb> rgb;
      for (int k : c.points) {
        xyz.push_back(y.frame.xyz[k].cast<double>());
        if (y.frame.rgb.size() == y.frame.size()) rgb.push_back(y.frame.rgb[k]);
      }
      Aligned a;
      try {
        a.cloud = proxseg::describe_candidate(xyz, full, rgb.empty() ? nullptr : &rgb);
      } catch (const InputError&) {
        continue;  // too small to describe: recognize_scene() makes no object of it either
      }
      a.object.points = c.points;
      a.object.centroid = a.cloud.centroid;
      a.alignments = align(a.cloud);
      candidates->push_back(std::move(a));
    }
    // The database given is the full one or the full one without one object.
    return [candidates, &full, &rp, threads](const proxseg::Database& db) {
      std::string missing;
      for (const std::string& o : full.objects())
        if (std::none_of(db.views.begin(), db.views.end(),
                         [&](const proxseg::ModelView& v) { return v.object == o; }))
          missing = o;
      std::vector<proxseg::SceneObject> out;
      for (const Aligned& a : *candidates) {
        const proxseg::peers::PeerAnswer p =
            proxseg::peers::name_alignments(a.cloud, a.alignments, full, rp, threads, missing);
        proxseg::SceneObject o = a.object;
        o.recognition.name = p.name;
        o.recognition.best.object = p.best;
        o.recognition.best.pose = p.pose;
        o.recognition.best.score = p.score;
        out.push_back(std::move(o));
      }
      return out;
    };
  };
}
#endif

// The row of a fold's table.
std::string table_row(const std::string& method, const RealCounts& c, bool recognition) {
  const auto of = [](int a, int b) { return std::to_string(a) + "/" + std::to_string(b); };
  std::ostringstream s;
  s << "| " << method << " | " << of(c.segmented, c.objects) << " | ";
  if (recognition)
    s << of(c.named, c.objects) << " | " << of(c.pose_ok, c.named) << " | " << c.other_names
      << " | " << of(c.loo_missing_unknown, c.loo_cases) << " | "
      << of(c.loo_others_named, c.loo_others);
  else
    s << "- | - | - | - | -";
  s << " | " << fixed(c.frames ? c.seconds / c.frames : 0, 2) << " |\n";
  return s.str();
}

// How a variant does on a fold, for the choice on the other fold: the shares of objects named
// right, of missing objects left unknown and of others still named, less a share for each other
// name (an answer that is wrong counts against it as much as one missed).
double objective(const RealCounts& c) {
  const auto share = [](int a, int b) { return b ? double(a) / b : 0.0; };
  return share(c.named, c.objects) + share(c.loo_missing_unknown, c.loo_cases) +
         share(c.loo_others_named, c.loo_others) - share(c.other_names, c.objects);
}

}  // namespace

namespace {

std::vector<std::string> split_list(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  if (out.empty()) throw CLI::ValidationError("--folds: expected a comma-separated list");
  return out;
}

nlohmann::json counts_json(const RealCounts& c) {
  return {{"frames", c.frames},
          {"objects", c.objects},
          {"segmented", c.segmented},
          {"named", c.named},
          {"pose_ok", c.pose_ok},
          {"other_names", c.other_names},
          {"loo_cases", c.loo_cases},
          {"loo_missing_unknown", c.loo_missing_unknown},
          {"loo_others", c.loo_others},
          {"loo_others_named", c.loo_others_named},
          {"seconds_per_frame", c.frames ? c.seconds / c.frames : 0}};
}

// The methods' results on one fold, in table order.
struct FoldReport {
  std::string fold;
  std::vector<std::pair<std::string, FoldResult>> methods;
  std::vector<bool> recognition;  // per method: it names objects (else segments only)
};

// proxseg's variants on every fold, then for each fold the variant chosen on the others.
std::vector<std::pair<std::string, FoldResult>> proxseg_cross_fold(
    const std::vector<Fold>& folds, const std::vector<Variant>& variants,
    const proxseg::Database& db, const proxseg::YcbModels& models, nlohmann::json& grid_json) {
  std::vector<std::vector<FoldResult>> results(variants.size());
  for (std::size_t v = 0; v < variants.size(); ++v)
    for (const Fold& f : folds) {
      std::cerr << "real_bench: proxseg " << variants[v].name << " on " << f.name << "\n";
      results[v].push_back(run_fold(
          f, "proxseg", proxseg::proxseg_recognizer(variants[v].segment, variants[v].recognition),
          db, models));
      grid_json.push_back({{"variant", variants[v].name},
                           {"fold", f.name},
                           {"objective", objective(results[v].back().counts)},
                           {"counts", counts_json(results[v].back().counts)}});
    }
  std::vector<std::pair<std::string, FoldResult>> out;
  for (std::size_t f = 0; f < folds.size(); ++f) {
    std::size_t chosen = 0;
    double best = -1e9;
    for (std::size_t v = 0; v < variants.size(); ++v) {
      double others = 0;
      for (std::size_t g = 0; g < folds.size(); ++g)
        if (g != f || folds.size() == 1) others += objective(results[v][g].counts);
      if (others > best) best = others, chosen = v;
    }
    out.emplace_back(variants.size() > 1 ? "proxseg (" + variants[chosen].name + ")" : "proxseg",
                     results[chosen][f]);
  }
  return out;
}

// The sensor's figures of each fold (sensor_figures.hpp): what a generated scene should match.
std::string sensor_markdown(const std::vector<Fold>& folds, const proxseg::YcbModels& models) {
  std::ostringstream md;
  md << "Sensor figures measured on the folds (docs/method.md \"Real sensors\"): distance of an "
        "object's points to its model at the true pose per metre of range (median over the "
        "objects of each frame), missing returns on labelled pixels within 3 px of another label "
        "and inside, and the median axial RMS of planar 14 x 14 px patches by range (bins of "
        ">= 20 patches):\n\n| fold | objects' range, m | residual p50, mm/m | residual p90, "
        "mm/m | missing at borders | missing inside | planar noise, mm (range m) |\n"
        "|---|---|---|---|---|---|---|\n";
  for (const Fold& f : folds) {
    proxseg::SensorFigures s;
    for (const auto& y : f.frames) s += proxseg::measure_sensor(y, models);
    std::vector<double> range, p50, p90;
    for (const auto& r : s.residuals) {
      if (!(r.range > 0)) continue;
      range.push_back(r.range);
      p50.push_back(1000 * r.p50 / r.range);
      p90.push_back(1000 * r.p90 / r.range);
    }
    const auto median = [](std::vector<double> v) {
      if (v.empty()) return 0.0;
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    const auto [lo, hi] = std::minmax_element(range.begin(), range.end());
    md << "| " << f.name << " | " << (range.empty() ? "-" : fixed(*lo, 2) + "-" + fixed(*hi, 2))
       << " | " << fixed(median(p50), 1) << " | " << fixed(median(p90), 1) << " | "
       << proxseg::bench::percent(s.border ? double(s.border_missing) / s.border : 0) << " % | "
       << proxseg::bench::percent(s.inside ? double(s.inside_missing) / s.inside : 0) << " % | ";
    for (std::size_t b = 0; b < s.patches.size(); ++b)
      if (s.patches[b] >= 20)
        md << fixed(1000 * s.patch_rms[b], 2) << " (" << fixed(0.1 * b + 0.05, 2) << ") ";
    md << "|\n";
  }
  return md.str() + "\n";
}

// Every variant on every fold: what each rule buys on real frames.
std::string grid_markdown(const nlohmann::json& grid) {
  std::ostringstream md;
  if (grid.size() <= 2) return "";
  md << "proxseg's variants (bench/real_grid.json) on each fold: named, other names, left out "
        "unknown, left out others named:\n\n| variant | fold | named | other names | left out: "
        "unknown | left out: others named | s/frame |\n|---|---|---|---|---|---|---|\n";
  for (const auto& g : grid) {
    const auto& c = g["counts"];
    const auto of = [&](const char* a, const char* b) {
      return std::to_string(c[a].get<int>()) + "/" + std::to_string(c[b].get<int>());
    };
    md << "| " << g["variant"].get<std::string>() << " | " << g["fold"].get<std::string>() << " | "
       << of("named", "objects") << " | " << c["other_names"].get<int>() << " | "
       << of("loo_missing_unknown", "loo_cases") << " | " << of("loo_others_named", "loo_others")
       << " | " << fixed(c["seconds_per_frame"].get<double>(), 2) << " |\n";
  }
  return md.str() + "\n";
}

std::string markdown(const std::vector<FoldReport>& reports, const nlohmann::json& grid,
                     const std::string& sensor, const Options& o, std::size_t variants) {
  std::ostringstream md;
  md << "## Real scenes (YCB-Video, each video one fold)\n\n"
     << "`make bench-real` at commit " << proxseg::bench::git_commit() << ", "
     << proxseg::bench::utc_now() << ", " << proxseg::bench::machine() << " (load "
     << proxseg::bench::load_averages() << "). Database: the 21 YCB-Video models (`" << o.ycbv
     << "/models/*/points.xyz`, no colour). Labelled objects of >= 200 valid pixels; "
     << "segmented = a candidate at IoU >= 0.5; named = that object carries the right name; "
     << "pose = ADD-S under 10 % of the diameter (of those named); other names = names on no "
     << "labelled object of that name; leave-one-out = each object's model missing in turn "
     << "(missing left unknown; the others still named). "
     << (variants > 1 ? "proxseg's variant for a fold is chosen on the other fold. " : "")
     << "The peers recognise proxseg's candidates with proxseg's naming rule; s/frame is in "
        "process (segment + recognise).\n\n";
  md << sensor << grid_markdown(grid);
  for (const FoldReport& r : reports) {
    md << "**" << r.fold << "**\n\n"
       << "| method | segmented | named | pose ok | other names | left out: unknown | left "
          "out: others named | s/frame |\n|---|---|---|---|---|---|---|---|\n";
    for (std::size_t m = 0; m < r.methods.size(); ++m)
      md << table_row(r.methods[m].first, r.methods[m].second.counts, r.recognition[m]);
    md << "\n";
    const FoldResult& proxseg = r.methods.front().second;
    if (!proxseg.notes.empty()) {
      md << "proxseg's misses on " << r.fold << ":\n";
      for (const std::string& n : proxseg.notes) md << "- " << n << "\n";
      md << "\n";
    }
  }
  return md.str();
}

std::string objects_csv(const std::vector<FoldReport>& reports) {
  std::ostringstream csv;
  csv << "fold,method,frame,object,pixels,iou,segmented,named,best,score,runner_up,"
         "runner_up_score,add_s,pose_ok\n";
  for (const FoldReport& r : reports)
    for (const auto& [method, result] : r.methods)
      for (const ObjectRow& row : result.rows)
        csv << row.fold << ",\"" << method << "\"," << row.frame << "," << row.score.object << ","
            << row.score.pixels << "," << fixed(row.score.iou, 3) << "," << row.score.segmented
            << "," << row.score.named << "," << row.score.best << "," << fixed(row.score.score, 3)
            << "," << row.score.runner_up << "," << fixed(row.score.runner_up_score, 3) << ","
            << fixed(row.score.add_s, 4) << "," << row.score.pose_ok << "\n";
  return csv.str();
}

void add_peers(std::vector<FoldReport>& reports, const std::vector<Fold>& folds,
               const proxseg::Database& db, const proxseg::YcbModels& models, const Options& o) {
#ifdef PROXSEG_WITH_PEERS
  static const proxseg::RecognitionParams rp;  // the naming rule, as proxseg's default
  const int team = o.threads > 0 ? o.threads : omp_get_max_threads();
  proxseg::peers::Open3dParams o3d;
  o3d.ransac_iterations = o.peer_ransac;  // as scene_bench: 10k per view and candidate
  const proxseg::peers::Open3dPeer open3d(db, o3d, o.threads);
  const std::string o3d_name =
      "Open3D FPFH + RANSAC " + std::to_string(o.peer_ransac / 1000) + "k + ICP";
#ifdef PROXSEG_WITH_PPF
  const proxseg::peers::PpfPeer ppf(db, proxseg::peers::PpfParams{}, o.threads);
#endif
  for (std::size_t f = 0; f < folds.size(); ++f) {
    std::cerr << "real_bench: peers on " << folds[f].name << "\n";
    reports[f].methods.emplace_back(
        "PCL LCCP", run_segmenter(folds[f], "PCL LCCP", [](const proxseg::Frame& frame) {
          return proxseg::peers::lccp(frame);
        }));
    reports[f].recognition.push_back(false);
    const Aligner by_open3d = [&](const proxseg::Cloud& c) {
      return open3d.align(c, static_cast<int>(rp.seed));
    };
    reports[f].methods.emplace_back(
        o3d_name, run_fold(folds[f], o3d_name, peer_method(by_open3d, db, rp, team), db, models));
    reports[f].recognition.push_back(true);
#ifdef PROXSEG_WITH_PPF
    const Aligner by_ppf = [&](const proxseg::Cloud& c) { return ppf.align(c, 0); };
    reports[f].methods.emplace_back(
        "OpenCV PPF + ICP",
        run_fold(folds[f], "OpenCV PPF + ICP", peer_method(by_ppf, db, rp, team), db, models));
    reports[f].recognition.push_back(true);
#endif
  }
#else
  (void)reports, (void)folds, (void)db, (void)models;
  if (o.peers == "all") std::cerr << "real_bench: built without PCL: no peers\n";
#endif
}

int run(const Options& o) {
  namespace fs = std::filesystem;
  if (o.peers != "all" && o.peers != "none")
    throw CLI::ValidationError("--peers: expected all or none, got '" + o.peers + "'");
  if (o.threads > 0) omp_set_num_threads(o.threads);
  const fs::path out(o.output);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out))
    throw InputError(o.output + ": cannot create the output folder (" + ec.message() + ")");
  const std::vector<Variant> variants = read_grid(o.grid, o);
  const proxseg::YcbModels models = proxseg::read_ycb_models(o.ycbv);
  fs::remove_all(out / "db");
  const proxseg::Database db = proxseg::ycb_database(models, (out / "db").string());
  std::vector<Fold> folds;
  for (const std::string& name : split_list(o.folds))
    folds.push_back(read_fold(o.ycbv, name, models));

  nlohmann::json grid_json = nlohmann::json::array();
  std::vector<FoldReport> reports;
  auto chosen = proxseg_cross_fold(folds, variants, db, models, grid_json);
  for (std::size_t f = 0; f < folds.size(); ++f)
    reports.push_back({folds[f].name, {std::move(chosen[f])}, {true}});
  if (o.peers == "all") add_peers(reports, folds, db, models, o);

  nlohmann::json summary = {{"commit", proxseg::bench::git_commit()},
                            {"grid", grid_json},
                            {"folds", nlohmann::json::array()}};
  for (const FoldReport& r : reports) {
    nlohmann::json methods = nlohmann::json::array();
    for (const auto& [name, result] : r.methods)
      methods.push_back(
          {{"method", name}, {"counts", counts_json(result.counts)}, {"notes", result.notes}});
    summary["folds"].push_back({{"fold", r.fold}, {"methods", methods}});
  }
  const std::string md =
      markdown(reports, grid_json, sensor_markdown(folds, models), o, variants.size());
  return proxseg::bench::finish(out,
                                {{"real.md", md},
                                 {"real.json", summary.dump(2) + "\n"},
                                 {"objects.csv", objects_csv(reports)}},
                                summary, md, o.json);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Real YCB-Video scenes as folds: proxseg and the peers (make bench-real)"};
  app.add_option("--ycbv", o.ycbv, "The YCB-Video folder (classes.txt, models/, the folds)")
      ->capture_default_str();
  app.add_option("--folds", o.folds, "Frame folders of --ycbv, each one fold")
      ->capture_default_str();
  app.add_option("--grid", o.grid,
                 "JSON array of proxseg variants ({name, segment: {}, recognition: {}}); each "
                 "fold is reported with the variant chosen on the others");
  app.add_option("--peers", o.peers, "all (PCL LCCP, Open3D, OpenCV PPF) or none")
      ->capture_default_str();
  app.add_option("--peer-ransac", o.peer_ransac, "Open3D RANSAC iterations per view")
      ->capture_default_str();
  app.add_option("--threads", o.threads, "Threads (0 = all cores)")->capture_default_str();
  app.add_option("-o,--output", o.output, "Output folder (real.md, real.json, objects.csv)")
      ->required();
  app.add_flag("--json", o.json, "Print the summary as JSON instead of the markdown");
  return proxseg::bench::main_of("real_bench", app, argc, argv, [&] { return run(o); });
}
