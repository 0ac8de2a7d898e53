// db_scale_bench's report (db_scale_bench.hpp): dbscale.json and dbscale.md from what a run
// measured: per row the rates, times and what took the answers; per size the database file's
// processes; the cost of the largest database against the smallest.
#include <proxseg/io/params.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bench_util.hpp"
#include "db_scale_bench.hpp"

namespace proxseg::bench::dbscale {
namespace {

namespace fs = std::filesystem;

struct Summary {
  Rates rates;
  double describe_ms = 0, recognize_ms = 0, views_aligned = 0, best_right = 0, shortlisted = 0,
         best_rank = 0;
  std::map<std::string, int> wrong, unknown_runner_up;
};

// Over the first n answers of a row.
Summary summarise(const Measured& run, const Row& r, std::size_t n) {
  const std::vector<TestView>& tests = run.tests;
  const std::vector<TestObject>& tested = run.tested;
  const double m = run.rp.min_score;
  n = std::min(n, r.answers.size());
  Summary s;
  const std::vector<Answer> answers(r.answers.begin(), r.answers.begin() + n);
  s.rates = rates(tests, answers, tested, m);
  for (std::size_t i = 0; i < n; ++i) {
    const Answer& a = r.answers[i];
    const Extra& e = r.extra[i];
    const std::string& truth = tested[tests[i].object].name;
    s.describe_ms += a.describe_ms;
    s.recognize_ms += e.recognize_ms;
    s.views_aligned += e.views_aligned;
    s.best_right += e.best == truth;
    s.shortlisted += e.truth_shortlisted;
    s.best_rank += e.best_rank;
    if (!a.best.empty() && a.score >= m && a.best != truth) ++s.wrong[a.best];
    if (a.best.empty() || a.score < m) {
      const std::string& in_the_way = e.best == truth ? e.runner_up : e.best;
      if (!in_the_way.empty()) ++s.unknown_runner_up[in_the_way];
    }
  }
  if (n > 0)
    for (double* x : {&s.describe_ms, &s.recognize_ms, &s.views_aligned, &s.best_right,
                      &s.shortlisted, &s.best_rank})
      *x /= static_cast<double>(n);
  return s;
}

const Row* row_of(const Measured& run, int views, int shortlist) {
  for (const Row& r : run.rows)
    if (r.views == views && r.shortlist == shortlist) return &r;
  return nullptr;
}

nlohmann::json counts_json(const std::map<std::string, int>& counts) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [k, n] : counts) j[k] = n;
  return j;
}

