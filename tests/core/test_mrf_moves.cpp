// The MRF minimisers [paper 3.2]: alpha-beta swap and alpha-expansion never increase the energy,
// reach local optima (checked by brute force), restore noisy regions, survive degenerate problems,
// are deterministic, and converge on a voxel-like problem of the typical size.
#include <proxseg/core/mrf.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <queue>
#include <random>
#include <set>
#include <vector>

namespace proxseg {
namespace {

using Minimiser = MrfResult (*)(const MrfProblem&, std::vector<int>, int);

MrfProblem random_problem(std::mt19937& rng, int n, int k, int n_edges, double w) {
  MrfProblem p;
  p.unary.resize(n, k);
  std::uniform_real_distribution<double> u(0.0, 2.0);
  for (int j = 0; j < n; ++j)
    for (int l = 0; l < k; ++l) p.unary(j, l) = u(rng);
  std::set<std::pair<int, int>> edges;
  const long max_edges = static_cast<long>(n) * (n - 1) / 2;
  std::uniform_int_distribution<int> node(0, std::max(0, n - 1));
  while (static_cast<long>(edges.size()) < std::min<long>(n_edges, max_edges)) {
    int a = node(rng), b = node(rng);
    if (a == b) continue;
    edges.insert({std::min(a, b), std::max(a, b)});
  }
  p.edges.assign(edges.begin(), edges.end());
  p.pairwise_weight = w;
  return p;
}

std::vector<int> random_labels(std::mt19937& rng, int n, int k) {
  std::uniform_int_distribution<int> lab(0, k - 1);
  std::vector<int> l(static_cast<std::size_t>(n));
  for (int& x : l) x = lab(rng);
  return l;
}

std::vector<int> unary_argmin(const MrfProblem& p) {
  std::vector<int> l(static_cast<std::size_t>(p.nodes()));
  for (int j = 0; j < p.nodes(); ++j) p.unary.row(j).minCoeff(&l[j]);
  return l;
}

// Lowest energy reachable by one swap move of labels (a, b) from `labels`.
double best_swap_energy(const MrfProblem& p, const std::vector<int>& labels, int a, int b) {
  std::vector<int> idx;
  for (int j = 0; j < p.nodes(); ++j)
    if (labels[j] == a || labels[j] == b) idx.push_back(j);
  double best = energy(p, labels);
  std::vector<int> trial = labels;
  for (unsigned mask = 0; mask < (1u << idx.size()); ++mask) {
    for (std::size_t i = 0; i < idx.size(); ++i) trial[idx[i]] = (mask >> i & 1u) ? b : a;
    best = std::min(best, energy(p, trial));
  }
  return best;
}

// Lowest energy reachable by one expansion move of label a from `labels`.
double best_expansion_energy(const MrfProblem& p, const std::vector<int>& labels, int a) {
  std::vector<int> idx;
  for (int j = 0; j < p.nodes(); ++j)
    if (labels[j] != a) idx.push_back(j);
  double best = energy(p, labels);
  for (unsigned mask = 0; mask < (1u << idx.size()); ++mask) {
    std::vector<int> trial = labels;
    for (std::size_t i = 0; i < idx.size(); ++i)
      if (mask >> i & 1u) trial[idx[i]] = a;
    best = std::min(best, energy(p, trial));
  }
  return best;
}

bool swap_optimal(const MrfProblem& p, const std::vector<int>& labels) {
  const double e = energy(p, labels);
  for (int a = 0; a < p.labels(); ++a)
    for (int b = a + 1; b < p.labels(); ++b)
      if (best_swap_energy(p, labels, a, b) < e - 1e-9) return false;
  return true;
}

bool expansion_optimal(const MrfProblem& p, const std::vector<int>& labels) {
  const double e = energy(p, labels);
  for (int a = 0; a < p.labels(); ++a)
    if (best_expansion_energy(p, labels, a) < e - 1e-9) return false;
  return true;
}

// ---------------------------------------------------------------------------------------------
// 3. Energy never increases

void check_monotone(Minimiser solve) {
  std::mt19937 rng(12345);
  for (int n : {5, 40, 200, 1500}) {
    for (int k = 2; k <= 6; ++k) {
      const MrfProblem p = random_problem(rng, n, k, 3 * n, 0.2 + 0.2 * (k % 3));
      const std::vector<int> init = random_labels(rng, n, k);
      const MrfResult r = solve(p, init, 100);
      SCOPED_TRACE("n=" + std::to_string(n) + " k=" + std::to_string(k));
      EXPECT_NEAR(r.energy_before, energy(p, init), 1e-9);
      EXPECT_LE(r.energy_after, r.energy_before + 1e-12);
      EXPECT_NEAR(r.energy_after, energy(p, r.labels), 1e-9);
      ASSERT_EQ(static_cast<int>(r.labels.size()), n);
      double prev = r.energy_before;
      for (double e : r.energy_trace) {
        EXPECT_LT(e, prev);
        prev = e;
      }
      if (!r.energy_trace.empty()) {
        EXPECT_NEAR(r.energy_trace.back(), r.energy_after, 1e-9);
      }
      EXPECT_GE(r.cycles, 1);
      EXPECT_LT(r.cycles, 100);  // converged before the cap
      // Random initial labels are far from optimal: something must have been accepted.
      EXPECT_FALSE(r.energy_trace.empty());
    }
  }
}

TEST(AlphaBetaSwap, EnergyNeverIncreases) {
  check_monotone(&alpha_beta_swap);
}
TEST(AlphaExpansion, EnergyNeverIncreases) {
  check_monotone(&alpha_expansion);
}

// ---------------------------------------------------------------------------------------------
// 4. Local optimality by brute force

TEST(AlphaBetaSwap, NoSwapMoveImprovesResult) {
  int initial_not_optimal = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    std::mt19937 rng(seed);
    const MrfProblem p = random_problem(rng, 8, 3, 12, 0.3 + 0.1 * (seed % 5));
    const std::vector<int> init = random_labels(rng, 8, 3);
    initial_not_optimal += !swap_optimal(p, init);  // the checker can detect non-optimality
    const MrfResult r = alpha_beta_swap(p, init, 100);
    const double e = energy(p, r.labels);
    for (int a = 0; a < 3; ++a)
      for (int b = a + 1; b < 3; ++b)
        EXPECT_GE(best_swap_energy(p, r.labels, a, b), e - 1e-9)
            << "seed " << seed << " pair " << a << "," << b;
  }
  EXPECT_GT(initial_not_optimal, 6);
}

TEST(AlphaExpansion, NoExpansionMoveImprovesResult) {
  int initial_not_optimal = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    std::mt19937 rng(100 + seed);
    const MrfProblem p = random_problem(rng, 8, 3, 12, 0.3 + 0.1 * (seed % 5));
    const std::vector<int> init = random_labels(rng, 8, 3);
    initial_not_optimal += !expansion_optimal(p, init);
    const MrfResult r = alpha_expansion(p, init, 100);
    const double e = energy(p, r.labels);
    for (int a = 0; a < 3; ++a)
      EXPECT_GE(best_expansion_energy(p, r.labels, a), e - 1e-9) << "seed " << seed << " a " << a;
  }
  EXPECT_GT(initial_not_optimal, 6);
}

