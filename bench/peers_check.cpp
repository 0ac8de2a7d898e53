// Runs the PCL peers (peers_pcl.hpp) on labelled mOSD scenes and prints, per scene and method,
// the number of segments, labelled points, time and V-measure against the mOSD objects.
// Usage: peers_check SCENE.pcd...
#include "bench_main.hpp"
#include "peers_pcl.hpp"

#include <proxseg/eval/metrics.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <chrono>
#include <cstdio>
#include <exception>
#include <functional>
#include <set>
#include <string>
#include <vector>

namespace {

int run(const std::vector<std::string>& scenes) {
  using Method = std::function<std::vector<std::uint32_t>(const proxseg::Frame&)>;
  const std::vector<std::pair<std::string, Method>> methods = {
      {"lccp", [](const proxseg::Frame& f) { return proxseg::peers::lccp(f); }},
      {"region_growing_rgb",
       [](const proxseg::Frame& f) { return proxseg::peers::region_growing_rgb(f); }},
      {"euclidean", [](const proxseg::Frame& f) { return proxseg::peers::euclidean(f); }},
  };
  std::printf("%-28s %-20s %8s %9s %9s %9s %7s %7s %7s\n", "scene", "method", "segments",
              "labelled", "valid", "ms", "V", "hom", "compl");
  for (const std::string& scene : scenes) {
    proxseg::Frame frame;
    try {
      frame = proxseg::read_point_cloud(scene);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return 1;
    }
    const std::vector<std::uint32_t> truth =
        frame.label.empty() ? std::vector<std::uint32_t>() : proxseg::mosd_objects(frame.label);
    std::string name = scene;
    if (const auto s = name.find_last_of('/'); s != std::string::npos) name = name.substr(s + 1);
    for (const auto& [method, run] : methods) {
      const auto t0 = std::chrono::steady_clock::now();
      const std::vector<std::uint32_t> labels = run(frame);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      std::set<std::uint32_t> segments;
      std::size_t labelled = 0;
      for (const std::uint32_t l : labels)
        if (l) {
          segments.insert(l);
          ++labelled;
        }
      if (truth.empty()) {
        std::printf("%-28s %-20s %8zu %9zu %9zu %9.1f %7s %7s %7s\n", name.c_str(), method.c_str(),
                    segments.size(), labelled, frame.valid_count(), ms, "-", "-", "-");
      } else {
        const proxseg::VMeasure v = proxseg::v_measure(truth, labels);
        std::printf("%-28s %-20s %8zu %9zu %9zu %9.1f %7.3f %7.3f %7.3f\n", name.c_str(),
                    method.c_str(), segments.size(), labelled, frame.valid_count(), ms, v.v,
                    v.homogeneity, v.completeness);
      }
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"peers_check: the PCL peers on labelled mOSD scenes"};
  std::vector<std::string> scenes;
  app.add_option("scenes", scenes, "SCENE.pcd files")->required();
  return proxseg::bench::main_of("peers_check", app, argc, argv, [&] { return run(scenes); });
}
