// segment(): voxels -> features -> Algorithm 1 -> k-means -> MRF -> selection (paper 3.1-3.3).
#pragma once
#include <proxseg/core/clustering.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/features.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/mrf.hpp>
#include <proxseg/core/selection.hpp>
#include <proxseg/core/voxels.hpp>

#include <string>
#include <utility>
#include <vector>

namespace proxseg {

// Every parameter of the segmentation, one struct per stage, with the paper's defaults.
struct SegmentParams {
  VoxelParams voxels;
  FeatureParams features;
  ClusteringParams clustering;
  KMeansParams kmeans;
  MrfParams mrf;
  SelectionParams selection;
  // Whether the paper's labels (stages 2-6: features, Algorithm 1, k-means, MRF, point labels)
  // are computed when nothing needs them. The voxel selection always needs them (the paper
  // preset, unorganized frames), and the image-grid selection when selection.image.merge_links
  // and merge_min_agreement > 0; the default's image-grid selection does not consult them, and
  // on its development sets they changed no answer (docs/method.md, "What each stage buys"), so
  // it skips them unless asked.
  bool paper_labels = false;
  int threads = 0;  // 0 = all cores; results do not depend on it
  // A frame whose segmentation would need more memory than this, in MiB (segment_memory_mib's
  // estimate of the process's peak), is refused before it starts (InputError); 0 = no limit.
  double max_memory_mib = 0;
};

// The feature blocks [3.1] a segmentation computes.
struct FeatureBlocks {
  bool colour = false, texture = false, shape = false;
  bool operator==(const FeatureBlocks& o) const {
    return colour == o.colour && texture == o.texture && shape == o.shape;
  }
  bool operator!=(const FeatureBlocks& o) const { return !(*this == o); }
};

// The blocks segment() computes under `features` for a frame with or without colours and image
// grid: each one asked for (use_* with a weight > 0) that the frame can give. Colour needs the
// frame's colours; so does texture (Gabor filters on the grey levels of the colour image), which
// also needs the image grid.
FeatureBlocks feature_blocks(const FeatureParams& features, bool coloured, bool organized);

// Whether segment() computes the paper's labels (stages 2-6) for a frame under params.
bool needs_paper_labels(const SegmentParams& params, const Frame& frame);

struct SegmentResult {
  // Whether the labels below are the paper's (stages 2-6). Without them (needs_paper_labels
  // false) the voxel and label fields are empty, point_labels (= point_labels_kmeans) holds the
  // image-grid surfaces the selection starts from (1..n, the support plane n + 1, 0 for none)
  // and k() is 0.
  bool paper_labels = true;
  VoxelGrid voxels;
  std::vector<int> clustered;               // voxels that were clustered (>= min_points_per_voxel)
  FeatureBlocks blocks;                     // the blocks computed (feature_blocks)
  Eigen::MatrixXf features;                 // one row per clustered voxel, block-balanced
  FeatureSpace space;                       // principal axes the clustering works in
  std::vector<Centroid> initial_centroids;  // Algorithm 1
  Eigen::MatrixXd centroids;                // after k-means (projected space)
  std::vector<int> labels_kmeans;           // per clustered voxel, 0..k-1
  std::vector<int> labels;                  // per clustered voxel after the MRF (= k-means if off)
  double energy_before = 0, energy_after = 0;
  // How many ran: at most KMeansParams::max_iterations and MrfParams::max_cycles.
  int kmeans_iterations_run = 0, mrf_cycles_run = 0;
  std::vector<std::uint32_t> point_labels;               // per point: 0 invalid, 1..k (above)
  std::vector<std::uint32_t> point_labels_kmeans;        // the same before the MRF
  std::vector<std::size_t> label_sizes;                  // points per label: [0] unlabelled, 1..k
  Selection selection;                                   // clusters -> candidates [3.3]
  std::vector<std::pair<std::string, double>> times_ms;  // per stage, in pipeline order
  // Stages that ran on a second thread beside the ones above (the image-grid geometry of the
  // selection, beside Algorithm 1 .. point labels): not part of the sequence.
  std::vector<std::pair<std::string, double>> concurrent_ms;
  // The steps inside the image-grid stages, as "stage/step" (ImageSurfaces::steps_ms,
  // Selection::steps_ms): where their time goes.
  std::vector<std::pair<std::string, double>> steps_ms;
  double total_ms = 0;  // wall time of segment()
  int k() const { return static_cast<int>(centroids.rows()); }
};

// Checks ranges (voxel size > 0, weights >= 0, ...); throws InputError naming the field.
void validate(const SegmentParams& params);
// Named parameter sets: "default" (the best measured settings, docs/results.md) and "paper"
// (exactly the settings the paper gives: w_c = 0.275, alpha-beta swap, 2 cm voxels, alpha = 0.85;
// everything the paper leaves open keeps its default). Throws InputError for an unknown name.
SegmentParams preset(const std::string& name);

// Segments the frame (validates the parameters first). A frame without colours (Frame::rgb empty)
// is segmented without the colour and texture blocks; InputError if it has colours but not one
// per point.
SegmentResult segment(const Frame& frame, const SegmentParams& params);

// An estimate from above of the peak resident memory, in MiB, of a process that segments `frame`
// with `params`, the process's own ~20 MiB included: a fixed part and a part per pixel (per point
// of an unorganized cloud), larger when the paper's labels are computed. Fitted to organized
// frames of several sizes, from above (docs/robustness.md, "Memory", has the figures).
double segment_memory_mib(const Frame& frame, const SegmentParams& params);
// InputError "NAME: needs about N MiB to segment (estimated), more than max_memory_mib M; refused
// before starting" when params.max_memory_mib > 0 and the estimate exceeds it. segment() checks
// it first (NAME "the frame"); callers that know the frame's file check it with that name.
void check_memory(const Frame& frame, const SegmentParams& params, const std::string& name);

}  // namespace proxseg
