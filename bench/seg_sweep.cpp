// Parameter sweep for the segmentation: runs segment() on the given scenes with a JSON override
// and prints k and the V-measure (mOSD objects) after k-means and after the MRF.
// Usage: seg_sweep '{"clustering":{"prior_weight":100}}' scene.pcd...
#include <proxseg/eval/metrics.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/params.hpp>

#include <cstdio>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <vector>

#include "bench_main.hpp"

namespace {
// "ycbv:BASE" reads BASE-color/depth/meta/label; anything else is a labelled mOSD PCD.
proxseg::Frame load(const std::string& arg, std::vector<std::uint32_t>& truth) {
  if (arg.rfind("ycbv:", 0) == 0) {
    const std::string base = arg.substr(5);
    proxseg::Frame f = proxseg::read_rgbd(base + "-color.png", base + "-depth.png",
                                          proxseg::read_ycb_meta(base + "-meta.json"));
    const cv::Mat mask = cv::imread(base + "-label.png", cv::IMREAD_UNCHANGED);
    truth.assign(f.size(), 0);
    for (std::size_t i = 0; i < f.size(); ++i)
      if (f.valid(i)) truth[i] = 1 + mask.data[i];
    return f;
  }
  proxseg::Frame f = proxseg::read_point_cloud(arg);
  truth = proxseg::mosd_objects(f.label);
  return f;
}
// Objects whose majority label differs from the background's (truth 1).
int apart(const std::vector<std::uint32_t>& truth, const std::vector<std::uint32_t>& pred) {
  std::map<std::uint32_t, std::map<std::uint32_t, int>> c;
  for (std::size_t i = 0; i < truth.size(); ++i)
    if (truth[i]) ++c[truth[i]][pred[i]];
  std::map<std::uint32_t, std::uint32_t> m;
  for (auto& [t, h] : c)
    m[t] = std::max_element(h.begin(), h.end(), [](auto& a, auto& b) {
             return a.second < b.second;
           })->first;
  int n = 0;
  for (auto& [t, l] : m) n += t != 1 && l != m[1];
  return n;
}
int run(const std::string& json, const std::vector<std::string>& scenes) {
  const proxseg::SegmentParams params = proxseg::params_from_json(nlohmann::json::parse(json));
  double sum_km = 0, sum_mrf = 0, sum_k = 0, sum_c = 0, sum_ms = 0;
  for (const std::string& scene : scenes) {
    std::vector<std::uint32_t> truth;
    const proxseg::Frame frame = load(scene, truth);
    const proxseg::SegmentResult r = proxseg::segment(frame, params);
    std::vector<std::uint32_t> km(frame.size(), 0);
    for (std::size_t p = 0; p < frame.size(); ++p) {
      const int v = r.voxels.voxel_of_point[p];
      if (v < 0) continue;
      // k-means labels per point (sparse voxels left out of this comparison: label 0)
      auto it = std::lower_bound(r.clustered.begin(), r.clustered.end(), v);
      if (it != r.clustered.end() && *it == v)
        km[p] = r.labels_kmeans[it - r.clustered.begin()] + 1;
    }
    const double vk = proxseg::v_measure(truth, km).v,
                 vm = proxseg::v_measure(truth, r.point_labels).v;
    double ms = 0;
    for (const auto& t : r.times_ms) ms += t.second;
    std::printf("%-40s C=%3zu k=%3d V_kmeans=%.3f V_mrf=%.3f apart=%d/%d %.0f ms\n", scene.c_str(),
                r.initial_centroids.size(), r.k(), vk, vm, apart(truth, r.point_labels),
                static_cast<int>(std::set<std::uint32_t>(truth.begin(), truth.end()).size()) - 2,
                ms);
    sum_km += vk, sum_mrf += vm, sum_k += r.k(), sum_c += r.initial_centroids.size(), sum_ms += ms;
  }
  const int n = static_cast<int>(scenes.size());
  std::printf("MEAN C=%.1f k=%.1f V_kmeans=%.3f V_mrf=%.3f %.0f ms\n", sum_c / n, sum_k / n,
              sum_km / n, sum_mrf / n, sum_ms / n);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"seg_sweep: segment() on scenes with a JSON override: k and V-measure"};
  std::string json;
  std::vector<std::string> scenes;
  app.add_option("json", json,
                 "Parameter overrides, e.g. '{\"clustering\":{\"prior_weight\":100}}'")
      ->required();
  app.add_option("scenes", scenes, "scene.pcd files, or ycbv:BASE")->required();
  return proxseg::bench::main_of("seg_sweep", app, argc, argv, [&] { return run(json, scenes); });
}
