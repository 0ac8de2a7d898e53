// rec_bench's rows (rec_bench.hpp): proxseg with its defaults and the sweeps (one change each,
// like the paper's Table 2), and the registration peers (Open3D RANSAC and FGR, PCL, OpenCV PPF)
// named exactly as proxseg names, so that the rows differ only in registration.
#include <proxseg/core/errors.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <omp.h>

#include <algorithm>
#include <functional>
#include <iostream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bench_util.hpp"
#include "rec_bench.hpp"

#ifdef PROXSEG_WITH_PEERS
#include "peers_rec.hpp"
#endif

namespace proxseg::bench::recbench {
namespace {

using Recognizer = std::function<Answer(const TestView&)>;

// Algorithm 3 as proxseg does it: describe the test view like the database, align every view.
Recognizer proxseg_recognizer(const Database& db, const RecognitionParams& rp) {
  return [&db, rp](const TestView& t) {
    const auto t0 = Clock::now();
    Answer a;
    try {
      const proxseg::Cloud c = proxseg::describe_candidate(t.points, db);
      a.describe_ms = ms_since(t0);
      const proxseg::Recognition r = proxseg::recognize(c, db, rp);
      a.best = r.best.object;
      a.score = r.best.score;
      a.pose = r.best.pose;
      for (const proxseg::Alignment& x : r.alignments) {
        a.ransac_ms += x.ransac_ms;
        a.icp_ms += x.icp_ms;
        a.score_ms += x.score_ms;
      }
    } catch (const InputError&) {
      // Too few points left to describe (a heavy occlusion of a far view): no answer.
    }
    a.ms = ms_since(t0);
    return a;
  };
}

#ifdef PROXSEG_WITH_PEERS
// Names the test after the best-scoring view exactly as proxseg::recognize does (the same
// scores, score rule and ties to the earlier view) from a peer's poses, so that the rows compare
// whole recognisers that differ only in registration.
template <class Peer>
std::function<Answer(const TestView&)> peer_recognizer(const Peer& peer,
                                                       const proxseg::Database& db,
                                                       const proxseg::RecognitionParams& rp,
                                                       int threads) {
  return [&peer, &db, rp, threads](const TestView& t) {
    const auto t0 = Clock::now();
    Answer a;
    proxseg::Cloud c;
    try {
      c = proxseg::describe_candidate(t.points, db);
    } catch (const InputError&) {
      a.ms = ms_since(t0);
      return a;
    }
    a.describe_ms = ms_since(t0);
    const std::vector<proxseg::peers::PeerAlignment> aligned =
        peer.align(c, static_cast<int>(rp.seed));
    const int n = static_cast<int>(aligned.size());
    std::vector<double> score(n, 0), rank(n, 0), score_ms(n, 0);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int v = 0; v < n; ++v) {
      if (!aligned[v].found) continue;  // no hypothesis, no pose to score: 0
      const auto ts = Clock::now();
      const proxseg::Alignment scored =
          proxseg::score_pose(c, db.views[v].cloud(), aligned[v].pose, rp.registration);
      score[v] = proxseg::score_of(scored, rp.score);
      rank[v] = proxseg::rank_of(scored, rp.score);
      score_ms[v] = ms_since(ts);
    }
    for (int v = 0; v < n; ++v) {
      a.ransac_ms += aligned[v].ransac_ms;
      a.icp_ms += aligned[v].icp_ms;
      a.score_ms += score_ms[v];
    }
    // Ranked allowing for an occlusion, judged on the score, as recognize() does.
    const int best = static_cast<int>(std::max_element(rank.begin(), rank.end()) - rank.begin());
    if (n > 0 && aligned[best].found) {
      a.best = db.views[best].object;
      a.score = score[best];
      a.pose = aligned[best].pose;
    }
    a.ms = ms_since(t0);
    return a;
  };
}
#endif

// A row of proxseg with database `d` (of `views` per object) and parameters `p`.
Row proxseg_row(const std::string& label, const std::string& kind, int paper, const Database& d,
                const RecognitionParams& p, int views) {
  Row r;
  r.label = label;
  r.kind = kind;
  r.paper = paper;
  r.views = views;
  r.radii = d.descriptor.fpfh_radii;
  r.ransac = p.registration.ransac_iterations;
  r.icp = p.registration.icp_iterations;
  r.run = proxseg_recognizer(d, p);
  return r;
}

// A sweep's row on its own database (`views` per object, descriptor `d`), which the row keeps.
Row sweep_row(const std::string& label, int paper, const Bench& b, int views,
              const DescriptorParams& d) {
  auto db = std::make_shared<const Database>(render_database(b.objects, views, d));
  Row r = proxseg_row(label, "sweep", paper, *db, b.rp, views);
  r.owned = db;
  return r;
}

#ifdef PROXSEG_WITH_PEERS
// A row of `peer` (made on the run's database, kept by the row).
template <class Peer>
Row peer_row(const Bench& b, std::shared_ptr<const Peer> peer) {
  Row r;
  r.kind = "peer";
  r.radii = b.descriptor.fpfh_radii;
  r.run = peer_recognizer(*peer, b.db, b.rp, b.team);
  r.owned = peer;
  return r;
}

Row peer_row(const std::string& name, const Options& o, const Bench& b) {
  namespace peers = proxseg::peers;
  Row r;
  // The row of a peer: its label, RANSAC iterations (0: none) and ICP iterations.
  const auto row_of = [&](auto peer, const char* label, int ransac, int icp) {
    Row row = peer_row(b, std::move(peer));
    row.label = label;
    row.ransac = ransac;
    row.icp = icp;
    return row;
  };
  if (name == "open3d") {
    peers::Open3dParams o3d;
    o3d.ransac_iterations = 100000;  // its 4M default: 2.5x the time, no gain (docs/method.md)
    r = row_of(std::make_shared<const peers::Open3dPeer>(b.db, o3d, o.threads),
               "Open3D RANSAC 100k + ICP", o3d.ransac_iterations, o3d.icp_iterations);
  } else if (name == "pcl") {
    const peers::PclParams pcl;
    r = row_of(std::make_shared<const peers::PclPeer>(b.db, pcl, o.threads),
               "PCL SAC-prerejective 50k + ICP", pcl.ransac_iterations, pcl.icp_iterations);
    r.radii.resize(1);  // its point type holds one histogram
  } else if (name == "fgr") {
    const peers::FgrParams fgr;
    r = row_of(std::make_shared<const peers::FgrPeer>(b.db, fgr, o.threads), "Open3D FGR + ICP", 0,
               fgr.icp_iterations);  // no RANSAC
  } else {
#ifdef PROXSEG_WITH_PPF
    const peers::PpfParams ppf;
    const auto peer = std::make_shared<const peers::PpfPeer>(b.db, ppf, o.threads);
    r = peer_row(b, peer);
    r.label = "OpenCV PPF + ICP";
    r.radii.clear();  // point pair features, no FPFH
    r.icp = ppf.icp_iterations;
    r.train_ms = peer->train_ms();
    std::cerr << "rec_bench: OpenCV PPF detectors of " << b.db.views.size() << " views trained in "
              << fixed(r.train_ms / 1000, 2) << " s\n";
#endif
  }
  r.views = o.views;
  return r;
}
#endif

}  // namespace

