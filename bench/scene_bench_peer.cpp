// scene_bench's peer pipeline (scene_bench.hpp): PCL plane + Euclidean clusters as candidates,
// each aligned to every view by Open3D and named as proxseg names.
#include <proxseg/core/errors.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "peer_naming.hpp"
#include "peers_pcl.hpp"
#include "scene_bench.hpp"

namespace proxseg::bench::scenebench {
namespace {

std::vector<std::vector<int>> segments_of(const std::vector<std::uint32_t>& labels,
                                          std::uint32_t first) {
  std::map<std::uint32_t, std::vector<int>> by_label;
  for (std::size_t k = 0; k < labels.size(); ++k)
    if (labels[k] >= first) by_label[labels[k]].push_back(static_cast<int>(k));
  std::vector<std::vector<int>> out;
  for (auto& [label, pts] : by_label) out.push_back(std::move(pts));
  return out;
}

}  // namespace

std::vector<Prediction> peer_scene(const Frame& frame, const Database& db,
                                   const peers::Open3dPeer& open3d, const RecognitionParams& rp,
                                   int threads) {
  bool plane = false;
  const std::vector<std::uint32_t> labels = peers::euclidean(frame, {}, &plane);
  std::vector<Prediction> out;
  for (std::vector<int>& points : segments_of(labels, plane ? 2 : 1)) {
    std::vector<Eigen::Vector3d> xyz;
    std::vector<Rgb> rgb;
    xyz.reserve(points.size());
    for (int k : points) {
      xyz.push_back(frame.xyz[k].cast<double>());
      if (frame.rgb.size() == frame.size()) rgb.push_back(frame.rgb[k]);
    }
    Cloud c;
    try {
      c = describe_candidate(xyz, db, rgb.empty() ? nullptr : &rgb);
    } catch (const InputError&) {
      continue;
    }
    const peers::PeerAnswer a =
        peers::name_alignments(c, open3d.align(c, static_cast<int>(rp.seed)), db, rp, threads);
    Prediction p;
    p.points = std::move(points);
    p.name = a.name;
    p.best = a.best;
    p.score = a.score;
    p.runner_up = a.runner_up;
    p.colour = a.colour;
    p.pose = a.pose;
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace proxseg::bench::scenebench
