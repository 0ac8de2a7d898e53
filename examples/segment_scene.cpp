// A program built against an installed proxseg (find_package or pkg-config; docs/library.md):
// it segments one point cloud with the default parameters and writes what `proxseg segment`
// writes: PREFIX.pcd (per-point label and instance), PREFIX.png and PREFIX.json.
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/version.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/memory.hpp>
#include <proxseg/io/output.hpp>

#include <exception>
#include <iostream>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: segment_scene CLOUD.pcd|CLOUD.ply OUTPUT_PREFIX\n";
    return 2;
  }
  try {
    proxseg::keep_freed_memory();  // as the CLI does (docs/library.md)
    const proxseg::Frame frame = proxseg::read_point_cloud(argv[1]);
    const proxseg::SegmentParams params;  // the defaults: `proxseg segment` without options
    const proxseg::SegmentResult result = proxseg::segment(frame, params);
    proxseg::write_segmentation(argv[2], frame, params, result);
    int objects = 0;
    for (const proxseg::Candidate& c : result.selection.components) objects += !c.background;
    std::cout << "proxseg " << proxseg::version() << " (" << proxseg::git_commit()
              << "): " << objects << " candidate objects in " << argv[1] << "\n";
  } catch (const std::exception& e) {
    std::cerr << "segment_scene: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