// A k-label problem where ties and zero-capacity links are common (integer unaries).
TEST(AlphaBetaSwap, LocalOptimalityWithTies) {
  for (unsigned seed = 1; seed <= 8; ++seed) {
    std::mt19937 rng(500 + seed);
    MrfProblem p = random_problem(rng, 8, 4, 14, 1.0);
    std::uniform_int_distribution<int> small(0, 3);
    for (int j = 0; j < 8; ++j)
      for (int l = 0; l < 4; ++l) p.unary(j, l) = small(rng);
    const MrfResult rs = alpha_beta_swap(p, random_labels(rng, 8, 4), 100);
    EXPECT_TRUE(swap_optimal(p, rs.labels)) << "seed " << seed;
    const MrfResult re = alpha_expansion(p, random_labels(rng, 8, 4), 100);
    EXPECT_TRUE(expansion_optimal(p, re.labels)) << "seed " << seed;
  }
}

// Capacities are quantised internally; local optimality must hold at any energy scale.
TEST(Mrf, LocalOptimalityAtExtremeScales) {
  for (double scale : {1e-6, 1e6}) {
    for (unsigned seed = 1; seed <= 6; ++seed) {
      std::mt19937 rng(700 + seed);
      MrfProblem p = random_problem(rng, 8, 3, 13, 0.5);
      p.unary *= scale;
      p.pairwise_weight *= scale;
      const std::vector<int> init = random_labels(rng, 8, 3);
      const MrfResult rs = alpha_beta_swap(p, init, 100);
      const MrfResult re = alpha_expansion(p, init, 100);
      const double es = energy(p, rs.labels), ee = energy(p, re.labels);
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(best_expansion_energy(p, re.labels, a), ee - 1e-9 * scale)
            << scale << " " << seed;
        for (int b = a + 1; b < 3; ++b)
          EXPECT_GE(best_swap_energy(p, rs.labels, a, b), es - 1e-9 * scale)
              << scale << " " << seed;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// 5. Noisy regions are restored

struct GridCase {
  MrfProblem problem;
  std::vector<int> truth;
};

// side x side 8-connected grid split into `k` vertical stripes. Each node observes the one-hot
// vector of its true label plus Gaussian noise; the unary is the squared distance of the
// observation to each label's one-hot vector. The noise is set so that about 25% of the nodes have
// a unary favouring a wrong label.
GridCase noisy_grid(int side, int k, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, k == 2 ? 1.05 : 0.72);
  GridCase g;
  const int n = side * side;
  g.problem.unary.resize(n, k);
  g.truth.resize(static_cast<std::size_t>(n));
  std::vector<std::vector<int>> nb(static_cast<std::size_t>(n));
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const int j = y * side + x;
      g.truth[j] = x * k / side;
      Eigen::VectorXd obs = Eigen::VectorXd::Unit(k, g.truth[j]);
      for (int d = 0; d < k; ++d) obs(d) += noise(rng);
      for (int l = 0; l < k; ++l)
        g.problem.unary(j, l) = (obs - Eigen::VectorXd::Unit(k, l)).squaredNorm();
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if ((dx || dy) && xx >= 0 && yy >= 0 && xx < side && yy < side)
            nb[j].push_back(yy * side + xx);
        }
    }
  g.problem.edges = edge_list(nb);
  g.problem.pairwise_weight = 2.0;
  return g;
}

