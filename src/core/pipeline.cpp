// segment(): the paper's sections 3.1-3.3, top to bottom.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/stop.hpp>

#include "image_selection_detail.hpp"
#include "util/nearest_points.hpp"
#include "util/parallel_for.hpp"
#include "util/run_beside.hpp"
#include "util/stopwatch.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <new>
#include <opencv2/core.hpp>
#include <sstream>

namespace proxseg {
namespace {

// The clustered voxel whose label each voxel takes: its own index in `clustered` if it was
// clustered, else the nearest clustered voxel by voxel centroid; -1 if there is none.
std::vector<int> label_sources(const Frame& frame, const VoxelGrid& grid,
                               const std::vector<int>& clustered) {
  std::vector<int> source(grid.size(), -1);
  for (std::size_t i = 0; i < clustered.size(); ++i) source[clustered[i]] = static_cast<int>(i);
  if (clustered.size() < grid.size() && !clustered.empty()) {
    auto centroid = [&](int v) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (int p : grid.points[v]) c += frame.xyz[p].cast<double>();
      return Eigen::Vector3d(c / static_cast<double>(grid.points[v].size()));
    };
    std::vector<Eigen::Vector3d> centres(clustered.size());
    for (std::size_t i = 0; i < clustered.size(); ++i) centres[i] = centroid(clustered[i]);
    const detail::NearestPoints index(std::move(centres));
    for (std::size_t v = 0; v < grid.size(); ++v)
      if (source[v] < 0) source[v] = index.nearest(centroid(static_cast<int>(v)), 1)[0].first;
  }
  return source;
}

// Whether each point has a voxel: exactly the points that get a label in step 6.
std::vector<char> voxelised(const VoxelGrid& grid) {
  std::vector<char> out(grid.voxel_of_point.size());
  for (std::size_t p = 0; p < out.size(); ++p) out[p] = grid.voxel_of_point[p] >= 0;
  return out;
}

// Every valid point takes the label of its voxel's source (label_sources): 1..k, 0 for invalid
// points.
std::vector<std::uint32_t> label_points(const Frame& frame, const VoxelGrid& grid,
                                        const std::vector<int>& source,
                                        const std::vector<int>& labels) {
  std::vector<std::uint32_t> out(frame.size(), 0);
  for (std::size_t p = 0; p < frame.size(); ++p) {
    const int v = grid.voxel_of_point[p];
    if (v >= 0 && source[v] >= 0) out[p] = static_cast<std::uint32_t>(labels[source[v]] + 1);
  }
  return out;
}

// Points per label as label_points() gives them ([0]: unlabelled, 1..k), counted per voxel: every
// point of a voxel takes its source's label. The report needs them for every frame.
std::vector<std::size_t> label_sizes(const Frame& frame, const VoxelGrid& grid,
                                     const std::vector<int>& source, const std::vector<int>& labels,
                                     int k) {
  std::vector<std::size_t> sizes(static_cast<std::size_t>(k) + 1, 0);
  std::size_t labelled = 0;
  for (std::size_t v = 0; v < grid.size(); ++v)
    if (source[v] >= 0) {
      sizes[static_cast<std::size_t>(labels[source[v]]) + 1] += grid.points[v].size();
      labelled += grid.points[v].size();
    }
  sizes[0] = frame.size() - labelled;
  return sizes;
}

// The feature parameters segment() works with: the requested ones with only the blocks it
// computes switched on, so that voxel_features never reads colours the frame does not have and
// balance_blocks weighs exactly the blocks that were computed.
FeatureParams effective_features(const FeatureParams& requested, const FeatureBlocks& blocks) {
  FeatureParams p = requested;
  p.use_colour = blocks.colour;
  p.use_texture = blocks.texture;
  p.use_shape = blocks.shape;
  return p;
}

}  // namespace

FeatureBlocks feature_blocks(const FeatureParams& features, bool coloured, bool organized) {
  FeatureBlocks b;
  b.colour = features.use_colour && features.colour_weight > 0 && coloured;
  b.texture = features.use_texture && features.texture_weight > 0 && coloured && organized;
  b.shape = features.use_shape && features.shape_weight > 0;
  return b;
}