// "ape-hue150 (look-alike) 3, box-12 (box) 1", most first; "-" when empty.
std::string counts_md(const std::map<std::string, int>& counts,
                      const std::map<std::string, std::string>& kinds) {
  std::vector<std::pair<std::string, int>> v(counts.begin(), counts.end());
  std::stable_sort(v.begin(), v.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  std::string s;
  for (const auto& [name, n] : v) {
    const auto k = kinds.find(name);
    s += (s.empty() ? "" : ", ") + name + " (" + (k == kinds.end() ? "?" : k->second) + ") " +
         std::to_string(n);
  }
  return s.empty() ? "-" : s;
}

// The acceptance: the cost of the largest database against the smallest, shortlist default (and
// every view, where both sizes have those rows).
struct CostRatio {
  const Row *small = nullptr, *large = nullptr, *small_every = nullptr, *large_every = nullptr;
  double ratio = 0, ratio_every = 0;
};

CostRatio cost_ratio(const Measured& run) {
  CostRatio c;
  c.small = row_of(run, run.sizes.front(), run.rp.shortlist);
  c.large = row_of(run, run.sizes.back(), run.rp.shortlist);
  if (c.small && c.large)
    c.ratio = summarise(run, *c.large, c.large->answers.size()).rates.mean_ms /
              summarise(run, *c.small, c.small->answers.size()).rates.mean_ms;
  c.small_every = row_of(run, run.sizes.front(), 0);
  c.large_every = row_of(run, run.sizes.back(), 0);
  if (c.small_every && c.large_every)
    c.ratio_every = summarise(run, *c.large_every, run.all_tests).rates.mean_ms /
                    summarise(run, *c.small_every, run.all_tests).rates.mean_ms;
  return c;
}

nlohmann::json parameters_json(const Options& o, const Measured& run) {
  const TestSetParams& tp = run.tp;
  return {{"models", o.models},
          {"views_per_object", o.views},
          {"sizes", run.sizes},
          {"tests", run.tests.size()},
          {"all_view_tests", run.all_tests},
          {"test_colours", run.coloured},
          {"seed", o.seed},
          {"threads", run.team},
          {"test_set",
           {{"min_distance", tp.min_distance},
            {"max_distance", tp.max_distance},
            {"depth_noise", tp.depth_noise},
            {"disparity_step", tp.disparity_step},
            {"min_angle_to_view_deg", tp.min_angle_to_view_deg}}},
          {"recognition", to_json(run.rp)}};
}

nlohmann::json objects_json(const Measured& run) {
  nlohmann::json objects = nlohmann::json::array();
  for (std::size_t i = 0; i < run.objects.size(); ++i) {
    nlohmann::json j = {{"name", run.objects[i].name}, {"file", run.objects[i].file}};
    if (i < run.tested.size()) {
      j["kind"] = "tested";
    } else {
      const Distractor& d = run.extra_objects[i - run.tested.size()];
      j["kind"] = d.kind;
      j["texture"] = d.texture;
      j["size_m"] = {d.size.x(), d.size.y(), d.size.z()};
      if (d.original >= 0) {
        j["hue_turn_deg"] = 360 * d.hue_turn;
        j["mean_chroma"] = d.chroma;
      }
    }
    objects.push_back(j);
  }
  return objects;
}

nlohmann::json rows_json(const Measured& run) {
  nlohmann::json rows = nlohmann::json::array();
  for (const Row& r : run.rows) {
    const Summary s = summarise(run, r, r.answers.size());
    nlohmann::json j = {
        {"views", r.views},
        {"objects", r.objects},
        {"lookalikes", r.lookalikes},
        {"shortlist", r.shortlist},
        {"tests", s.rates.tests},
        {"tp_rate", s.rates.tp_rate()},
        {"fp_rate", s.rates.fp_rate()},
        {"unknown_rate", s.rates.tests ? double(s.rates.unknown) / s.rates.tests : 0.0},
        {"pose_rate", s.rates.pose_rate()},
        {"best_right_rate", s.best_right},
        {"mean_ms", s.rates.mean_ms},
        {"mean_describe_ms", s.describe_ms},
        {"mean_recognize_ms", s.recognize_ms},
        {"mean_views_aligned", s.views_aligned},
        {"wrong_answers", counts_json(s.wrong)},
        {"unknown_runner_up", counts_json(s.unknown_runner_up)},
        {"loadavg_before", r.load_before},
        {"loadavg_after", r.load_after}};
    if (r.shortlist > 0) {
      j["truth_shortlisted_rate"] = s.shortlisted;
      j["mean_best_view_rank"] = s.best_rank;
    }
    rows.push_back(j);
  }
  return rows;
}

nlohmann::json processes_json(const Measured& run) {
  nlohmann::json processes = nlohmann::json::array();
  for (const ProcessRow& p : run.process_rows)
    processes.push_back({{"views", p.views},
                         {"file_mb", p.file_mb},
                         {"open_ms", p.open_ms},
                         {"open_rss_mb", p.open_rss_mb},
                         {"object_wall_s", p.wall_s},
                         {"object_cpu_s", p.cpu_s},
                         {"object_rss_mb", p.rss_mb},
                         {"object_wall_ratio", p.wall_ratio},
                         {"object_cpu_ratio", p.cpu_ratio},
                         {"tests", p.tests},
                         {"tp", p.tp}});
  return processes;
}

void md_intro(std::ostream& md, const Options& o, const Measured& run) {
  const std::vector<int>& sizes = run.sizes;
  const RecognitionParams& rp = run.rp;
  const TestSetParams& tp = run.tp;
  const double m = rp.min_score;
  int n_box = 0, n_cylinder = 0, n_lookalike = 0;
  for (const Distractor& d : run.extra_objects)
    (d.kind == "box" ? n_box : d.kind == "cylinder" ? n_cylinder : n_lookalike) += 1;
  md << "## Recognition against database size (" << sizes.front() << "-" << sizes.back()
     << " views)\n\n"
     << "Generated by `make bench-dbscale` (bench/db_scale_bench.cpp) at commit " << git_commit()
     << " on " << machine() << ", " << utc_now() << "; seed " << o.seed << ", " << run.team
     << " threads. Load average (1, 5, 15 min): " << run.load_start << " at the start, "
     << run.load_end
     << " at the end (the machine is shared: times compare within this run only).\n\n"
     << "Objects tested: the " << run.tested.size() << " meshes of `"
     << fs::path(o.models).filename().string()
     << "` (LINEMOD). Distractors fill each database: " << n_box << " boxes and " << n_cylinder
     << " cylinders (seeded, 3-25 cm, plain or striped, banded, checkered in two contrasting "
        "colours) and "
     << n_lookalike
     << " look-alikes (a tested mesh with every hue turned by 120-240 degrees, nearly grey "
        "meshes also tinted to saturation "
     << fixed(kTintSaturation, 1) << ": same shape, other colour), one every 7th distractor. "
     << o.views << " noiseless render_views() per object; each database is a prefix of the next. "
     << "Tests: " << run.tests.size() << " make_test_views() of the tested objects (round-robin), "
     << (run.coloured ? "with their rendered colours" : "without colour") << ", "
     << fixed(tp.min_distance, 1) << "-" << fixed(tp.max_distance, 1)
     << " m, Kinect-like noise, at least " << fixed(tp.min_angle_to_view_deg, 0)
     << " degrees from every database viewpoint. Each test: describe_candidate() + recognize() "
        "with the default RecognitionParams (shortlist "
     << rp.shortlist << ", min_score " << fixed(m, 2) << ", min_margin " << fixed(rp.min_margin, 2)
     << "); the shortlist 0 rows align every view (the paper's way) on the first " << run.all_tests
     << " tests only (their cost grows with the views). TP: recognize() names the object; FP: it "
        "names another; unknown: it answers \"unknown\" (min_score or min_margin); pose ok: "
        "named right and within 2 cm and 10 degrees. Best view right: the best view's object "
        "before the thresholds. Shortlisted: a view of the right object was among the views "
        "aligned. Best view's rank: its place in the shortlist (1 = nearest by signature), "
        "mean. ms: describe + recognition, wall, per candidate.\n\n";
}

void md_rows(std::ostream& md, const Measured& run) {
  md << "| views | objects (look-alikes) | shortlist | tests | views aligned | ms / candidate | TP "
        "(%) | FP (%) | unknown (%) | pose ok (%) | best view right (%) | shortlisted (%) | best "
        "view's rank | load before / after |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : run.rows) {
    const Summary s = summarise(run, r, r.answers.size());
    md << "| " << r.views << " | " << r.objects << " (" << r.lookalikes << ") | "
       << (r.shortlist > 0 ? std::to_string(r.shortlist) : "0 (every view)") << " | "
       << s.rates.tests << " | " << fixed(s.views_aligned, 1) << " | " << fixed(s.rates.mean_ms, 0)
       << " | " << percent(s.rates.tp_rate()) << " | " << percent(s.rates.fp_rate()) << " | "
       << percent(s.rates.tests ? double(s.rates.unknown) / s.rates.tests : 0) << " | "
       << percent(s.rates.pose_rate()) << " | " << percent(s.best_right) << " | "
       << (r.shortlist > 0 ? percent(s.shortlisted) : "-") << " | "
       << (r.shortlist > 0 ? fixed(s.best_rank, 1) : "-") << " | "
       << r.load_before.substr(0, r.load_before.find(' ')) << " / "
       << r.load_after.substr(0, r.load_after.find(' ')) << " |\n";
  }
}

