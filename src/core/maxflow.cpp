// Boykov-Kolmogorov maximum flow (see maxflow.hpp): two search trees, S from the source and T
// from the sink, grow along arcs with residual capacity until they touch; the path found is
// augmented, the nodes it cut off (orphans) look for a new parent in their tree or become free,
// and growth resumes until neither tree can grow.
#include "maxflow.hpp"

#include <algorithm>
#include <limits>

namespace proxseg {

void MaxFlow::reset(int nodes) {
  nodes_.assign(static_cast<std::size_t>(nodes), Node{});
  arcs_.clear();
  flow_ = 0;
}

void MaxFlow::set_active(int i) {
  Node& n = nodes_[static_cast<std::size_t>(i)];
  if (n.next != -1) return;
  if (queue_last_[1] != -1)
    nodes_[static_cast<std::size_t>(queue_last_[1])].next = i;
  else
    queue_first_[1] = i;
  queue_last_[1] = i;
  n.next = i;
}

// The next active node, or -1. Nodes enter the second queue; the first is drained first.
int MaxFlow::next_active() {
  for (;;) {
    int i = queue_first_[0];
    if (i == -1) {
      queue_first_[0] = i = queue_first_[1];
      queue_last_[0] = queue_last_[1];
      queue_first_[1] = queue_last_[1] = -1;
      if (i == -1) return -1;
    }
    Node& n = nodes_[static_cast<std::size_t>(i)];
    if (n.next == i)
      queue_first_[0] = queue_last_[0] = -1;
    else
      queue_first_[0] = n.next;
    n.next = -1;
    if (n.parent != kFree) return i;  // free nodes left the trees since they were queued
  }
}

// Orphans cut off by an augmentation are adopted nearest-to-the-terminal first (each is put in
// front of the queue as the path is walked from the middle outwards), so that the deeper ones
// find a valid ancestor; orphans made while adopting wait at the back. The order changes the
// work, not the cut.
void MaxFlow::set_orphan_front(int i) {
  nodes_[static_cast<std::size_t>(i)].parent = kOrphan;
  orphans_.push_front(i);
}
void MaxFlow::set_orphan_rear(int i) {
  nodes_[static_cast<std::size_t>(i)].parent = kOrphan;
  orphans_.push_back(i);
}

// Pushes the bottleneck along source -> ... -> tail(middle) -> head(middle) -> ... -> sink; nodes
// whose parent arc saturates become orphans.
void MaxFlow::augment(int middle) {
  auto node = [this](int i) -> Node& { return nodes_[static_cast<std::size_t>(i)]; };
  Cap bottleneck = arcs_[static_cast<std::size_t>(middle)].residual;
  int i = arcs_[static_cast<std::size_t>(sister(middle))].head;
  for (int a; (a = node(i).parent) != kTerminal; i = arcs_[static_cast<std::size_t>(a)].head)
    bottleneck = std::min(bottleneck, arcs_[static_cast<std::size_t>(sister(a))].residual);
  bottleneck = std::min(bottleneck, node(i).terminal);
  i = arcs_[static_cast<std::size_t>(middle)].head;
  for (int a; (a = node(i).parent) != kTerminal; i = arcs_[static_cast<std::size_t>(a)].head)
    bottleneck = std::min(bottleneck, arcs_[static_cast<std::size_t>(a)].residual);
  bottleneck = std::min(bottleneck, -node(i).terminal);

  arcs_[static_cast<std::size_t>(sister(middle))].residual += bottleneck;
  arcs_[static_cast<std::size_t>(middle)].residual -= bottleneck;
  i = arcs_[static_cast<std::size_t>(sister(middle))].head;
  for (int a; (a = node(i).parent) != kTerminal;) {
    arcs_[static_cast<std::size_t>(a)].residual += bottleneck;
    Cap& back = arcs_[static_cast<std::size_t>(sister(a))].residual;
    back -= bottleneck;
    const int up = arcs_[static_cast<std::size_t>(a)].head;
    if (back == 0) set_orphan_front(i);
    i = up;
  }
  node(i).terminal -= bottleneck;
  if (node(i).terminal == 0) set_orphan_front(i);
  i = arcs_[static_cast<std::size_t>(middle)].head;
  for (int a; (a = node(i).parent) != kTerminal;) {
    arcs_[static_cast<std::size_t>(sister(a))].residual += bottleneck;
    Cap& forward = arcs_[static_cast<std::size_t>(a)].residual;
    forward -= bottleneck;
    const int up = arcs_[static_cast<std::size_t>(a)].head;
    if (forward == 0) set_orphan_front(i);
    i = up;
  }
  node(i).terminal += bottleneck;
  if (node(i).terminal == 0) set_orphan_front(i);
  flow_ += bottleneck;
}

// An orphan looks for a new parent in its own tree: a neighbour with residual capacity towards
// it (away from it in the sink tree) whose path to the terminal does not run through an orphan,
// the one closest to the terminal. Without one it becomes free, its neighbours in the tree
// become active and its children orphans.
void MaxFlow::adopt(int i) {
  constexpr int kInfinite = std::numeric_limits<int>::max();
  Node& n = nodes_[static_cast<std::size_t>(i)];
  const bool sink = n.sink;
  int best = kFree, best_dist = kInfinite;
  for (int a0 = n.first; a0 != -1; a0 = arcs_[static_cast<std::size_t>(a0)].next) {
    // Source tree: flow comes from the neighbour (its arc j -> i); sink tree: goes to it.
    const Cap cap = sink ? arcs_[static_cast<std::size_t>(a0)].residual
                         : arcs_[static_cast<std::size_t>(sister(a0))].residual;
    if (cap == 0) continue;
    int j = arcs_[static_cast<std::size_t>(a0)].head;
    const Node& nj = nodes_[static_cast<std::size_t>(j)];
    if (nj.sink != sink || nj.parent == kFree) continue;
    // Distance of j to its terminal, if its path does not end in an orphan.
    int d = 0;
    for (;;) {
      Node& nk = nodes_[static_cast<std::size_t>(j)];
      if (nk.ts == time_) {
        d += nk.dist;
        break;
      }
      const int a = nk.parent;
      ++d;
      if (a == kTerminal) {
        nk.ts = time_;
        nk.dist = 1;
        break;
      }
      if (a == kOrphan) {
        d = kInfinite;
        break;
      }
      j = arcs_[static_cast<std::size_t>(a)].head;
    }
    if (d == kInfinite) continue;
    if (d < best_dist) {
      best = a0;
      best_dist = d;
    }
    // Stamp the path, so later searches stop early.
    for (j = arcs_[static_cast<std::size_t>(a0)].head;
         nodes_[static_cast<std::size_t>(j)].ts != time_;
         j = arcs_[static_cast<std::size_t>(nodes_[static_cast<std::size_t>(j)].parent)].head) {
      nodes_[static_cast<std::size_t>(j)].ts = time_;
      nodes_[static_cast<std::size_t>(j)].dist = d--;
    }
  }
  if (best != kFree) {
    n.parent = best;
    n.ts = time_;
    n.dist = best_dist + 1;
    return;
  }
  n.parent = kFree;
  for (int a0 = n.first; a0 != -1; a0 = arcs_[static_cast<std::size_t>(a0)].next) {
    const int j = arcs_[static_cast<std::size_t>(a0)].head;
    const Node& nj = nodes_[static_cast<std::size_t>(j)];
    if (nj.sink != sink || nj.parent == kFree) continue;
    const Cap cap = sink ? arcs_[static_cast<std::size_t>(a0)].residual
                         : arcs_[static_cast<std::size_t>(sister(a0))].residual;
    if (cap > 0) set_active(j);
    if (nj.parent >= 0 && arcs_[static_cast<std::size_t>(nj.parent)].head == i) set_orphan_rear(j);
  }
}

MaxFlow::Cap MaxFlow::solve() {
  queue_first_[0] = queue_first_[1] = queue_last_[0] = queue_last_[1] = -1;
  orphans_.clear();
  time_ = 0;
  const int m = static_cast<int>(nodes_.size());
  for (int i = 0; i < m; ++i) {
    Node& n = nodes_[static_cast<std::size_t>(i)];
    n.next = -1;
    n.ts = 0;
    if (n.terminal != 0) {
      n.sink = n.terminal < 0;
      n.parent = kTerminal;
      n.dist = 1;
      set_active(i);
    } else {
      n.parent = kFree;
    }
  }
  int current = -1;  // the node being grown stays active after an augmentation
  for (;;) {
    int i = current;
    if (i != -1) {
      nodes_[static_cast<std::size_t>(i)].next = -1;
      if (nodes_[static_cast<std::size_t>(i)].parent == kFree) i = -1;
    }
    if (i == -1 && (i = next_active()) == -1) break;
    Node& n = nodes_[static_cast<std::size_t>(i)];
    // Grow the tree of i by one layer, or find an arc into the other tree.
    int middle = -1;
    for (int a = n.first; a != -1; a = arcs_[static_cast<std::size_t>(a)].next) {
      const Cap cap = n.sink ? arcs_[static_cast<std::size_t>(sister(a))].residual
                             : arcs_[static_cast<std::size_t>(a)].residual;
      if (cap == 0) continue;
      const int j = arcs_[static_cast<std::size_t>(a)].head;
      Node& nj = nodes_[static_cast<std::size_t>(j)];
      if (nj.parent == kFree) {
        nj.sink = n.sink;
        nj.parent = sister(a);
        nj.ts = n.ts;
        nj.dist = n.dist + 1;
        set_active(j);
      } else if (nj.sink != n.sink) {
        middle = n.sink ? sister(a) : a;  // the path's arc from the source tree to the sink tree
        break;
      } else if (nj.ts <= n.ts && nj.dist > n.dist) {  // a shorter way to the terminal
        nj.parent = sister(a);
        nj.ts = n.ts;
        nj.dist = n.dist + 1;
      }
    }
    ++time_;
    if (middle == -1) {
      current = -1;
      continue;
    }
    n.next = i;  // stays active (set_active would queue it)
    current = i;
    augment(middle);
    while (!orphans_.empty()) {
      const int orphan = orphans_.front();
      orphans_.pop_front();
      adopt(orphan);
    }
  }
  mark_source_side();
  return flow_;
}

// The canonical cut: what the source reaches through arcs with residual capacity.
void MaxFlow::mark_source_side() {
  const std::size_t m = nodes_.size();
  source_side_.assign(m, 0);
  stack_.clear();
  for (std::size_t i = 0; i < m; ++i)
    if (nodes_[i].terminal > 0) {
      source_side_[i] = 1;
      stack_.push_back(static_cast<int>(i));
    }
  while (!stack_.empty()) {
    const int i = stack_.back();
    stack_.pop_back();
    for (int a = nodes_[static_cast<std::size_t>(i)].first; a != -1;
         a = arcs_[static_cast<std::size_t>(a)].next) {
      const Arc& arc = arcs_[static_cast<std::size_t>(a)];
      if (arc.residual > 0 && !source_side_[static_cast<std::size_t>(arc.head)]) {
        source_side_[static_cast<std::size_t>(arc.head)] = 1;
        stack_.push_back(arc.head);
      }
    }
  }
}

}  // namespace proxseg