namespace {

// Stage 1 found nothing to work on: no valid point at all, or none within the voxels' reach, the
// voxel side's fault (orders of magnitude too small), not the frame's: say which.
[[noreturn]] void nothing_to_segment(const Frame& frame, const VoxelGrid& grid) {
  const double voxel_size = grid.voxel_size;
  const std::size_t valid = grid.valid_points;
  if (valid == 0) throw InputError("frame: no valid points to segment");
  double farthest = 0;  // the largest coordinate of a valid point, in metres
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.valid(i)) farthest = std::max(farthest, double(frame.xyz[i].cwiseAbs().maxCoeff()));
  std::ostringstream o;
  o << "field voxels.voxel_size: none of the frame's " << valid << " valid points lies within "
    << kVoxelReach << " voxels of the origin with voxel_size " << voxel_size
    << " m (expected at least " << farthest / kVoxelReach << " m for this frame; the paper: 0.02)";
  throw InputError(o.str());
}

bool on_image_grid(const SegmentParams& params, const Frame& frame) {
  return params.selection.geometry == SelectionParams::Geometry::kImage && frame.organized();
}

// Stages 1-6, the paper's labels [3.1-3.2]. On an organized frame with the image-grid selection
// its geometry (read_geometry) runs on a second thread beside stages 3-6, after the features and
// the principal axes, which use every thread themselves. Stop points between the stages, on the
// calling thread (run_beside() waits for the geometry before it rethrows).
void paper_labels(const Frame& frame, const SegmentParams& params,
                  const std::function<void(const std::vector<char>&)>& read_geometry,
                  SegmentResult& r) {
  detail::Stopwatch watch;
  const FeatureParams features = effective_features(params.features, r.blocks);

  // 1. Voxels [3.1]: 2 cm cells and their occupied 26-neighbours; sparse cells wait until the end.
  r.voxels = build_voxels(frame, params.voxels.voxel_size);
  if (r.voxels.size() == 0) nothing_to_segment(frame, r.voxels);
  r.clustered = dense_voxels(r.voxels, params.voxels.min_points_per_voxel);
  if (r.clustered.empty()) r.clustered = dense_voxels(r.voxels, 1);  // all cells are sparse
  const std::vector<std::vector<int>> graph = induced_neighbours(r.voxels, r.clustered);
  r.times_ms.emplace_back("voxels", watch.lap());
  stop_point();

  // 2. Features [3.1]: colour | texture | shape per voxel.
  r.features = voxel_features(frame, r.voxels, r.clustered, features, params.threads);
  r.times_ms.emplace_back("features", watch.lap());
  stop_point();

  // 3. Initial clustering [Algorithm 1] on the principal axes of the features.
  // The block weights were applied by voxel_features; balancing re-applies them after equalising.
  if (params.clustering.balance_blocks) {
    balance_blocks(r.features, {{0, kColourDims, features.colour_weight},
                                {kColourDims, kTextureDims, features.texture_weight},
                                {kColourDims + kTextureDims, kShapeDims, features.shape_weight}});
  }
  r.space = principal_axes(r.features, params.clustering.pca_dims, params.threads,
                           params.clustering.pca_solver);

  auto colour_labels = [&] {
    const Eigen::MatrixXd x = project(r.space, r.features);
    r.initial_centroids = initial_centroids(x, graph, r.space.variances, params.clustering);
    r.times_ms.emplace_back("initial_clustering", watch.lap());

    // 4. k-means [3.2] from Algorithm 1's centroids.
    Eigen::MatrixXd start(r.initial_centroids.size(), x.cols());
    for (std::size_t s = 0; s < r.initial_centroids.size(); ++s)
      start.row(s) = r.initial_centroids[s].mu.transpose();
    KMeansResult km = kmeans(x, start, params.kmeans);
    r.centroids = km.centroids;
    r.labels_kmeans = km.labels;
    r.kmeans_iterations_run = km.iterations;
    r.times_ms.emplace_back("kmeans", watch.lap());
    stop_point();

    // 5. MRF [3.2, eq. 1-3]: Potts model over the voxel graph, minimised by graph cuts.
    MrfProblem problem{unary_potentials(x, r.centroids, params.mrf.unary_weight), edge_list(graph),
                       params.mrf.pairwise_weight};
    r.labels = r.labels_kmeans;
    r.energy_before = r.energy_after = energy(problem, r.labels);
    if (params.mrf.enabled && r.k() > 1) {
      const MrfResult mrf = params.mrf.method == MrfMethod::kSwap
                                ? alpha_beta_swap(problem, r.labels, params.mrf.max_cycles)
                                : alpha_expansion(problem, r.labels, params.mrf.max_cycles);
      r.labels = mrf.labels;
      r.energy_after = mrf.energy_after;
      r.mrf_cycles_run = mrf.cycles;
    }
    r.times_ms.emplace_back("mrf", watch.lap());
    stop_point();

    // 6. Labels back to points; sparse voxels take their nearest clustered neighbour's label.
    const std::vector<int> source = label_sources(frame, r.voxels, r.clustered);
    r.point_labels = label_points(frame, r.voxels, source, r.labels);
    r.label_sizes = label_sizes(frame, r.voxels, source, r.labels, r.k());
    r.point_labels_kmeans = params.mrf.enabled
                                ? label_points(frame, r.voxels, source, r.labels_kmeans)
                                : r.point_labels;
    r.times_ms.emplace_back("point_labels", watch.lap());
  };
  const std::vector<char> labelled = voxelised(r.voxels);
  const int nthreads = detail::thread_count(params.threads);
  if (read_geometry && nthreads > 1) {
    detail::run_beside(true, colour_labels, [&] { read_geometry(labelled); });
  } else {
    colour_labels();
    if (read_geometry) read_geometry(labelled);
  }
}

