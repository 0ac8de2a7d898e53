// The C++ side of the Python overhead benchmark (bench/python_bench.py, `make bench-python`):
// reads each scene once, then times `rounds` calls of proxseg::segment() on it, in process.
// Prints one JSON line per scene: {"scene": ..., "ms": [per call wall time]}.
#include <proxseg/core/memory.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: segment_loop ROUNDS SCENE.pcd...\n";
    return 2;
  }
  proxseg::keep_freed_memory();  // as the README asks of programs that segment frame after frame
  const int rounds = std::atoi(argv[1]);
  const proxseg::SegmentParams params = proxseg::preset("default");
  for (int a = 2; a < argc; ++a) {
    const proxseg::Frame frame = proxseg::read_point_cloud(argv[a]);
    std::cout << "{\"scene\": \"" << argv[a] << "\", \"ms\": [";
    for (int r = 0; r < rounds; ++r) {
      const auto t = std::chrono::steady_clock::now();
      const proxseg::SegmentResult result = proxseg::segment(frame, params);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
      std::cout << (r ? ", " : "") << ms;
      if (result.k() == 0) return 1;  // keeps the call from being optimised away
    }
    std::cout << "]}\n";
  }
  return 0;
}
