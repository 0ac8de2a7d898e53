// MRF refinement [paper 3.2, eq. 1-3]: Potts energy minimised by alpha-beta swap (Boykov, Veksler,
// Zabih 2001) or alpha-expansion (Kolmogorov, Zabih 2004 construction) on a Boykov-Kolmogorov
// max-flow (maxflow.hpp).
#include <proxseg/core/mrf.hpp>

#include "maxflow.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace proxseg {
namespace {

// Smallest value of 1 - d/sum(d) before the logarithm; keeps psi large but finite.
constexpr double kMinOneMinusRatio = 1e-9;

// A binary s-t cut problem over m inner nodes, solved by MaxFlow (maxflow.hpp), whose
// buffers are reused by every move. Node i on the source side pays cap_sink[i] (its i->t arc is
// cut), on the sink side cap_source[i]; an edge (i, j) with capacities (c_ij, c_ji) costs c_ij
// when i is on the source side and j on the sink side, c_ji in the opposite case.
class BinaryCut {
 public:
  void reset(int m) {
    m_ = m;
    cap_source_.assign(static_cast<std::size_t>(m), 0.0);
    cap_sink_.assign(static_cast<std::size_t>(m), 0.0);
    edges_.clear();
  }
  void set_tlinks(int i, double cap_source, double cap_sink) {
    cap_source_[static_cast<std::size_t>(i)] = cap_source;
    cap_sink_[static_cast<std::size_t>(i)] = cap_sink;
  }
  void add_edge(int i, int j, double cap_ij, double cap_ji) {
    edges_.push_back({i, j, cap_ij, cap_ji});
  }

  // Runs the max-flow; afterwards on_source_side(i) tells the side of node i in the minimum cut
  // (the smallest source side, whatever the order of augmentation).
  void solve() {
    // Integer capacities: with doubles, rounding leaves tiny positive residuals on arcs that should
    // be saturated and the search then spends most of its time pushing ~1e-16 of flow around.
    // Every flow and residual value is bounded by the sum of all capacities, which is mapped to
    // 2^52 (so the cut is exact up to ~1e-16 of the total; moves are accepted on the exact energy
    // anyway).
    double total = 0;
    for (int i = 0; i < m_; ++i) total += cap_source_[i] + cap_sink_[i];
    for (const auto& e : edges_) total += e.cap_ij + e.cap_ji;
    const double scale = total > 0 ? std::min(4503599627370496.0 / total, 1e300) : 1.0;
    // std::llround for 0 <= c * scale <= 2^52, where the fraction x - trunc(x) is exact, without
    // the library call (a tenth of the MRF's instructions).
    auto quantize = [scale](double c) {
      const double x = c * scale;
      const MaxFlow::Cap t = static_cast<MaxFlow::Cap>(x);
      return t + (x - static_cast<double>(t) >= 0.5);
    };
    flow_.reset(m_);
    for (int i = 0; i < m_; ++i)
      flow_.set_terminals(i, quantize(cap_source_[i]), quantize(cap_sink_[i]));
    for (const auto& e : edges_) flow_.add_edge(e.i, e.j, quantize(e.cap_ij), quantize(e.cap_ji));
    flow_.solve();
  }
  bool on_source_side(int i) const { return flow_.on_source_side(i); }