// Without the paper's labels the image-grid surfaces are the labels the selection starts from:
// surface i is label i + 1, the support plane count + 1; points outside `within` have none.
void surface_labels(const ImageSurfaces& surfaces, const std::vector<char>& within,
                    SegmentResult& r) {
  const auto plane = static_cast<std::uint32_t>(surfaces.count + 1);
  r.point_labels.assign(surfaces.surface.size(), 0);
  r.label_sizes.assign(static_cast<std::size_t>(surfaces.count) + 2, 0);
  for (std::size_t p = 0; p < surfaces.surface.size(); ++p) {
    const int s = within[p] ? surfaces.surface[p] : -1;
    r.point_labels[p] = s >= 0 ? static_cast<std::uint32_t>(s + 1) : s == -2 ? plane : 0;
    ++r.label_sizes[r.point_labels[p]];
  }
  r.point_labels_kmeans = r.point_labels;
}

}  // namespace

bool needs_paper_labels(const SegmentParams& params, const Frame& frame) {
  return params.paper_labels || !on_image_grid(params, frame) ||
         (params.selection.image.merge_links && params.selection.image.merge_min_agreement > 0);
}

double segment_memory_mib(const Frame& frame, const SegmentParams& params) {
  // Peak RSS of `proxseg segment` (mOSD learn0 upsampled 1x, 2x, 3x: 307k, 1.23M, 2.76M pixels):
  // 46, 123, 241 MiB by default (80 bytes a pixel above 21 MiB), 57, 139, 320 MiB with the
  // paper's labels (107 bytes a pixel above 24 MiB). The estimate rounds both up.
  const double per_pixel = needs_paper_labels(params, frame) ? 128 : 96;
  return 32 + per_pixel * static_cast<double>(frame.size()) / (1 << 20);
}

