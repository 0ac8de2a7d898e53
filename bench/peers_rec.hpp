// Registration "peers" that the recognition benchmark (bench/rec_bench.cpp) compares proxseg
// against: Open3D's feature-matching RANSAC + ICP, Open3D's Fast Global Registration + ICP, PCL's
// SampleConsensusPrerejective + ICP and OpenCV's point-pair-feature detector + its ICP, each
// aligning every view of a proxseg database to one candidate.
//
// Every peer gets exactly the clouds proxseg uses (the voxel-filtered points, normals and FPFH
// of Cloud), converted once to its own types, so that the comparison is about registration
// alone. Open3D and PCL stay inside bench/peers_rec.cpp, OpenCV's contrib module inside
// bench/peers_ppf.cpp: this header needs none of them.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/recognition/registration.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

namespace proxseg::peers {

// One (candidate, view) registration by a peer.
struct PeerAlignment {
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  // candidate frame <- model frame
  bool found = false;  // the coarse stage returned a hypothesis (ICP runs only from one)
  // Coarse stage (RANSAC; FGR's matching and optimisation; PPF's voting) and refinement.
  double ransac_ms = 0, icp_ms = 0;
};

// Open3D 0.16 pipelines::registration, as in its global registration tutorial.
struct Open3dParams {
  int ransac_iterations = 4000000;  // RANSACConvergenceCriteria::max_iteration_
  double ransac_confidence = 0.999;
  double max_correspondence_distance = 0.01;
  double edge_length_similarity = 0.9;  // CorrespondenceCheckerBasedOnEdgeLength
  double checker_distance = 0.01;       // CorrespondenceCheckerBasedOnDistance
  int icp_iterations = 30;
  double icp_distance = 0.015;
};

// RegistrationRANSACBasedOnFeatureMatching (source = view, target = candidate, features = all
// of Cloud::features) then point-to-point RegistrationICP. Views are spread over `threads`
// OpenMP threads (0 = all cores) like proxseg's; Open3D's own parallel loops then run on one
// thread each (OpenMP does not nest by default). Open3D's alternative, one view at a time with
// every loop parallel, spent most of its time in OpenMP barriers: an ICP iteration on a few
// hundred points is too short a parallel region.
class Open3dPeer {
 public:
  Open3dPeer(const Database& db, const Open3dParams& params, int threads);
  ~Open3dPeer();
  Open3dPeer(const Open3dPeer&) = delete;
  Open3dPeer& operator=(const Open3dPeer&) = delete;
  // One alignment per database view. Open3D draws from its global generator, seeded here with
  // `seed`; with more than one thread its draws interleave, so results may vary run to run.
  std::vector<PeerAlignment> align(const Cloud& candidate, int seed) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Open3D 0.16 FastGlobalRegistrationBasedOnFeatureMatching [Zhou, Park, Koltun, ECCV 2016], as in
// Open3D's "fast global registration" tutorial; the option's defaults except the distance.
struct FgrParams {
  double division_factor = 1.4;  // graduated non-convexity: mu /= this every 4 iterations
  // Where the robust kernel's mu stops decreasing: the tutorial's voxel size / 2, 0.0025 for
  // proxseg's 5 mm voxels. Open3D compares it with mu (a squared distance) in normalised units
  // (the clouds divided by the larger one's radius, 5-15 cm here), so the kernel ends sqrt(0.0025)
  // = 5 % of the radius wide, 3-8 mm: about a voxel, where ICP takes over.
  double max_correspondence_distance = 0.0025;
  int iterations = 64;
  double tuple_scale = 0.95;  // tuple test: edge lengths of 3 matches agree within 5 %
  int max_tuples = 1000;
  int icp_iterations = 30;  // the same point-to-point ICP as Open3dParams
  double icp_distance = 0.015;
};

// FastGlobalRegistrationBasedOnFeatureMatching (source = view, target = candidate, features = all
// of Cloud::features: mutual nearest neighbours, tuple test, robust optimisation; no RANSAC) then
// point-to-point RegistrationICP. Views are spread over `threads` OpenMP threads (0 = all cores)
// like Open3dPeer's.
class FgrPeer {
 public:
  FgrPeer(const Database& db, const FgrParams& params, int threads);
  ~FgrPeer();
  FgrPeer(const FgrPeer&) = delete;
  FgrPeer& operator=(const FgrPeer&) = delete;
  // One alignment per database view. The tuple test draws from Open3D's global generator, seeded
  // here with `seed`; with more than one thread its draws interleave, so results may vary run to
  // run.
  std::vector<PeerAlignment> align(const Cloud& candidate, int seed) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// PCL 1.13, as in its "robust pose estimation of rigid objects" tutorial.
struct PclParams {
  int ransac_iterations = 50000;
  int samples = 3;
  int correspondence_randomness = 5;
  float similarity_threshold = 0.9f;
  float max_correspondence_distance = 0.01f;
  float inlier_fraction = 0.25f;
  int icp_iterations = 30;
  double icp_distance = 0.015;
};

// SampleConsensusPrerejective<PointNormal, PointNormal, FPFHSignature33> (source = view,
// target = candidate, features = the first 33 rows of Cloud::features, i.e. the first FPFH
// radius: the point type holds one histogram) then IterativeClosestPoint. Views are spread over
// `threads` OpenMP threads (0 = all cores) like proxseg's, each thread reusing one aligner so
// that the candidate's search trees are built once per thread.
class PclPeer {
 public:
  PclPeer(const Database& db, const PclParams& params, int threads);
  ~PclPeer();
  PclPeer(const PclPeer&) = delete;
  PclPeer& operator=(const PclPeer&) = delete;
  // One alignment per database view. PCL samples with std::rand(), seeded here with `seed`;
  // with more than one thread the threads share it, so results may vary run to run.
  std::vector<PeerAlignment> align(const Cloud& candidate, int seed) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// OpenCV 4.6 contrib's surface_matching: PPF3DDetector [Drost et al., CVPR 2010] and its ICP, as
// in OpenCV's ppf_load_match sample. Sizes are relative to each cloud's bounding box (OpenCV's
// convention); the views are 5 mm voxel clouds of objects 5-30 cm across. Chosen on a tuning run
// (rec_bench --seed 2, 24 + 24 test views, not the reported set; docs/method.md, "Peers").
struct PpfParams {
  // relativeSamplingStep: training keeps one point (the mean) per cell of a 1/step per axis grid
  // over the view's box, 1-3 cm cells here (about 170 of a view's 850 points; 0.07 and OpenCV's
  // 0.05 keep 350 and 530, cost 5-10x and about 100x the matching time and named no more tests
  // right), and quantises pair distances in steps of step x the box diagonal.
  double sampling_step = 0.1;
  // relativeDistanceStep: OpenCV 4.6's trainModel quantises distances with relativeSamplingStep
  // and ignores this (checked: 0.05, 0.1 and 0.3 give the same poses); kept equal to it.
  double distance_step = 0.1;
  double num_angles = 30;  // OpenCV's default, 12 degree bins (20 did no better)
  // match(): the candidate is sampled like the views (relativeSceneDistance, relative to its own
  // box, which is about a view's) and every 1/scene_sample_step-th sampled point votes.
  double scene_distance = 0.1;
  double scene_sample_step = 0.2;  // OpenCV's default, 1/5
  // Pose clustering (setSearchParams). OpenCV's defaults are relative numbers used as absolute
  // ones (a position threshold of relativeSamplingStep metres, a rotation threshold of 30 rad,
  // which merges every pose within 10 cm): set here in metres and degrees.
  double position_threshold = 0.01;
  double rotation_threshold_deg = 12;  // one angle bin
  // The best clusters (most votes) refined with ICP; the lowest ICP residual wins. The best 3
  // named fewer tests right than the best one alone: the residual misranks the refined poses.
  int refine = 1;
  // cv::ppf_match_3d::ICP: point-to-plane, picky, robust rejection (2.5 sigma), a pyramid of
  // levels; the sample's tolerance and rejection, 4 levels for views of a few hundred points.
  int icp_iterations = 100;
  float icp_tolerance = 0.005f;
  float icp_rejection_scale = 2.5f;
  int icp_levels = 4;
};

// One detector per database view, trained at construction (points and normals of Cloud, model
// frame); align() matches the candidate's points and normals against each, refines the best
// `refine` poses with ICP (the view's points onto the candidate's) and returns the best per view.
// Training and matching run over `threads` OpenMP threads (0 = all cores), views spread like the
// other peers'. Neither PPF nor OpenCV's ICP draws random numbers: results do not depend on the
// seed or the thread count. Not reentrant: one align() at a time (a detector's match() writes
// its state).
class PpfPeer {
 public:
  PpfPeer(const Database& db, const PpfParams& params, int threads);
  ~PpfPeer();
  PpfPeer(const PpfPeer&) = delete;
  PpfPeer& operator=(const PpfPeer&) = delete;
  double train_ms() const;  // wall time of training every view's detector (construction)
  // One alignment per database view; `seed` is unused (nothing is random), kept for symmetry.
  std::vector<PeerAlignment> align(const Cloud& candidate, int seed) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace proxseg::peers