// The peers in the order of their rows (and of --peers all).
constexpr const char* kPeerNames[] = {"open3d", "pcl", "ppf", "fgr"};

std::vector<std::string> peer_list(const std::string& spec) {
  std::vector<std::string> available;
#ifdef PROXSEG_WITH_PEERS
  available = {"open3d", "pcl", "fgr"};
#ifdef PROXSEG_WITH_PPF
  available.insert(available.begin() + 2, "ppf");
#endif
#endif
  if (spec == "none") return {};
  if (spec == "all") return available;
  std::vector<std::string> out;
  std::stringstream in(spec);
  std::string name;
  while (std::getline(in, name, ',')) {
    if (std::find(std::begin(kPeerNames), std::end(kPeerNames), name) == std::end(kPeerNames))
      throw CLI::ValidationError("--peers: unknown peer '" + name +
                                 "' (expected open3d, pcl, ppf, fgr)");
    if (std::find(available.begin(), available.end(), name) == available.end())
      throw CLI::ValidationError(
          "--peers: this build has no peer '" + name +
          "' (PCL, or OpenCV contrib for ppf, was not found when it was built: run "
          "scripts/install-deps.sh --bench, then rebuild)");
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
  }
  return out;
}

void add_proxseg_rows(const Options& o, Bench& b) {
  b.rows.push_back(proxseg_row("proxseg", "proxseg", 0, b.db, b.rp, o.views));
  b.rows.back().clean_tests = static_cast<int>(b.clean.size());
  b.rows.back().occluded_tests = static_cast<int>(b.occluded.size());
  b.sweep_tests = o.no_sweep ? 0 : std::min<int>(o.sweep_tests, b.clean.size());
  if (b.sweep_tests == 0) return;
  for (int views : {4, 2})
    if (views < o.views)
      b.rows.push_back(sweep_row(std::to_string(views) + " views per object", views == 4 ? 1 : 3, b,
                                 views, b.descriptor));
  const std::pair<std::vector<double>, int> radii[] = {{{0.015}, 4}, {{0.01, 0.02, 0.04}, 2}};
  for (const auto& [r, paper] : radii) {
    DescriptorParams d = b.descriptor;
    d.fpfh_radii = r;
    b.rows.push_back(sweep_row("FPFH " + radii_mm(r) + " mm", paper, b, o.views, d));
  }
  RecognitionParams fewer = b.rp;
  fewer.registration.ransac_iterations = 250;
  fewer.registration.icp_iterations = 10;
  b.rows.push_back(proxseg_row("RANSAC 250, ICP 10", "sweep", 5, b.db, fewer, o.views));
  for (std::size_t i = 1; i < b.rows.size(); ++i) b.rows[i].clean_tests = b.sweep_tests;
}

void add_peer_rows([[maybe_unused]] const Options& o, const std::vector<std::string>& peers,
                   [[maybe_unused]] Bench& b) {
#ifdef PROXSEG_WITH_PEERS
  for (const std::string& peer : peers) {
    Row r = peer_row(peer, o, b);
    r.clean_tests = std::min<int>(o.peer_tests, b.clean.size());
    r.occluded_tests = std::min<int>(o.peer_tests, b.occluded.size());
    b.rows.push_back(std::move(r));
  }
#else
  (void)peers;
#endif
}

}  // namespace proxseg::bench::recbench