void md_cost_ratio(std::ostream& md, const Measured& run) {
  const CostRatio c = cost_ratio(run);
  const std::vector<int>& sizes = run.sizes;
  if (c.small && c.large && c.small != c.large)
    md << "\nCost of " << sizes.back() << " views against " << sizes.front() << " (shortlist "
       << run.rp.shortlist << "): ms(" << sizes.back() << ") / ms(" << sizes.front()
       << ") = " << fixed(c.ratio, 2)
       << " (acceptance: at most 2: " << (c.ratio <= 2 ? "met" : "not met") << ")"
       << (c.small_every && c.large_every && c.small_every != c.large_every
               ? "; every view: " + fixed(c.ratio_every, 2)
               : std::string())
       << ".\n";
}

void md_processes(std::ostream& md, const Measured& run) {
  if (run.process_rows.empty()) return;
  const ProcessRow& base = run.process_rows.front();
  md << "\n### The database file, one process per question\n\n"
     << "Each size stored in one database file (`proxseg db` format, docs/database.md). Open: "
        "a fresh process runs load_database() (median of 5; RSS: the process's peak after "
        "opening, libraries included). recognize --object: `proxseg recognize --object TEST "
        "--db DB --json --threads 2` on the first "
     << base.tests
     << " test views (as PCD files with their colours), one process each: median wall and "
        "CPU (user + system) from spawn to exit, the largest peak RSS, and the answers named "
        "right (TP, min_score "
     << fixed(run.rp.min_score, 2)
     << "). x smallest: the median ratio to the smallest database's run of the same test just "
        "before (paired, so that the machine's drift between sizes cancels).\n\n"
     << "| views | file (MB) | open (ms) | RSS after open (MB) | recognize --object wall (s) | "
        "x smallest | CPU (s) | x smallest | peak RSS (MB) | TP |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const ProcessRow& p : run.process_rows)
    md << "| " << p.views << " | " << fixed(p.file_mb, 0) << " | " << fixed(p.open_ms, 1) << " | "
       << fixed(p.open_rss_mb, 0) << " | " << fixed(p.wall_s, 2) << " | " << fixed(p.wall_ratio, 2)
       << " | " << fixed(p.cpu_s, 2) << " | " << fixed(p.cpu_ratio, 2) << " | "
       << fixed(p.rss_mb, 0) << " | " << p.tp << "/" << p.tests << " |\n";
}

