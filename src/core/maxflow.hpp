// Minimum s-t cut of a graph with integer capacities, for the MRF's graph-cut moves [paper 3.2]:
// the Boykov-Kolmogorov augmenting-path algorithm (Boykov & Kolmogorov, "An experimental
// comparison of min-cut/max-flow algorithms for energy minimization in vision", PAMI 2004), on
// flat arrays that are reused from one move to the next.
//
// The cut reported is canonical: a node is on the source side exactly when it is reachable from
// the source in the residual graph of the maximum flow. That set is the same for every maximum
// flow (the smallest source side of all minimum cuts), so the answer does not depend on the order
// in which paths were found.
#pragma once

#include <cstdint>
#include <deque>
#include <vector>

namespace proxseg {

class MaxFlow {
 public:
  using Cap = std::int64_t;

  // Starts a new graph of `nodes` inner nodes and no edges; buffers keep their storage.
  void reset(int nodes);
  // Terminal capacities of node i: source -> i and i -> sink. Only their difference is kept:
  // the common part is flow that goes s -> i -> t.
  void set_terminals(int i, Cap from_source, Cap to_sink) {
    flow_ += from_source < to_sink ? from_source : to_sink;
    nodes_[static_cast<std::size_t>(i)].terminal = from_source - to_sink;
  }
  // Arcs i -> j (capacity cap_ij) and j -> i (cap_ji).
  void add_edge(int i, int j, Cap cap_ij, Cap cap_ji) {
    const int a = static_cast<int>(arcs_.size());
    Node& ni = nodes_[static_cast<std::size_t>(i)];
    Node& nj = nodes_[static_cast<std::size_t>(j)];
    arcs_.push_back({j, ni.first, cap_ij});
    arcs_.push_back({i, nj.first, cap_ji});
    ni.first = a;
    nj.first = a + 1;
  }
  // Runs the maximum flow; returns its value. Afterwards on_source_side() tells the cut.
  Cap solve();
  bool on_source_side(int i) const { return source_side_[static_cast<std::size_t>(i)] != 0; }

 private:
  static constexpr int kFree = -1, kTerminal = -2, kOrphan = -3;  // parent of a node
  struct Node {
    int first = -1;        // first out-arc
    int parent = kFree;    // arc to the parent in its tree, or kFree / kTerminal / kOrphan
    int next = -1;         // next active node; itself when last; -1 when not active
    int ts = 0, dist = 0;  // time stamp and distance to the terminal, for the adoption heuristic
    bool sink = false;     // in the sink tree (meaningful when parent != kFree)
    Cap terminal = 0;      // residual source -> node (> 0) or node -> sink (< 0)
  };
  struct Arc {
    int head = 0;   // node the arc points to
    int next = -1;  // next out-arc of the same tail
    Cap residual = 0;
  };
  // The arcs come in pairs: arc a and its reverse a ^ 1.
  static int sister(int a) { return a ^ 1; }

  void set_active(int i);
  int next_active();
  void augment(int middle);
  void set_orphan_front(int i);
  void set_orphan_rear(int i);
  void adopt(int i);
  void mark_source_side();

  std::vector<Node> nodes_;
  std::vector<Arc> arcs_;
  int queue_first_[2] = {-1, -1}, queue_last_[2] = {-1, -1};
  std::deque<int> orphans_;  // waiting for adoption
  int time_ = 0;
  Cap flow_ = 0;
  std::vector<char> source_side_;
  std::vector<int> stack_;
};

}  // namespace proxseg
