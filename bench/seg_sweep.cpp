// Parameter sweep for the segmentation: runs segment() on the given scenes with a JSON override
// and prints k and the V-measure (mOSD objects) after k-means and after the MRF.
// Usage: seg_sweep '{"clustering":{"prior_weight":100}}' scene.pcd...
#include <proxseg/io.hpp>
#include <proxseg/metrics.hpp>
#include <proxseg/params.hpp>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: seg_sweep JSON scene.pcd...\n");
    return 2;
  }
  const proxseg::SegmentParams params = proxseg::params_from_json(nlohmann::json::parse(argv[1]));
  double sum_km = 0, sum_mrf = 0, sum_k = 0, sum_c = 0, sum_ms = 0;
  for (int a = 2; a < argc; ++a) {
    const proxseg::Frame frame = proxseg::read_point_cloud(argv[a]);
    const proxseg::SegmentResult r = proxseg::segment(frame, params);
    const auto truth = proxseg::mosd_objects(frame.label);
    std::vector<std::uint32_t> km(frame.size(), 0);
    for (std::size_t p = 0; p < frame.size(); ++p) {
      const int v = r.voxels.voxel_of_point[p];
      if (v < 0) continue;
      // k-means labels per point (sparse voxels left out of this comparison: label 0)
      auto it = std::lower_bound(r.clustered.begin(), r.clustered.end(), v);
      if (it != r.clustered.end() && *it == v) km[p] = r.labels_kmeans[it - r.clustered.begin()] + 1;
    }
    const double vk = proxseg::v_measure(truth, km).v, vm = proxseg::v_measure(truth, r.point_labels).v;
    double ms = 0;
    for (const auto& t : r.times_ms) ms += t.second;
    std::printf("%-40s C=%3zu k=%3d V_kmeans=%.3f V_mrf=%.3f %.0f ms\n", argv[a], r.initial_centroids.size(), r.k(),
                vk, vm, ms);
    sum_km += vk, sum_mrf += vm, sum_k += r.k(), sum_c += r.initial_centroids.size(), sum_ms += ms;
  }
  const int n = argc - 2;
  std::printf("MEAN C=%.1f k=%.1f V_kmeans=%.3f V_mrf=%.3f %.0f ms\n", sum_c / n, sum_k / n, sum_km / n,
              sum_mrf / n, sum_ms / n);
  return 0;
}