double accuracy(const std::vector<int>& a, const std::vector<int>& b) {
  int same = 0;
  for (std::size_t i = 0; i < a.size(); ++i) same += a[i] == b[i];
  return static_cast<double>(same) / static_cast<double>(a.size());
}

void check_restoration(Minimiser solve, int k) {
  for (unsigned seed : {7u, 8u, 9u}) {
    const GridCase g = noisy_grid(30, k, seed);
    const std::vector<int> init = unary_argmin(g.problem);
    const double before = accuracy(init, g.truth);
    EXPECT_GT(before, 0.68);
    EXPECT_LT(before, 0.82);
    const MrfResult r = solve(g.problem, init, 100);
    const double after = accuracy(r.labels, g.truth);
    EXPECT_GE(after, 0.98) << "k=" << k << " seed " << seed << " before " << before;
    EXPECT_LT(r.energy_after, r.energy_before);
  }
}

TEST(AlphaBetaSwap, RestoresNoisyTwoRegionGrid) {
  check_restoration(&alpha_beta_swap, 2);
}
TEST(AlphaExpansion, RestoresNoisyTwoRegionGrid) {
  check_restoration(&alpha_expansion, 2);
}
TEST(AlphaBetaSwap, RestoresNoisyThreeRegionGrid) {
  check_restoration(&alpha_beta_swap, 3);
}
TEST(AlphaExpansion, RestoresNoisyThreeRegionGrid) {
  check_restoration(&alpha_expansion, 3);
}

// ---------------------------------------------------------------------------------------------
// 6. Degenerate problems

