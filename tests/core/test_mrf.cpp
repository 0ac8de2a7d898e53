// Tests of the MRF stage [paper 3.2]: unary potentials (equation 2), the max-flow behind the moves,
// the edge list and the Potts energy (the minimisers: test_mrf_moves.cpp).
#include <proxseg/core/mrf.hpp>

#include "core/maxflow.hpp"

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

// ---------------------------------------------------------------------------------------------
// 1. Unary potentials

// The max-flow behind the moves against Edmonds-Karp (shortest augmenting paths on a dense
// residual matrix): the same flow value, and the same source side, which must be what the source
// reaches in the residual graph (the smallest minimum cut, unique whatever the flow). Small
// integer capacities make many minimum cuts tie.
TEST(MaxFlow, SameFlowAndSmallestCutAsEdmondsKarp) {
  std::mt19937 rng(7);
  MaxFlow solver;
  for (int trial = 0; trial < 300; ++trial) {
    const int m = 2 + trial % 40;
    const int s = m, t = m + 1, nv = m + 2;
    std::vector<std::vector<long>> cap(nv, std::vector<long>(nv, 0));
    std::uniform_int_distribution<int> c(0, trial % 3 == 0 ? 3 : 20), node(0, m - 1);
    solver.reset(m);
    for (int i = 0; i < m; ++i) {
      const long from_s = c(rng) * (rng() % 3 == 0), to_t = c(rng) * (rng() % 3 == 0);
      solver.set_terminals(i, from_s, to_t);
      cap[s][i] += from_s;
      cap[i][t] += to_t;
    }
    for (int e = 0; e < 3 * m; ++e) {
      const int i = node(rng), j = node(rng);
      if (i == j) continue;
      const long a = c(rng), b = c(rng);
      solver.add_edge(i, j, a, b);
      cap[i][j] += a;
      cap[j][i] += b;
    }
    const long flow = solver.solve();
    // Edmonds-Karp.
    long expected = 0;
    for (;;) {
      std::vector<int> prev(nv, -1);
      prev[s] = s;
      std::queue<int> q;
      q.push(s);
      while (!q.empty() && prev[t] < 0) {
        const int u = q.front();
        q.pop();
        for (int v = 0; v < nv; ++v)
          if (prev[v] < 0 && cap[u][v] > 0) prev[v] = u, q.push(v);
      }
      if (prev[t] < 0) break;
      long b = std::numeric_limits<long>::max();
      for (int v = t; v != s; v = prev[v]) b = std::min(b, cap[prev[v]][v]);
      for (int v = t; v != s; v = prev[v]) cap[prev[v]][v] -= b, cap[v][prev[v]] += b;
      expected += b;
    }
    ASSERT_EQ(flow, expected) << "trial " << trial;
    std::vector<char> reached(nv, 0);
    std::vector<int> stack{s};
    reached[s] = 1;
    while (!stack.empty()) {
      const int u = stack.back();
      stack.pop_back();
      for (int v = 0; v < nv; ++v)
        if (!reached[v] && cap[u][v] > 0) reached[v] = 1, stack.push_back(v);
    }
    for (int i = 0; i < m; ++i)
      ASSERT_EQ(solver.on_source_side(i), reached[i] != 0) << "trial " << trial << " node " << i;
  }
}

TEST(UnaryPotentials, NearerCentroidHasLowerPotential) {
  Eigen::MatrixXd c(3, 2);
  c << 0, 0, 10, 0, 0, 5;
  Eigen::MatrixXd x(4, 2);
  x << 1, 0, 9, 1, 0, 4, 3, 3;
  const Eigen::MatrixXd u = unary_potentials(x, c, 1.0);
  ASSERT_EQ(u.rows(), 4);
  ASSERT_EQ(u.cols(), 3);
  EXPECT_TRUE(u.allFinite());
  for (int j = 0; j < 4; ++j) {
    Eigen::VectorXd d(3);
    for (int l = 0; l < 3; ++l) d(l) = (x.row(j) - c.row(l)).norm();
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        if (d(a) < d(b)) {
          EXPECT_LT(u(j, a), u(j, b)) << "row " << j;
        }
      }
    for (int l = 0; l < 3; ++l) {
      EXPECT_GE(u(j, l), 0.0);
      EXPECT_NEAR(u(j, l), -std::log(1.0 - d(l) / d.sum()), 1e-12);
    }
  }
}

TEST(UnaryPotentials, SingleCentroidGivesZeros) {
  Eigen::MatrixXd c(1, 3);
  c << 1, 2, 3;
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(5, 3);
  const Eigen::MatrixXd u = unary_potentials(x, c, 2.0);
  ASSERT_EQ(u.rows(), 5);
  ASSERT_EQ(u.cols(), 1);
  EXPECT_TRUE(u.isZero(0.0));
}

TEST(UnaryPotentials, WeightScalesLinearly) {
  const Eigen::MatrixXd c = Eigen::MatrixXd::Random(4, 3);
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(20, 3);
  const Eigen::MatrixXd u1 = unary_potentials(x, c, 1.0);
  const Eigen::MatrixXd u3 = unary_potentials(x, c, 3.0);
  EXPECT_GT(u1.maxCoeff(), 0.0);
  EXPECT_TRUE(u3.isApprox(3.0 * u1, 1e-12));
}

TEST(UnaryPotentials, DegenerateCasesStayFinite) {
  // Feature equal to every centroid (all distances 0) -> all labels cost 0.
  Eigen::MatrixXd c(3, 2);
  c << 1, 1, 1, 1, 1, 1;
  Eigen::MatrixXd x(1, 2);
  x << 1, 1;
  Eigen::MatrixXd u = unary_potentials(x, c, 1.0);
  EXPECT_TRUE(u.isZero(0.0));
  // Feature on two coincident centroids, third elsewhere: ratio 1 for the far one -> large but
  // finite; the near ones cost 0.
  c << 0, 0, 0, 0, 5, 5;
  x << 0, 0;
  u = unary_potentials(x, c, 1.0);
  EXPECT_TRUE(u.allFinite());
  EXPECT_EQ(u(0, 0), 0.0);
  EXPECT_EQ(u(0, 1), 0.0);
  EXPECT_GT(u(0, 2), 10.0);
}

// ---------------------------------------------------------------------------------------------
// 2. Edge list

TEST(EdgeList, UnorderedPairsAscending) {
  // 0-1, 0-2, 1-2, 2-3; node 4 isolated; neighbour lists in arbitrary order.
  const std::vector<std::vector<int>> nb = {{2, 1}, {0, 2}, {3, 1, 0}, {2}, {}};
  const std::vector<std::pair<int, int>> expected = {{0, 1}, {0, 2}, {1, 2}, {2, 3}};
  EXPECT_EQ(edge_list(nb), expected);
  EXPECT_TRUE(edge_list({}).empty());
}

TEST(Energy, MatchesHandComputation) {
  MrfProblem p;
  p.unary.resize(3, 2);
  p.unary << 0.5, 1.0, 2.0, 0.25, 0.0, 3.0;
  p.edges = {{0, 1}, {1, 2}, {0, 2}};
  p.pairwise_weight = 0.3;
  EXPECT_NEAR(energy(p, {0, 1, 0}), 0.5 + 0.25 + 0.0 + 2 * 0.3, 1e-12);
  EXPECT_NEAR(energy(p, {0, 0, 0}), 0.5 + 2.0 + 0.0, 1e-12);
}

}  // namespace
}  // namespace proxseg