void check_memory(const Frame& frame, const SegmentParams& params, const std::string& name) {
  if (params.max_memory_mib <= 0) return;
  const double need = segment_memory_mib(frame, params);
  if (need <= params.max_memory_mib) return;
  throw InputError(name + ": needs about " + std::to_string(static_cast<long>(std::ceil(need))) +
                   " MiB to segment (estimated), more than max_memory_mib " +
                   std::to_string(static_cast<long>(params.max_memory_mib)) +
                   "; refused before starting");
}

namespace {

// The pipeline, stage by stage [3.1-3.3].
SegmentResult segment_stages(const Frame& frame, const SegmentParams& params) {
  if (frame.coloured() && frame.rgb.size() != frame.size())
    throw InputError("frame: " + std::to_string(frame.rgb.size()) + " colours for " +
                     std::to_string(frame.size()) + " points (expected one per point, or none)");
  SegmentResult r;
  stop_point();  // between stages only: no helper thread of a stage is running then
  detail::Stopwatch whole;
  // An XYZ-only frame: the colour and texture blocks are off for this call, as if not asked for.
  r.blocks = feature_blocks(params.features, frame.coloured(), frame.organized());
  r.paper_labels = needs_paper_labels(params, frame);
  const bool on_grid = on_image_grid(params, frame);

  // The image-grid geometry of the selection (7) needs only the frame: normals, support plane,
  // creases, surfaces.
  ImageSurfaces surfaces;
  double surfaces_ms = 0;
  auto read_geometry = [&](const std::vector<char>& labelled, int threads) {
    detail::Stopwatch own;
    surfaces = image_surfaces(frame, labelled, params.selection, threads);
    surfaces_ms = own.lap();
    for (const auto& [step, ms] : surfaces.steps_ms)
      r.steps_ms.emplace_back("image_surfaces/" + step, ms);
  };
  if (r.paper_labels) {
    // 1-6: the paper's labels, with the geometry on a second thread beside stages 3-6.
    std::function<void(const std::vector<char>&)> beside;
    if (on_grid) beside = [&](const std::vector<char>& labelled) { read_geometry(labelled, 1); };
    paper_labels(frame, params, beside, r);
    if (on_grid) r.concurrent_ms.emplace_back("image_surfaces", surfaces_ms);
  } else {
    // Without them: the geometry on every thread, its surfaces as the labels. Points too far
    // out to voxelise are left out as on the paper's path.
    r.voxels.voxel_size = params.voxels.voxel_size;
    const std::vector<char> within = voxelisable(frame, params.voxels.voxel_size,
                                                 r.voxels.valid_points, r.voxels.voxelised_points);
    if (r.voxels.voxelised_points == 0) nothing_to_segment(frame, r.voxels);
    read_geometry(within, params.threads);
    surface_labels(surfaces, within, r);
    r.times_ms.emplace_back("image_surfaces", surfaces_ms);
  }

  stop_point();
  // 7. Selection [3.3]: connected same-label clusters, split at weak links, kept by size; on an
  // organized frame by default the geometry is read on the image grid instead of the voxels.
  detail::Stopwatch watch;
  r.selection = on_grid ? select_on_image(frame, std::move(surfaces), r.point_labels,
                                          params.selection, params.threads)
                        : select_candidates(frame, r.voxels, r.point_labels, params.selection,
                                            params.threads);
  r.times_ms.emplace_back("selection", watch.lap());
  for (const auto& [step, ms] : r.selection.steps_ms)
    r.steps_ms.emplace_back("selection/" + step, ms);
  r.total_ms = whole.lap();
  stop_point();  // a stopped call throws rather than return what it has
  return r;
}

}  // namespace

SegmentResult segment(const Frame& frame, const SegmentParams& params) {
  validate(params);
  check_memory(frame, params, "the frame");
  try {
    return segment_stages(frame, params);
  } catch (const cv::Exception& e) {
    // OpenCV says "Insufficient memory" with its own exception: made the one signal of memory
    // exhausted that callers handle (a batch's failed row, the CLI's message naming the frame).
    if (e.code == cv::Error::StsNoMem) throw std::bad_alloc();
    throw;
  }
}

}  // namespace proxseg