void check_degenerate(Minimiser solve) {
  // Single label: nothing to do.
  MrfProblem one;
  one.unary = Eigen::MatrixXd::Constant(4, 1, 0.5);
  one.edges = {{0, 1}, {1, 2}};
  one.pairwise_weight = 1.0;
  MrfResult r = solve(one, {0, 0, 0, 0}, 100);
  EXPECT_EQ(r.labels, std::vector<int>({0, 0, 0, 0}));
  EXPECT_DOUBLE_EQ(r.energy_after, 2.0);
  EXPECT_TRUE(r.energy_trace.empty());

  // No nodes at all.
  MrfProblem empty;
  empty.unary.resize(0, 3);
  r = solve(empty, {}, 100);
  EXPECT_TRUE(r.labels.empty());
  EXPECT_EQ(r.energy_after, 0.0);

  // Nodes without edges: the result is the per-node unary argmin.
  MrfProblem iso;
  iso.unary.resize(3, 3);
  iso.unary << 3, 1, 2, 0, 5, 5, 4, 4, 1;
  iso.pairwise_weight = 10.0;
  r = solve(iso, {0, 1, 1}, 100);
  EXPECT_EQ(r.labels, std::vector<int>({1, 0, 2}));
  EXPECT_DOUBLE_EQ(r.energy_after, 2.0);

  // Isolated nodes mixed with a connected pair; max_cycles = 0 leaves the labels alone.
  MrfProblem mixed = iso;
  mixed.unary.conservativeResize(5, 3);
  mixed.unary.row(3) << 0, 0.2, 3;
  mixed.unary.row(4) << 0.2, 0, 3;
  mixed.edges = {{3, 4}};
  r = solve(mixed, {2, 2, 0, 2, 2}, 100);
  EXPECT_EQ(r.labels[0], 1);
  EXPECT_EQ(r.labels[1], 0);
  EXPECT_EQ(r.labels[2], 2);
  EXPECT_EQ(r.labels[3], r.labels[4]);
  EXPECT_NEAR(r.energy_after, 2.2, 1e-12);
  r = solve(mixed, {2, 2, 0, 2, 2}, 0);
  EXPECT_EQ(r.labels, std::vector<int>({2, 2, 0, 2, 2}));
  EXPECT_EQ(r.cycles, 0);

  // Inconsistent input is rejected.
  EXPECT_THROW(solve(iso, {0, 1}, 10), std::invalid_argument);
  EXPECT_THROW(solve(iso, {0, 1, 3}, 10), std::invalid_argument);
}

TEST(AlphaBetaSwap, DegenerateProblems) {
  check_degenerate(&alpha_beta_swap);
}
TEST(AlphaExpansion, DegenerateProblems) {
  check_degenerate(&alpha_expansion);
}

// ---------------------------------------------------------------------------------------------
// 7. Determinism

TEST(Mrf, Deterministic) {
  std::mt19937 rng(77);
  const MrfProblem p = random_problem(rng, 3000, 6, 12000, 0.4);
  const std::vector<int> init = random_labels(rng, 3000, 6);
  for (Minimiser solve : {&alpha_beta_swap, &alpha_expansion}) {
    const MrfResult a = solve(p, init, 100), b = solve(p, init, 100);
    EXPECT_EQ(a.labels, b.labels);
    EXPECT_EQ(a.energy_trace, b.energy_trace);
    EXPECT_EQ(a.cycles, b.cycles);
  }
}

// A run capped at c cycles is the first c cycles of the uncapped run: the same accepted moves in
// the same order (the default stops after 2 sweeps, the paper preset runs to convergence).
TEST(Mrf, CappedRunIsThePrefixOfTheConvergedRun) {
  std::mt19937 rng(91);
  const MrfProblem p = random_problem(rng, 2000, 7, 8000, 0.3);
  const std::vector<int> init = random_labels(rng, 2000, 7);
  for (Minimiser solve : {&alpha_beta_swap, &alpha_expansion}) {
    const MrfResult full = solve(p, init, 100);
    ASSERT_GE(full.cycles, 3);  // so that the caps below stop early
    std::size_t previous_moves = 0;
    for (int cap = 1; cap < full.cycles; ++cap) {
      SCOPED_TRACE("cap " + std::to_string(cap));
      const MrfResult r = solve(p, init, cap);
      EXPECT_EQ(r.cycles, cap);
      ASSERT_LE(r.energy_trace.size(), full.energy_trace.size());
      EXPECT_TRUE(
          std::equal(r.energy_trace.begin(), r.energy_trace.end(), full.energy_trace.begin()));
      EXPECT_GE(r.energy_trace.size(), previous_moves);
      EXPECT_NEAR(r.energy_after, energy(p, r.labels), 1e-9);
      EXPECT_GE(r.energy_after, full.energy_after - 1e-12);
      previous_moves = r.energy_trace.size();
    }
  }
}

