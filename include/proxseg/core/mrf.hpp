// MRF refinement of the labels [paper 3.2, eq. 1-3]: Potts model minimised by graph cuts.
#pragma once
#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

namespace proxseg {

enum class MrfMethod { kSwap, kExpansion };
// The names of its values, in its order: how the CLI, JSON configs and Python spell them.
inline std::vector<std::string> value_names(MrfMethod) {
  return {"swap", "expansion"};
}

struct MrfParams {
  bool enabled = true;
  double unary_weight = 1.0;  // w_u (paper: 1.0)
  // w_c. The paper's 0.275 (its octree neighbourhood, each pair counted twice in eq. 1) erases
  // objects under ~30 cm on the 26-neighbour voxel graph; 0.05 per unordered pair keeps them
  // (docs/method.md has the measurements).
  double pairwise_weight = 0.05;
  MrfMethod method = MrfMethod::kSwap;
  // Full sweeps over the label pairs (expansion: over the labels); fewer if a sweep lowers nothing.
  // Two sweeps give nearly all of the energy decrease of running to convergence for much less
  // time (docs/method.md, "MRF", has the figures); the paper preset runs to convergence.
  int max_cycles = 2;
};

// E(l) = sum_j unary(j, l_j) + sum_{(j,k) in edges} w_c [l_j != l_k]; each edge listed once.
struct MrfProblem {
  Eigen::MatrixXd unary;                   // nodes x labels
  std::vector<std::pair<int, int>> edges;  // j < k
  double pairwise_weight = 0;
  int nodes() const { return static_cast<int>(unary.rows()); }
  int labels() const { return static_cast<int>(unary.cols()); }
};

// Eq. 2 with the sign fixed: psi_j(l) = -w_u log(1 - d_jl / sum_l' d_jl'), d = Euclidean distance
// from row j of x to centroid l. With k = 1 the unary is 0.
Eigen::MatrixXd unary_potentials(const Eigen::MatrixXd& x, const Eigen::MatrixXd& centroids,
                                 double unary_weight);

// Unordered neighbour pairs (j < k) of a symmetric adjacency list.
std::vector<std::pair<int, int>> edge_list(const std::vector<std::vector<int>>& neighbours);

double energy(const MrfProblem& problem, const std::vector<int>& labels);

struct MrfResult {
  std::vector<int> labels;
  double energy_before = 0, energy_after = 0;
  int cycles = 0;                    // full sweeps done
  std::vector<double> energy_trace;  // energy after every accepted move
};

// Alpha-beta swap moves (Boykov, Veksler, Zabih 2001) on a Boykov-Kolmogorov max-flow,
// repeated over all label pairs until no swap lowers E.
MrfResult alpha_beta_swap(const MrfProblem& problem, std::vector<int> labels, int max_cycles);
// Alpha-expansion moves, same contract.
MrfResult alpha_expansion(const MrfProblem& problem, std::vector<int> labels, int max_cycles);

}  // namespace proxseg
