// Registration "peers" that the recognition benchmark (bench/rec_bench.cpp) compares proxseg
// against: Open3D's feature-matching RANSAC + ICP and PCL's SampleConsensusPrerejective + ICP,
// each aligning every view of a proxseg database to one candidate.
//
// Both peers get exactly the clouds proxseg uses (the voxel-filtered points, normals and FPFH
// of Cloud), converted once to their own types, so that the comparison is about registration
// alone. Open3D and PCL stay inside bench/peers_rec.cpp: this header needs neither.
#pragma once
#include <proxseg/database.hpp>
#include <proxseg/registration.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

namespace proxseg::peers {

// One (candidate, view) registration by a peer.
struct PeerAlignment {
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  // candidate frame <- model frame
  bool found = false;  // RANSAC returned a hypothesis (ICP runs only from one)
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

}  // namespace proxseg::peers