 private:
  struct PairEdge {
    int i, j;
    double cap_ij, cap_ji;
  };
  int m_ = 0;
  std::vector<double> cap_source_, cap_sink_;
  std::vector<PairEdge> edges_;
  MaxFlow flow_;
};

void validate(const MrfProblem& problem, const std::vector<int>& labels) {
  const int n = problem.nodes(), k = problem.labels();
  if (static_cast<int>(labels.size()) != n)
    throw std::invalid_argument("mrf: labels size " + std::to_string(labels.size()) + " != nodes " +
                                std::to_string(n));
  if (n > 0 && k < 1) throw std::invalid_argument("mrf: problem has nodes but no labels");
  for (int l : labels)
    if (l < 0 || l >= k) throw std::invalid_argument("mrf: label out of range");
  for (const auto& [a, b] : problem.edges)
    if (a < 0 || b < 0 || a >= n || b >= n) throw std::invalid_argument("mrf: edge out of range");
  if (!std::isfinite(problem.pairwise_weight) || problem.pairwise_weight < 0)
    throw std::invalid_argument("mrf: pairwise weight must be finite and >= 0");
  if (!problem.unary.allFinite()) throw std::invalid_argument("mrf: unary must be finite");
}

// Move-making driver shared by swap and expansion.
class MoveSolver {
 public:
  MoveSolver(const MrfProblem& problem, std::vector<int> labels)
      : p_(problem), w_(problem.pairwise_weight), labels_(std::move(labels)) {
    validate(p_, labels_);
    const int n = p_.nodes();
    // Symmetric adjacency in CSR form (self-loops dropped: they never cost anything).
    adj_off_.assign(static_cast<std::size_t>(n) + 1, 0);
    for (const auto& [a, b] : p_.edges)
      if (a != b) {
        ++adj_off_[static_cast<std::size_t>(a) + 1];
        ++adj_off_[static_cast<std::size_t>(b) + 1];
      }
    for (int v = 0; v < n; ++v) adj_off_[v + 1] += adj_off_[v];
    adj_.resize(adj_off_[n]);
    std::vector<int> fill(adj_off_.begin(), adj_off_.end() - 1);
    for (const auto& [a, b] : p_.edges)
      if (a != b) {
        adj_[fill[a]++] = b;
        adj_[fill[b]++] = a;
      }
    local_.assign(static_cast<std::size_t>(n), -1);
    count_.assign(static_cast<std::size_t>(p_.labels()), 0);
    for (int l : labels_) ++count_[l];
    result_.energy_before = energy(p_, labels_);
    current_ = result_.energy_before;
  }

  // A move is skipped when it provably cannot change anything: the swap subproblem of (a, b)
  // depends only on the set of nodes labelled a or b (fixed neighbours pay w_c with either label),
  // so it is skipped while neither label's node set has changed since (a, b) was last solved; an
  // expansion of a is skipped while no move at all was accepted since a was last expanded. The
  // result is the same as running every move, only faster.
  MrfResult run(MrfMethod method, int max_cycles) {
    const int k = p_.labels();
    if (p_.nodes() > 0 && k > 1) {
      version_.assign(static_cast<std::size_t>(k), 0);
      touched_.assign(static_cast<std::size_t>(k), 0);
      constexpr long kNever = -1;
      std::vector<std::pair<long, long>> pair_seen;
      std::vector<long> expansion_seen;
      if (method == MrfMethod::kSwap)
        pair_seen.assign(static_cast<std::size_t>(k) * static_cast<std::size_t>(k),
                         {kNever, kNever});
      else
        expansion_seen.assign(static_cast<std::size_t>(k), kNever);
      for (int cycle = 0; cycle < max_cycles; ++cycle) {
        bool improved = false;
        if (method == MrfMethod::kSwap) {
          for (int a = 0; a < k; ++a)
            for (int b = a + 1; b < k; ++b) {
              auto& seen = pair_seen[static_cast<std::size_t>(a) * k + b];
              if (count_[a] + count_[b] == 0 || seen == std::make_pair(version_[a], version_[b]))
                continue;
              improved |= swap_move(a, b);
              seen = {version_[a], version_[b]};
            }
        } else {
          for (int a = 0; a < k; ++a) {
            if (count_[a] == p_.nodes() || expansion_seen[a] == accepted_) continue;
            improved |= expansion_move(a);
            expansion_seen[a] = accepted_;
          }
        }
        ++result_.cycles;
        if (!improved) break;
      }
    }
    result_.energy_after = energy(p_, labels_);
    result_.labels = std::move(labels_);
    return std::move(result_);
  }

 private:
  int deg_begin(int v) const { return adj_off_[v]; }
  int deg_end(int v) const { return adj_off_[v + 1]; }