// ---------------------------------------------------------------------------------------------
// 8. Two labels: one swap move is exact, so the result is the global minimum.

TEST(AlphaBetaSwap, TwoLabelsReachGlobalMinimum) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(900 + seed);
    const MrfProblem p = random_problem(rng, 6, 2, 8, 0.2 + 0.15 * (seed % 6));
    double best = 1e300;
    for (unsigned mask = 0; mask < 64; ++mask) {
      std::vector<int> l(6);
      for (int i = 0; i < 6; ++i) l[i] = mask >> i & 1u;
      best = std::min(best, energy(p, l));
    }
    const MrfResult r = alpha_beta_swap(p, random_labels(rng, 6, 2), 100);
    EXPECT_NEAR(r.energy_after, best, 1e-9) << "seed " << seed;
  }
}

// ---------------------------------------------------------------------------------------------
// Voxel-like problem of the typical size: 26-neighbour grid, unary from eq. 2 (timing printed).

TEST(Mrf, VoxelLikeProblemConverges) {
  const int nx = 22, ny = 22, nz = 21, k = 10, dim = 6;
  const int n = nx * ny * nz;
  std::mt19937 rng(2024);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixXd centroids(k, dim);
  for (int l = 0; l < k; ++l)
    for (int d = 0; d < dim; ++d) centroids(l, d) = 3.0 * g(rng);
  // Features: smooth blobs (label by position) plus noise.
  Eigen::MatrixXd x(n, dim);
  std::vector<std::vector<int>> nb(static_cast<std::size_t>(n));
  auto id = [&](int i, int j, int l) { return (l * ny + j) * nx + i; };
  for (int l = 0; l < nz; ++l)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int v = id(i, j, l);
        const int region = ((i / 6) + 4 * (j / 6) + 2 * (l / 7)) % k;
        for (int d = 0; d < dim; ++d) x(v, d) = centroids(region, d) + 1.0 * g(rng);
        for (int dl = -1; dl <= 1; ++dl)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const int ii = i + di, jj = j + dj, ll = l + dl;
              if ((di || dj || dl) && ii >= 0 && jj >= 0 && ll >= 0 && ii < nx && jj < ny &&
                  ll < nz)
                nb[v].push_back(id(ii, jj, ll));
            }
      }
  // w_u = 1 is the paper's setting: with 10 centroids eq. 2 gives small unary differences against
  // w_c = 0.275 on 26 neighbours, so the result is very smooth. w_u = 10 keeps more labels.
  for (double w_u : {1.0, 10.0}) {
    MrfProblem p;
    p.unary = unary_potentials(x, centroids, w_u);
    p.edges = edge_list(nb);
    p.pairwise_weight = 0.275;
    const std::vector<int> init = unary_argmin(p);
    for (Minimiser solve : {&alpha_beta_swap, &alpha_expansion}) {
      const auto t0 = std::chrono::steady_clock::now();
      const MrfResult r = solve(p, init, 100);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      const int used = static_cast<int>(std::set<int>(r.labels.begin(), r.labels.end()).size());
      std::cout << (solve == &alpha_beta_swap ? "swap" : "expansion") << " w_u=" << w_u << ": " << n
                << " nodes, " << p.edges.size() << " edges, " << k << " labels: " << r.cycles
                << " cycles, " << r.energy_trace.size() << " moves, E " << r.energy_before << " -> "
                << r.energy_after << ", labels used " << used << ", " << ms << " ms\n";
      EXPECT_LT(r.energy_after, r.energy_before);
      EXPECT_LT(r.cycles, 100);
    }
  }
}

}  // namespace
}  // namespace proxseg
