// The C++ side of the Python overhead benchmark (bench/python_bench.py, `make bench-python`):
// reads the scenes once, then for every scene index read from stdin runs proxseg::segment() on
// that scene in process and prints its wall time in ms, one line per call. Python asks for one
// C++ call, makes its own call on the same scene, and so on: the two sides alternate call by call
// and meet the same machine load.
#include <proxseg/core/pipeline.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/memory.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "bench_main.hpp"

namespace {

int run(const std::vector<std::string>& scenes) {
  const proxseg::SegmentParams params = proxseg::preset("default");
  std::vector<proxseg::Frame> frames;
  for (const std::string& scene : scenes) frames.push_back(proxseg::read_point_cloud(scene));
  std::size_t i = 0;
  while (std::cin >> i) {
    if (i >= frames.size()) return 2;
    const auto t = std::chrono::steady_clock::now();
    const proxseg::SegmentResult result = proxseg::segment(frames[i], params);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
    std::cout << ms << " " << result.total_ms << " " << result.k() << std::endl;  // flushed
  }
  return 0;
}

}  // namespace

// main_of keeps freed memory, as the README asks of programs that segment frame after frame.
int main(int argc, char** argv) {
  CLI::App app{"segment_loop: segment() on the scenes whose indices come on stdin, ms per call"};
  std::vector<std::string> scenes;
  app.add_option("scenes", scenes, "SCENE.pcd files (then scene indices on stdin)")->required();
  return proxseg::bench::main_of("segment_loop", app, argc, argv, [&] { return run(scenes); });
}