  // Nodes labelled a or b; source side -> a, sink side -> b.
  bool swap_move(int a, int b) {
    set_.clear();
    for (int v = 0; v < p_.nodes(); ++v)
      if (labels_[v] == a || labels_[v] == b) {
        local_[v] = static_cast<int>(set_.size());
        set_.push_back(v);
      }
    const int m = static_cast<int>(set_.size());
    cut_.reset(m);
    for (int i = 0; i < m; ++i) {
      const int v = set_[i];
      double cost_a = p_.unary(v, a), cost_b = p_.unary(v, b);
      for (int e = deg_begin(v); e < deg_end(v); ++e) {
        const int q = adj_[e];
        if (local_[q] < 0) {  // fixed neighbour: Potts cost it would pay with each label
          cost_a += w_ * (labels_[q] != a);
          cost_b += w_ * (labels_[q] != b);
        } else if (q > v) {
          cut_.add_edge(i, local_[q], w_, w_);
        }
      }
      const double mn = std::min(cost_a, cost_b);
      cut_.set_tlinks(i, cost_b - mn, cost_a - mn);
    }
    cut_.solve();
    proposal_.resize(static_cast<std::size_t>(m));
    for (int i = 0; i < m; ++i) proposal_[i] = cut_.on_source_side(i) ? a : b;
    return try_accept();
  }

  // Nodes not labelled a; source side -> keep the label, sink side -> switch to a.
  bool expansion_move(int a) {
    set_.clear();
    for (int v = 0; v < p_.nodes(); ++v)
      if (labels_[v] != a) {
        local_[v] = static_cast<int>(set_.size());
        set_.push_back(v);
      }
    const int m = static_cast<int>(set_.size());
    cut_.reset(m);
    cost_keep_.assign(static_cast<std::size_t>(m), 0.0);
    cost_switch_.assign(static_cast<std::size_t>(m), 0.0);
    for (int i = 0; i < m; ++i) {
      const int v = set_[i];
      cost_keep_[i] += p_.unary(v, labels_[v]);
      cost_switch_[i] += p_.unary(v, a);
      for (int e = deg_begin(v); e < deg_end(v); ++e) {
        const int q = adj_[e];
        if (local_[q] < 0) {  // neighbour already labelled a
          cost_keep_[i] += w_;
        } else if (q > v) {
          const int j = local_[q];
          if (labels_[v] == labels_[q]) {
            cut_.add_edge(i, j, w_, w_);
          } else {
            // E(keep,keep) = E(keep,switch) = E(switch,keep) = w, E(switch,switch) = 0, written as
            // w - w [j switches] + w [i keeps, j switches] (Kolmogorov & Zabih 2004).
            cut_.add_edge(i, j, w_, 0.0);
            cost_switch_[j] -= w_;
          }
        }
      }
    }
    for (int i = 0; i < m; ++i) {
      const double mn = std::min(cost_keep_[i], cost_switch_[i]);
      cut_.set_tlinks(i, cost_switch_[i] - mn, cost_keep_[i] - mn);
    }
    cut_.solve();
    proposal_.resize(static_cast<std::size_t>(m));
    for (int i = 0; i < m; ++i) proposal_[i] = cut_.on_source_side(i) ? labels_[set_[i]] : a;
    return try_accept();
  }