void md_every_view(std::ostream& md, const Measured& run) {
  if (run.all_tests <= 0) return;
  const int all_tests = run.all_tests;
  md << "\n### Shortlist against every view, on the same first " << all_tests << " tests\n\n"
     << "| views | TP shortlist / every view (%) | FP (%) | unknown (%) | pose ok (%) | ms "
        "shortlist / every view | speed-up |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (int size : run.sizes) {
    const Row* d = row_of(run, size, run.rp.shortlist);
    const Row* e = row_of(run, size, 0);
    if (!d || !e) continue;
    const Summary a = summarise(run, *d, all_tests), b = summarise(run, *e, all_tests);
    const auto unk = [](const Rates& x) { return x.tests ? double(x.unknown) / x.tests : 0.0; };
    md << "| " << size << " | " << percent(a.rates.tp_rate()) << " / " << percent(b.rates.tp_rate())
       << " | " << percent(a.rates.fp_rate()) << " / " << percent(b.rates.fp_rate()) << " | "
       << percent(unk(a.rates)) << " / " << percent(unk(b.rates)) << " | "
       << percent(a.rates.pose_rate()) << " / " << percent(b.rates.pose_rate()) << " | "
       << fixed(a.rates.mean_ms, 0) << " / " << fixed(b.rates.mean_ms, 0) << " | "
       << fixed(b.rates.mean_ms / a.rates.mean_ms, 1) << " |\n";
  }
}

void md_in_the_way(std::ostream& md, const Measured& run) {
  md << "\n### What takes the answers\n\n"
     << "Per row: the objects named wrongly (FP), and for the unknown answers the object that "
        "stood in the way (the wrong best view, or the runner-up of a right one).\n\n"
     << "| views | shortlist | wrong answers | unknown: in the way |\n|---|---|---|---|\n";
  for (const Row& r : run.rows) {
    const Summary s = summarise(run, r, r.answers.size());
    md << "| " << r.views << " | " << r.shortlist << " | " << counts_md(s.wrong, run.kinds) << " | "
       << counts_md(s.unknown_runner_up, run.kinds) << " |\n";
  }
  md << "\nEvery object (kind, texture, size, hue turn) and row (stage times, load) is in "
        "`dbscale.json`.\n";
}

}  // namespace

nlohmann::json report_json(const Options& o, const Measured& run) {
  nlohmann::json summary;
  summary["parameters"] = parameters_json(o, run);
  summary["machine"] = machine();
  summary["date"] = utc_now();
  summary["commit"] = git_commit();
  summary["loadavg"] = {{"start", run.load_start}, {"end", run.load_end}};
  summary["objects"] = objects_json(run);
  summary["rows"] = rows_json(run);
  const CostRatio c = cost_ratio(run);
  if (c.small && c.large)
    summary["cost_ratio"] = {{"views", {run.sizes.front(), run.sizes.back()}}, {"ratio", c.ratio}};
  if (c.small_every && c.large_every) summary["cost_ratio_every_view"] = c.ratio_every;
  summary["processes"] = processes_json(run);
  return summary;
}

std::string report_markdown(const Options& o, const Measured& run) {
  std::ostringstream md;
  md_intro(md, o, run);
  md_rows(md, run);
  md_cost_ratio(md, run);
  md_processes(md, run);
  md_every_view(md, run);
  md_in_the_way(md, run);
  return md.str();
}

}  // namespace proxseg::bench::dbscale
