// lccp_process INPUT.pcd... -o OUTDIR
//
// A plain PCL program that does what bench/peers_pcl.cpp's proxseg::peers::lccp does, for the
// whole-process timing of seg_bench: read each PCD, supervoxels + LCCP with the LccpParams defaults
// (bench/peers_pcl.hpp), fill the valid points no supervoxel reached from the nearest labelled
// point within 3 cm, number the segments 1..n by smallest point index (0 = invalid or unassigned)
// and write OUTDIR/<stem>.pcd (binary x y z rgba label, organized when the input is). The only
// proxseg code in it is the allocator setting of proxseg's CLI (src/core/memory.cpp).
#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/lccp_segmentation.h>
#include <pcl/segmentation/supervoxel_clustering.h>

#include <proxseg/core/errors.hpp>
#include <proxseg/io/memory.hpp>

#include <CLI/CLI.hpp>

#include <cstdint>
#include <exception>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "bench_main.hpp"
#include "nearest_fill.hpp"

namespace {

using Point = pcl::PointXYZRGBA;
namespace fs = std::filesystem;

// LccpParams defaults (bench/peers_pcl.hpp).
constexpr float kVoxelResolution = 0.0075f, kSeedResolution = 0.03f;
constexpr float kColourImportance = 0.0f, kSpatialImportance = 1.0f, kNormalImportance = 4.0f;
constexpr float kConcavityTolerance = 10.0f, kSmoothnessThreshold = 0.1f, kFillRadius = 0.03f;

// One label per point of the cloud: 0 = invalid or unassigned, 1..n = segment.
std::vector<std::uint32_t> segment(const pcl::PointCloud<Point>::Ptr& cloud) {
  const std::size_t n = cloud->size();
  std::vector<std::uint32_t> labels(n, 0);

  pcl::SupervoxelClustering<Point> super(kVoxelResolution, kSeedResolution);
  super.setUseSingleCameraTransform(false);
  super.setInputCloud(cloud);
  super.setColorImportance(kColourImportance);
  super.setSpatialImportance(kSpatialImportance);
  super.setNormalImportance(kNormalImportance);
  std::map<std::uint32_t, pcl::Supervoxel<Point>::Ptr> clusters;
  super.extract(clusters);
  if (clusters.empty()) return labels;
  std::multimap<std::uint32_t, std::uint32_t> adjacency;
  super.getSupervoxelAdjacency(adjacency);

  pcl::LCCPSegmentation<Point> lccp;
  lccp.setConcavityToleranceThreshold(kConcavityTolerance);
  lccp.setSanityCheck(true);
  lccp.setSmoothnessCheck(true, kVoxelResolution, kSeedResolution, kSmoothnessThreshold);
  lccp.setKFactor(0);
  lccp.setInputSupervoxels(clusters, adjacency);
  lccp.setMinSegmentSize(0);
  lccp.segment();

  pcl::PointCloud<pcl::PointXYZL>::Ptr labelled = super.getLabeledCloud();
  lccp.relabelCloud(*labelled);
  if (labelled->size() != n) return labels;
  for (std::size_t i = 0; i < n; ++i)
    if (pcl::isFinite((*cloud)[i])) labels[i] = (*labelled)[i].label;

  // Valid points in voxels that no supervoxel reached: the nearest labelled point's label.
  proxseg::peers::fill_from_nearest(
      labels, [&](std::size_t i) { return pcl::isFinite((*cloud)[i]); },
      [&](std::size_t i) { return pcl::PointXYZ((*cloud)[i].x, (*cloud)[i].y, (*cloud)[i].z); },
      kFillRadius * kFillRadius);

  // Segments 1..n in the order of their smallest point index.
  std::unordered_map<std::uint32_t, std::uint32_t> ids;
  for (std::uint32_t& l : labels)
    if (l != 0) l = ids.emplace(l, static_cast<std::uint32_t>(ids.size() + 1)).first->second;
  return labels;
}

// PCL 1.13's PCDReader crashes on a header without FIELDS (fixed in PCL 1.14, PR 5855) and loops
// forever on a directory, so both are checked first; x, y and z are required.
bool read_cloud(const std::string& path, pcl::PointCloud<Point>& cloud) {
  pcl::PCLPointCloud2 header;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec) || pcl::PCDReader().readHeader(path, header) < 0) return false;
  for (const char* field : {"x", "y", "z"})
    if (pcl::getFieldIndex(header, field) < 0) return false;
  return pcl::io::loadPCDFile<Point>(path, cloud) >= 0 && !cloud.empty();
}

// Each input segmented and written to OUTDIR/<stem>.pcd; an InputError when one cannot be.
int run(const std::vector<std::string>& inputs, const std::string& out_dir) {
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  fs::create_directories(out_dir);
  for (const std::string& input : inputs) {
    const fs::path output = fs::path(out_dir) / (fs::path(input).stem().string() + ".pcd");
    if (fs::exists(output) && fs::equivalent(input, output))
      throw proxseg::InputError(output.string() + " would overwrite the input");
    pcl::PointCloud<Point>::Ptr cloud(new pcl::PointCloud<Point>);
    if (!read_cloud(input, *cloud))
      throw proxseg::InputError(input + ": not a readable PCD with x y z fields and points");
    const std::vector<std::uint32_t> labels = segment(cloud);
    pcl::PointCloud<pcl::PointXYZRGBL> result;
    pcl::copyPointCloud(*cloud, result);
    for (std::size_t i = 0; i < labels.size(); ++i) result[i].label = labels[i];
    if (pcl::io::savePCDFileBinary(output.string(), result) < 0)
      throw proxseg::InputError(output.string() + ": cannot write");
  }
  return 0;
}

}  // namespace

// main_of sets the allocator as proxseg's CLI does, so that the whole-process comparison is of
// the two programs' work, not of glibc's defaults.
int main(int argc, char** argv) {
  CLI::App app{
      "lccp_process: PCL supervoxels + LCCP on each cloud; writes OUTDIR/<stem>.pcd with a label "
      "field"};
  std::vector<std::string> inputs;
  std::string out_dir;
  app.add_option("inputs", inputs, "INPUT.pcd files")->required();
  app.add_option("-o,--output", out_dir, "OUTDIR")->required();
  return proxseg::bench::main_of("lccp_process", app, argc, argv,
                                 [&] { return run(inputs, out_dir); });
}