  // Exact energy change of proposal_ (labels for set_), applied only if it strictly lowers E.
  // Clears local_ for the set in any case.
  bool try_accept() {
    const int m = static_cast<int>(set_.size());
    auto new_label = [&](int q) { return local_[q] >= 0 ? proposal_[local_[q]] : labels_[q]; };
    double delta = 0;
    for (int i = 0; i < m; ++i) {
      const int v = set_[i], nl = proposal_[i], ol = labels_[v];
      if (nl == ol) continue;
      delta += p_.unary(v, nl) - p_.unary(v, ol);
      for (int e = deg_begin(v); e < deg_end(v); ++e) {
        const int q = adj_[e];
        const int nq = new_label(q), oq = labels_[q];
        if (nq != oq && q < v) continue;  // both ends changed: counted once, from the smaller end
        delta += w_ * (static_cast<int>(nl != nq) - static_cast<int>(ol != oq));
      }
    }
    const double tol = 1e-12 * (1.0 + std::abs(current_));
    const bool accept = delta < -tol;
    for (int i = 0; i < m; ++i) {
      const int v = set_[i];
      if (accept && proposal_[i] != labels_[v]) {
        --count_[labels_[v]];
        ++count_[proposal_[i]];
        touched_[labels_[v]] = touched_[proposal_[i]] = 1;
        labels_[v] = proposal_[i];
      }
      local_[v] = -1;
    }
    if (accept) {
      current_ += delta;
      result_.energy_trace.push_back(current_);
      ++accepted_;
      for (std::size_t l = 0; l < touched_.size(); ++l)
        if (touched_[l]) {
          ++version_[l];
          touched_[l] = 0;
        }
    }
    return accept;
  }

  const MrfProblem& p_;
  const double w_;
  std::vector<int> labels_;
  std::vector<int> adj_off_, adj_, local_, count_, set_, proposal_;
  std::vector<double> cost_keep_, cost_switch_;
  BinaryCut cut_;
  double current_ = 0;
  long accepted_ = 0;          // accepted moves so far
  std::vector<long> version_;  // per label: bumped whenever its node set changes
  std::vector<char> touched_;  // scratch: labels whose node set the current move changes
  MrfResult result_;
};

}  // namespace

Eigen::MatrixXd unary_potentials(const Eigen::MatrixXd& x, const Eigen::MatrixXd& centroids,
                                 double unary_weight) {
  const Eigen::Index n = x.rows(), k = centroids.rows();
  if (k > 0 && centroids.cols() != x.cols())
    throw std::invalid_argument("unary_potentials: feature and centroid dimensions differ");
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(n, k);
  if (k <= 1) return u;
  Eigen::VectorXd d(k);
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index l = 0; l < k; ++l) d(l) = (x.row(j) - centroids.row(l)).norm();
    const double sum = d.sum();
    if (!(sum > 0)) continue;  // feature equals every centroid: all labels cost the same (0)
    for (Eigen::Index l = 0; l < k; ++l)
      u(j, l) = -unary_weight * std::log(std::max(1.0 - d(l) / sum, kMinOneMinusRatio));
  }
  return u;
}

std::vector<std::pair<int, int>> edge_list(const std::vector<std::vector<int>>& neighbours) {
  std::vector<std::pair<int, int>> edges;
  for (int j = 0; j < static_cast<int>(neighbours.size()); ++j)
    for (int k : neighbours[j])
      if (k != j) edges.emplace_back(std::min(j, k), std::max(j, k));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

double energy(const MrfProblem& problem, const std::vector<int>& labels) {
  if (static_cast<int>(labels.size()) != problem.nodes())
    throw std::invalid_argument("energy: labels size != nodes");
  double e = 0;
  for (int j = 0; j < problem.nodes(); ++j) {
    if (labels[j] < 0 || labels[j] >= problem.labels())
      throw std::invalid_argument("energy: label out of range");
    e += problem.unary(j, labels[j]);
  }
  for (const auto& [a, b] : problem.edges) {
    if (a < 0 || b < 0 || a >= problem.nodes() || b >= problem.nodes())
      throw std::invalid_argument("energy: edge out of range");
    if (labels[a] != labels[b]) e += problem.pairwise_weight;
  }
  return e;
}

MrfResult alpha_beta_swap(const MrfProblem& problem, std::vector<int> labels, int max_cycles) {
  return MoveSolver(problem, std::move(labels)).run(MrfMethod::kSwap, max_cycles);
}

MrfResult alpha_expansion(const MrfProblem& problem, std::vector<int> labels, int max_cycles) {
  return MoveSolver(problem, std::move(labels)).run(MrfMethod::kExpansion, max_cycles);
}

}  // namespace proxseg
