// Selection [paper 3.3]: labelled voxels -> clusters -> candidate objects.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/core/voxels.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace proxseg {

// Selection on voxels [3.3 and extensions]: the convexity rules of the voxel clusters.
struct VoxelSelectionParams {
  // Convexity [extension, after Stein et al., LCCP]: voxel edges whose normals differ by more than
  // concavity_tolerance_deg and turn towards each other are concave. SelectionParams::
  // split_concave cuts clusters there; merge_convex joins neighbouring components whose boundary
  // is convex or flat (at most SelectionParams::merge_max_concave_share of at least
  // merge_min_boundary voxel edges concave).
  double concavity_tolerance_deg = 10.0;
  bool merge_convex = true;
  int merge_min_boundary = 3;
};

// Selection on the image grid of organized frames [extension]: per-pixel normals, depth-step and
// crease edges between pixels, connected components. docs/method.md, "Selection on the image
// grid".
struct ImageSelectionParams {
  // Pixel offset of the central differences (and box-filter size) of the normals.
  int normal_step = 4;
  // The normals' smoothing keeps to each pixel's own surface (no depth step, by
  // depth_step_ratio), so that a silhouette's normals are not bent towards the surface behind it
  // (FeatureParams::normal_edge_ratio); false = the shape feature's plain box filter.
  bool edge_aware_normals = true;
  // Neighbouring pixels whose depths differ by more than this share of the depth lie on
  // different surfaces (a depth-discontinuity edge).
  double depth_step_ratio = 0.01;
  // The crease test compares the normals of the pixels concavity_step pixels to either side of a
  // pixel (along rows, columns and both diagonals); a crease turns them by more than
  // crease_tolerance_deg towards each other. Wider than the voxels' tolerance: the inside of a
  // mug or bowl turns the normals by 15-20 degrees over that span without being a crease.
  int concavity_step = 4;
  double crease_tolerance_deg = 35.0;
  // The support plane takes a pixel within plane_band_sigmas standard deviations of the sensor's
  // depth noise at its range, sensor_noise_at_1m x z^2 (Kinect v1: random noise and disparity
  // steps), and with its normal within SelectionParams::support_normal_tolerance_deg.
  double sensor_noise_at_1m = 0.0025;  // metres
  double plane_band_sigmas = 3.0;
  double plane_band_min = 0.005;  // metres: the band is never narrower (surface roughness)
  // The pixels of a candidate within plane_flat_sigmas standard deviations of the support plane
  // are given to it at the end: the normals of the table beside an object are bent by the object
  // over normal_step pixels, and that ring would otherwise stay with the object (as many table
  // pixels as pen pixels around a pen lying on the table). 0 = keep it.
  double plane_flat_sigmas = 1.0;
  // merge_links (docs/method.md, rule 6): components merge across gaps and short depth steps
  // where their points come within SelectionParams::cluster_tolerance, linked by pixel pairs at
  // most merge_window pixels apart: at least merge_min_links links, at most
  // SelectionParams::merge_max_concave_share of them concave. Rays across bands of missing pixels
  // (bridge_window pixels at most) link components whose ends lie within bridge_tolerance. A
  // merge also needs merge_min_agreement of the links to join pixels of the same segmentation
  // label (colour and texture). A piece of the support plane that left its noise band
  // (merge_min_links links to it, in it) joins it: without this rule 62 pieces of table became
  // candidates in the 45 mOSD learn scenes, none with it.
  bool merge_links = true;
  int merge_window = 3;
  int merge_min_links = 20;
  int bridge_window = 24;
  double bridge_tolerance = 0.08;  // metres
  double merge_min_agreement = 0;  // 0: the paper's labels are not consulted (nor computed)
  // A component with at least island_missing_share of its border beside missing pixels joins the
  // component it has the most rays to (at least merge_min_links).
  double island_missing_share = 0.9;
};

// Occlusion [extension, image grid]: pieces of one object that an object in front cut apart
// join. Rays (rows, columns, diagonals) of at most window pixels run from one component to
// another across pixels in front of both ends; a ray ends on one surface when the two ends
// continue one face (normals within normal_tolerance_deg, each end within surface_tolerance + 5 %
// of the gap of the other's tangent plane) or two faces of a convex body whose edge is hidden
// (each end behind the other's tangent plane). Two components join when at least min_rays rays,
// and min_share of the rays between them, end on one surface and their hue-saturation histograms
// [3.1] intersect by at least min_colour; or when at least min_face_rays of the rays continue one
// face (the stronger geometric evidence) and the histograms intersect by at least
// min_face_colour.
struct OcclusionParams {
  bool enabled = true;
  int window = 120;  // pixels
  int min_rays = 10;
  double min_share = 0.5;  // of the rays between the two, ending on one surface
  double normal_tolerance_deg = 20.0;
  double surface_tolerance = 0.01;  // metres
  double min_colour = 0.4;
  int min_face_rays = 3;
  double min_face_colour = 0.2;
};

