// rec_bench's tables (rec_bench.hpp): summary.json (parameters, per row the rates of each set
// and bin and the stage times, the paper's figures), tests.csv (per test and row), curves.csv and
// the ROC and precision-recall curves.
#include <proxseg/eval/pose_error.hpp>
#include <proxseg/io/params.hpp>

#include <algorithm>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "rec_bench.hpp"

namespace proxseg::bench::recbench {
namespace {

using Which = std::function<bool(const TestView&)>;

Which in_bin(int b) {
  return [b](const TestView& t) { return t.bin == b; };
}

nlohmann::json rates_json(const Rates& r) {
  return {
      {"tests", r.tests},           {"tp_rate", r.tp_rate()},
      {"fp_rate", r.fp_rate()},     {"unknown_rate", r.tests ? double(r.unknown) / r.tests : 0.0},
      {"pose_rate", r.pose_rate()}, {"mean_ms", r.mean_ms}};
}

nlohmann::json parameters_json(const Options& o, const Bench& b) {
  nlohmann::json objects = nlohmann::json::array();
  for (const auto& ob : b.objects)
    objects.push_back({{"name", ob.name},
                       {"file", ob.file},
                       {"symmetries", static_cast<int>(ob.symmetries.size()) - 1}});
  const TestSetParams& tp = b.tp;
  return {{"models", o.models},
          {"objects", objects},
          {"views", o.views},
          {"database_views", b.db.views.size()},
          {"descriptor",
           {{"voxel_size", b.descriptor.voxel_size},
            {"normal_radius", b.descriptor.normal_radius},
            {"fpfh_radii", b.descriptor.fpfh_radii}}},
          {"test_set",
           {{"tests", b.clean.size()},
            {"occluded_tests", b.occluded.size()},
            {"seed", o.seed},
            {"min_distance", tp.min_distance},
            {"max_distance", tp.max_distance},
            {"depth_noise", tp.depth_noise},
            {"disparity_step", tp.disparity_step},
            {"min_angle_to_view_deg", tp.min_angle_to_view_deg}}},
          {"recognition", to_json(b.rp)},
          {"sweep_tests", b.sweep_tests},
          {"peer_tests", o.peer_tests},
          {"threads", b.team}};
}

// A row's rates on each set and occlusion bin, and its mean stage times on the clean set.
nlohmann::json method_json(const Bench& b, const Row& r) {
  const double m = b.rp.min_score;
  const std::vector<TestView> c = subset(b.clean, r.clean.size()),
                              oc = subset(b.occluded, r.occluded.size());
  nlohmann::json j = {{"label", r.label},
                      {"kind", r.kind},
                      {"views", r.views},
                      {"fpfh_radii", r.radii},
                      {"ransac_iterations", r.ransac},
                      {"icp_iterations", r.icp},
                      {"train_ms", r.train_ms},
                      {"paper_analogue", r.paper < 0 ? "" : kPaperTable2[r.paper].name}};
  j["sets"]["clean"] = rates_json(rates(c, r.clean, b.objects, m));
  double stage[4] = {0, 0, 0, 0};
  for (const Answer& a : r.clean) {
    stage[0] += a.describe_ms / r.clean.size(), stage[1] += a.ransac_ms / r.clean.size();
    stage[2] += a.icp_ms / r.clean.size(), stage[3] += a.score_ms / r.clean.size();
  }
  j["sets"]["clean"]["stage_ms"] = {
      {"describe", stage[0]}, {"ransac", stage[1]}, {"icp", stage[2]}, {"score", stage[3]}};
  if (!oc.empty()) {
    j["sets"]["occluded"] = rates_json(rates(oc, r.occluded, b.objects, m));
    for (std::size_t k = 0; k < b.bins.size(); ++k)
      j["sets"][bin_name(b.bins[k])] =
          rates_json(rates(oc, r.occluded, b.objects, m, in_bin(static_cast<int>(k))));
  }
  return j;
}

nlohmann::json paper_json() {
  nlohmann::json paper;
  paper["table2"] = nlohmann::json::array();
  for (const PaperTest& p : kPaperTable2)
    paper["table2"].push_back({{"test", p.name},
                               {"views", p.views},
                               {"radii_mm", p.radii},
                               {"ransac_iterations", p.ransac},
                               {"icp_iterations", p.icp},
                               {"tp_rate", p.tp / 100.0},
                               {"fp_rate", p.fp / 100.0}});
  paper["table3_tp_rate"] = nlohmann::json::array();
  for (int tp3 : kPaperTable3Tp) paper["table3_tp_rate"].push_back(tp3 / 100.0);
  return paper;
}

// tests.csv's lines of row r on one set.
void csv_rows(const Bench& b, const Row& r, const char* set, const std::vector<TestView>& tv,
              const std::vector<Answer>& answers, std::ostream& csv) {
  const double m = b.rp.min_score;
  for (std::size_t i = 0; i < answers.size(); ++i) {
    const TestView& t = tv[i];
    const Answer& a = answers[i];
    const PoseError e = pose_error(a.pose, t.truth, b.objects[t.object].symmetries);
    csv << '"' << r.label << "\"," << set << "," << t.index << "," << b.objects[t.object].name
        << "," << fixed(t.distance, 3) << "," << fixed(t.nearest_view_deg) << "," << t.points.size()
        << "," << fixed(t.occlusion, 3) << "," << (a.best.empty() ? "-" : a.best) << ","
        << fixed(a.score, 4) << "," << named_right(a, t, b.objects, m) << ","
        << fixed(e.rotation_deg, 2) << "," << fixed(e.translation, 4) << "," << fixed(a.ms, 1)
        << "\n";
  }
}

// Row r's score curve on the tests `which` keeps (all when empty), written to curves.csv.
std::vector<CurvePoint> curve(const Bench& b, const Row& r, const std::string& set,
                              const std::vector<TestView>& tv, const std::vector<Answer>& answers,
                              const Which& which, std::ostream& csv) {
  const auto points = score_curve(tv, answers, b.objects, which);
  int n = 0;
  for (const auto& t : tv) n += !which || which(t);
  for (const auto& p : points)
    csv << '"' << r.label << "\"," << set << "," << n << "," << fixed(p.min_score, 4) << ","
        << fixed(p.tp_rate, 4) << "," << fixed(p.fp_rate, 4) << "," << fixed(p.precision, 4)
        << "\n";
  return points;
}

// Row r's curves: its ROC on the clean and the occluded tests (Fig. 3a, dashed), and for
// proxseg's defaults the precision-recall per occlusion bin (Fig. 3b), "no occlusion" first.
void row_curves(const Bench& b, const Row& r, int colour, Tables& t) {
  const std::vector<TestView> c = subset(b.clean, r.clean.size()),
                              oc = subset(b.occluded, r.occluded.size());
  std::ostringstream csv;
  Curve roc{r.label + " (" + std::to_string(c.size()) + " tests)", {}, colour};
  const auto clean_points = curve(b, r, "clean", c, r.clean, {}, csv);
  for (const auto& p : clean_points) roc.xy.emplace_back(p.fp_rate, p.tp_rate);
  t.roc.push_back(roc);
  if (!oc.empty()) {  // Fig. 3b's occluded tests, all bins together
    Curve roc_occluded{
        r.label + ", occluded (" + std::to_string(oc.size()) + " tests)", {}, colour, true};
    for (const auto& p : curve(b, r, "occluded", oc, r.occluded, {}, csv))
      roc_occluded.xy.emplace_back(p.fp_rate, p.tp_rate);
    t.roc.push_back(roc_occluded);
  }
  for (std::size_t k = 0; k < b.bins.size() && !oc.empty(); ++k) {
    const auto points =
        curve(b, r, bin_name(b.bins[k]), oc, r.occluded, in_bin(static_cast<int>(k)), csv);
    if (r.kind != "proxseg") continue;
    Curve pr{"occlusion " + bin_name(b.bins[k]) + " %", {}, static_cast<int>(k) + 1};
    for (const auto& p : points) pr.xy.emplace_back(p.tp_rate, p.precision);
    t.pr.push_back(pr);
  }
  if (r.kind == "proxseg") {
    Curve pr{"no occlusion", {}};
    for (const auto& p : clean_points) pr.xy.emplace_back(p.tp_rate, p.precision);
    t.pr.insert(t.pr.begin(), pr);
  }
  t.curves_csv += csv.str();
}

}  // namespace

std::string radii_mm(const std::vector<double>& radii) {
  std::string s;
  for (double r : radii) s += (s.empty() ? "" : ", ") + fixed(1000 * r, 0);
  return s;
}

std::string bin_name(const OcclusionBin& b) {
  return fixed(100 * b.lo, 0) + "-" + fixed(100 * b.hi, 0);
}

std::string paper_row(int i) {
  if (i < 0) return "";
  const PaperTest& p = kPaperTable2[i];
  return std::string(p.name) + " (" + std::to_string(p.views) + " views, " + p.radii + " mm, " +
         std::to_string(p.ransac) + " / " + std::to_string(p.icp) +
         " it.): " + std::to_string(p.tp) + " / " + std::to_string(p.fp);
}

std::vector<TestView> subset(const std::vector<TestView>& v, std::size_t n) {
  return std::vector<TestView>(v.begin(), v.begin() + std::min(n, v.size()));
}

Tables report_tables(const Options& o, const Bench& b) {
  Tables t;
  t.summary["parameters"] = parameters_json(o, b);
  t.summary["bins"] = nlohmann::json::array();
  for (const auto& bin : b.bins) t.summary["bins"].push_back(bin_name(bin));
  t.summary["methods"] = nlohmann::json::array();
  std::ostringstream tests_csv;
  tests_csv << "method,set,test,object,distance_m,nearest_db_view_deg,points,occlusion,answer,"
               "score,right,rot_err_deg,trans_err_m,ms\n";
  t.curves_csv = "method,set,tests,min_score,tp_rate,fp_rate,precision\n";
  for (const Row& r : b.rows) {
    t.summary["methods"].push_back(method_json(b, r));
    csv_rows(b, r, "clean", subset(b.clean, r.clean.size()), r.clean, tests_csv);
    csv_rows(b, r, "occluded", subset(b.occluded, r.occluded.size()), r.occluded, tests_csv);
    row_curves(b, r, static_cast<int>(&r - b.rows.data()), t);
  }
  t.tests_csv = tests_csv.str();
  t.summary["paper"] = paper_json();
  return t;
}

}  // namespace proxseg::bench::recbench