// Containers [extension, image grid]: the inside and the outside of one container (a mug, bowl or
// pot seen from above, which its rim cuts in two) join. A component is round when the circle
// fitted to its footprint on the support plane has a radius in [min_radius, max_radius] and the
// footprint lies on it within circle_rms of the radius (RMS). Another component is its inside
// when 90 % of its footprint lies within that circle (+ rim_tolerance), its top no higher than
// the round one's rim (+ rim_tolerance) and its bottom at least min_depth below the rim. Needs
// the support plane.
struct ContainerParams {
  bool enabled = true;
  double min_radius = 0.02;     // metres
  double max_radius = 0.2;      // metres
  double circle_rms = 0.1;      // share of the radius
  double rim_tolerance = 0.01;  // metres
  double min_depth = 0.02;      // metres
};

// Selection [3.3]: the rules both geometries share at the top, each geometry's own in its section.
struct SelectionParams {
  // Weak connections [3.3]: a point is weak when the number of cluster points within
  // density_radius is under weak_density_ratio times the cluster's median. On organized frames the
  // count is scaled by the squared range first, since a sensor's sampling density falls as 1/z^2.
  double density_radius = 0.005;  // metres
  double weak_density_ratio = 0.25;
  // Euclidean clustering of the remaining points [3.3]: points closer than this are connected.
  double cluster_tolerance = 0.01;  // metres
  int min_candidate_points = 300;   // smaller components are not candidates (paper preset: 500)
  bool absorb_small = true;         // small components join their main large neighbour, else 0
  // Convexity [extension, after Stein et al., LCCP]: clusters are cut at concave edges (voxel
  // edges, or creases on the image grid), and components merge across a boundary with at most
  // merge_max_concave_share of its links concave.
  bool split_concave = true;
  double merge_max_concave_share = 0.25;
  // Support plane [extension]: the dominant plane (same offset within background_plane_distance,
  // or the sensor's noise band on the image grid; normals within support_normal_tolerance_deg) is
  // cut from the rest, so objects do not stay connected to the table they stand on.
  bool cut_support_plane = true;
  double support_normal_tolerance_deg = 20.0;
  // Background: a large planar component that supports the objects (table, floor, wall) is
  // reported, with its own instance id, but is not a candidate.
  double background_min_area = 0.06;         // m^2, product of the two largest extents
  double background_plane_distance = 0.015;  // metres from the component's best plane
  double background_inlier_ratio = 0.85;     // share of points within that distance

  // Where the geometry of the selection is computed [extension]. kVoxels: the voxel clusters of
  // the paper's 3.3 (with the extensions of `voxels`). kImage: on the image grid of organized
  // frames (`image`, `occlusion`, `containers`); unorganized frames always use kVoxels.
  enum class Geometry { kVoxels, kImage };
  // The names of its values, in its order: how the CLI, JSON configs and Python spell them.
  friend std::vector<std::string> value_names(Geometry) { return {"voxels", "image"}; }
  Geometry geometry = Geometry::kImage;
  VoxelSelectionParams voxels;
  ImageSelectionParams image;
  OcclusionParams occlusion;
  ContainerParams containers;
};

// An oriented bounding box: centre, axes as columns (largest extent first, right-handed), and
// the side lengths along them.
struct OrientedBox {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
};

struct Candidate {
  std::uint32_t instance = 0;  // id in the per-point instance field, 1..n
  std::uint32_t label = 0;     // the segmentation label the component came from
  std::vector<int> points;     // point indices, ascending
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  OrientedBox box;
  bool background = false;  // a supporting plane, not a candidate object
};

struct Selection {
  std::vector<std::uint32_t> instance;  // per point: 0 = invalid or unassigned, else 1..n
  std::vector<Candidate> components;    // instance i is components[i - 1]
  int clusters = 0;                     // connected same-label voxel sets before splitting
  std::size_t weak_points = 0;          // points set aside as weak connections
  // Wall time of each step inside select_on_image(), in order (the voxel selection: none).
  std::vector<std::pair<std::string, double>> steps_ms;
};

// point_labels: per point, 0 = invalid, else the segmentation label (every point of a voxel has
// its voxel's label). Instances are numbered by their smallest point index, so the numbering does
// not depend on threads (0 = all cores).
Selection select_candidates(const Frame& frame, const VoxelGrid& grid,
                            const std::vector<std::uint32_t>& point_labels,
                            const SelectionParams& params, int threads = 0);

// The oriented bounding box of a set of points (principal axes).
OrientedBox oriented_box(const Frame& frame, const std::vector<int>& points);

}  // namespace proxseg
