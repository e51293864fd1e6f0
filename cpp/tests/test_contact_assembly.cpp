// Contact assembly and bookkeeping: node-block insertion against plain
// MatSetValues, the matrix couplings, history matching against a brute-force
// search, the penalty retuning rule, contact lengths and the gap alone.
#include <textile/contact/contact_element.h>
#include <textile/contact/coupling_pattern.h>
#include <textile/contact/history_transfer.h>
#include <textile/contact/intermediate_geometry.h>
#include <textile/contact/node_block_matrix.h>
#include <textile/contact/penalty_adaptation.h>
#include <textile/contact/regularized_penalty.h>

#include "petsc_environment.h"
#include "test_contact_scenes.h"

#include <gtest/gtest.h>
#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace textile::contact;

namespace
{
/// Dense copy of an assembled matrix.
std::vector<double> dense(Mat A, int n)
{
  std::vector<double> out(n * n, 0.0);
  for_each_entry(A, [&](PetscInt r, PetscInt c, PetscScalar v) { out[r * n + c] = v; });
  return out;
}

/// Random elements on `nodes` fibre nodes: each couples 2 or 3 consecutive
/// nodes of one "fibre" with those of another, as contact elements do.
struct RandomElements
{
  std::vector<std::size_t> offsets = {0};
  std::vector<std::int64_t> nodes;
  std::vector<std::vector<double>> K;
  RandomElements(int count, int num_nodes, std::mt19937& gen)
  {
    std::uniform_int_distribution<int> first(0, num_nodes - 3), size(2, 3);
    std::uniform_real_distribution<double> U(-1, 1);
    for (int e = 0; e < count; ++e)
    {
      const int a = first(gen), b = first(gen), na = size(gen), nb = size(gen);
      for (int k = 0; k < na; ++k)
        nodes.push_back(a + k);
      for (int k = 0; k < nb; ++k)
        nodes.push_back(b + k); // may repeat a node of the first element
      offsets.push_back(nodes.size());
      const int n = 9 * (na + nb);
      K.emplace_back(n * n);
      for (double& v : K.back())
        v = U(gen);
    }
  }
  /// The reference: each element's dense block by MatSetValues.
  void insert_one_by_one(Mat A, const std::vector<std::int32_t>& dofs) const
  {
    for (std::size_t e = 0; e + 1 < offsets.size(); ++e)
    {
      std::vector<PetscInt> idx;
      for (std::size_t a = offsets[e]; a < offsets[e + 1]; ++a)
        for (int k = 0; k < 9; ++k)
          idx.push_back(dofs[9 * nodes[a] + k]);
      MatSetValues(A, idx.size(), idx.data(), idx.size(), idx.data(), K[e].data(), ADD_VALUES);
    }
  }
};

Mat seqaij(int n, int per_row)
{
  Mat A;
  MatCreateSeqAIJ(PETSC_COMM_SELF, n, n, per_row, nullptr, &A);
  MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE);
  return A;
}
} // namespace

/// How the node-block sums reach the matrix: in place (AIJ with the
/// pattern), through MatSetValues (entries outside the pattern, a dense
/// matrix); the result must equal element-by-element insertion.
class NodeBlockInsertion : public ::testing::TestWithParam<const char*>
{
};

TEST_P(NodeBlockInsertion, EqualsElementByElementInsertion)
{
  PetscEnvironment::require();
  const std::string how = GetParam();
  std::mt19937 gen(7);
  const int num_nodes = 30, n = 9 * num_nodes;
  const RandomElements el(40, num_nodes, gen);
  // constrained unknowns (-1) are skipped, a whole node among them
  std::vector<std::int32_t> dofs(n);
  for (int i = 0; i < n; ++i)
    dofs[i] = (i % 7 == 3 or i / 9 == 11) ? -1 : i;

  NodeBlockMatrix blocks;
  blocks.build(el.offsets, el.nodes, dofs);
  ASSERT_TRUE(blocks.built_for(dofs));
  EXPECT_LT(blocks.num_blocks(), 36 * el.K.size()); // shared node pairs are summed once

  Mat A;
  if (how == "in place")
  {
    // preallocated with the layout's own pattern, as CouplingPattern does,
    // over an empty base
    Mat base = seqaij(n, 0);
    MatAssemblyBegin(base, MAT_FINAL_ASSEMBLY);
    MatAssemblyEnd(base, MAT_FINAL_ASSEMBLY);
    {
      textile::assembly::SparsityPattern pattern(base);
      blocks.insert_pattern(pattern);
      A = pattern.create_matrix(base);
    }
    MatDestroy(&base);
    MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE); // in place only
  }
  else if (how == "outside the pattern")
  {
    A = seqaij(n, 1); // diagonal-sized: MatSetValues allocates the rest
    MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY);
    MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY);
  }
  else
  {
    MatCreateSeqDense(PETSC_COMM_SELF, n, n, nullptr, &A);
    MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY);
    MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY);
  }
  Mat B = seqaij(n, n);
  el.insert_one_by_one(B, dofs);
  MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY);
  // twice: the slots located on the first insertion serve the second, and
  // the buffer is cleared between insertions
  for (int pass = 0; pass < 2; ++pass)
  {
    MatZeroEntries(A);
    for (std::size_t e = 0; e < el.K.size(); ++e)
      blocks.add(e, el.K[e]);
    blocks.insert(A);
    MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY);
    MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY);
    const auto a = dense(A, n), b = dense(B, n);
    double err = 0, scale = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
    {
      err = std::max(err, std::abs(a[i] - b[i]));
      scale = std::max(scale, std::abs(b[i]));
    }
    EXPECT_LT(err, 1e-13 * scale) << how << ", pass " << pass; // sums in another order
  }
  MatDestroy(&A);
  MatDestroy(&B);
}

INSTANTIATE_TEST_SUITE_P(Matrices, NodeBlockInsertion,
                         ::testing::Values("in place", "outside the pattern", "dense"));

namespace
{
ContactElementState element_at(int fi, int fj, double si, double sj, int zone = 0)
{
  ContactElementState e;
  e.fibre_i = fi;
  e.fibre_j = fj;
  e.s_i = si;
  e.s_j = sj;
  e.zone = zone;
  return e;
}
} // namespace

TEST(HistoryMatching, SameAsBruteForce)
{
  std::mt19937 gen(3);
  std::uniform_int_distribution<int> fibre(0, 4);
  std::uniform_real_distribution<double> s(0.0, 8.0);
  std::vector<ContactElementState> old;
  for (int k = 0; k < 400; ++k)
  {
    const int a = fibre(gen), b = fibre(gen);
    old.push_back(element_at(std::min(a, b), std::max(a, b), s(gen), s(gen)));
  }
  old.push_back(old[17]); // an exact duplicate: the tie goes to the lower index
  std::vector<ContactPoint> points;
  for (int k = 0; k < 600; ++k)
  {
    ContactPoint p;
    const int a = fibre(gen), b = fibre(gen);
    p.fibre_i = std::min(a, b);
    p.fibre_j = std::max(a, b);
    const auto& near = old[k % old.size()];
    // half of them close to an old element, half anywhere
    p.s_i = k % 2 ? s(gen) : std::clamp(near.s_i + 0.3 * (s(gen) / 8 - 0.5), 0.0, 8.0);
    p.s_j = k % 2 ? s(gen) : near.s_j;
    if (k % 2 == 0)
    {
      p.fibre_i = near.fibre_i;
      p.fibre_j = near.fibre_j;
    }
    points.push_back(p);
  }
  const auto match = match_history(points, old);
  int matched = 0;
  for (std::size_t p = 0; p < points.size(); ++p)
  {
    int best = -1;
    double dist = 0.75;
    for (std::size_t k = 0; k < old.size(); ++k)
    {
      if (old[k].fibre_i != points[p].fibre_i or old[k].fibre_j != points[p].fibre_j)
        continue;
      const double d = std::abs(old[k].s_i - points[p].s_i) + std::abs(old[k].s_j - points[p].s_j);
      if (d < dist)
      {
        dist = d;
        best = static_cast<int>(k);
      }
    }
    EXPECT_EQ(match[p], best) << "point " << p;
    matched += best >= 0;
  }
  EXPECT_GT(matched, 250); // the test exercises matches, not only misses
}

TEST(PenaltyAdaptationRule, ForcePreservingBandedAndBounded)
{
  const double g_r = 2e-5;
  PenaltyAdaptation rule;
  rule.target = 2 * g_r;
  rule.regularization = g_r;
  rule.max_change = 4;
  rule.k_min = 1.0;
  rule.k_max = 1e12;
  rule.validate();
  const RegularizedPenalty unit(1.0, g_r);
  auto force = [&](double k, double p) { return k * unit.reaction(-p); };
  // inside the bounds the retuned penalty gives the zone's force at the target
  for (double p : {0.6 * rule.target, 2.5 * rule.target, 3.0 * rule.target})
  {
    const double k = 1e6, kt = rule.towards_target(k, p);
    EXPECT_NEAR(force(kt, rule.target), force(k, p), 1e-12 * force(k, p)) << p;
  }
  // far below the target: softened by max_change at most
  EXPECT_DOUBLE_EQ(rule.between_steps(1e6, 0.01 * rule.target), 1e6 / 4);
  // inside the band (hysteresis), or open: unchanged
  for (double p : {0.0, 0.5 * rule.target, rule.target, 1.5 * rule.target})
    EXPECT_EQ(rule.between_steps(1e6, p), 1e6) << p;
  // in a step, only beyond band_high
  EXPECT_EQ(rule.in_step(1e6, 1.9 * rule.target), 1e6);
  EXPECT_GT(rule.in_step(1e6, 2.1 * rule.target), 1e6);
  // the absolute bounds hold
  EXPECT_EQ(rule.between_steps(2.0, 0.01 * rule.target), 1.0);
  rule.band_low = 2; // inconsistent band
  EXPECT_THROW(rule.validate(), std::invalid_argument);
}

using scenes::section_vectors_along;
using scenes::two_lines;

TEST(ContactLengths, LineLengthsSumToTheZoneWhateverTheSpacing)
{
  const double R = 1e-3, length = 0.02;
  const Centrelines c = two_lines(0.0, 4, length, R, 1e-6);
  const auto g = section_vectors_along(c);
  const auto zones = find_proximity_zones(c, 2.0, 1.0);
  ASSERT_EQ(zones.size(), 1u);
  for (double spacing : {0.5 * length / 4, 0.25 * length / 4, 0.3 * length / 4})
  {
    const auto points = contact_points(c, SectionVectors{g}, zones[0], spacing, 0.17, 2.0);
    double total = 0;
    for (const auto& p : points)
    {
      EXPECT_FALSE(p.crossing);
      total += p.length;
    }
    // lengths of a line contact: its length, not a multiple of 1/spacing
    EXPECT_NEAR(total, intermediate_length(c, zones[0]), 1e-12 * length) << spacing;
  }
  // the default spacing gives one 2-point piece per fibre element
  EXPECT_EQ(contact_points(c, SectionVectors{g}, zones[0], 0.5 * length / 4, 0.17, 2.0).size(),
            8u);
}

TEST(ContactLengths, CrossingStandsForTheSumOfTheRadii)
{
  const double R = 1e-3;
  const Centrelines c = two_lines(M_PI / 2, 4, 0.02, R, 1e-6);
  const auto g = section_vectors_along(c);
  const auto zones = find_proximity_zones(c, 2.0, 1.0);
  ASSERT_EQ(zones.size(), 1u);
  const auto points = contact_points(c, SectionVectors{g}, zones[0], 2.5e-3, 0.17, 2.0);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_TRUE(points[0].crossing);
  EXPECT_DOUBLE_EQ(points[0].length, crossing_length(R, R));
  EXPECT_DOUBLE_EQ(crossing_length(R, 0.5 * R), 1.5 * R);
}

TEST(ContactGap, SameAsTheKernelsGap)
{
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> U(-1, 1);
  const double R = 0.01;
  for (int trial = 0; trial < 20; ++trial)
  {
    std::vector<double> xi, xj;
    for (int a = 0; a < 3; ++a)
      for (const auto& [x, z] : {std::pair{&xi, 0.0}, std::pair{&xj, -2 * R}})
      {
        const double s = (a - 1) * 0.05;
        const Eigen::Vector3d p = x == &xi ? Eigen::Vector3d(s, 0, z) : Eigen::Vector3d(0, s, z);
        for (int k = 0; k < 3; ++k)
          x->push_back(p[k] + 1e-3 * U(gen));
        for (const Eigen::Vector3d& v : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.7, 0.7, 0)})
          for (int k = 0; k < 3; ++k)
            x->push_back(v[k] + 0.1 * U(gen));
      }
    const Particle pi{3, U(gen), 0, 0, R}, pj{3, U(gen), 0, 0, R};
    const Eigen::Vector3d N = Eigen::Vector3d(0.1 * U(gen), 0.1 * U(gen), 1).normalized();
    const RegularizedPenalty law(1e4, 1e-3 * R);
    std::vector<double> r(54, 0.0);
    const auto full = contact_element(pi, pj, N, law, nullptr, Eigen::Vector3d::Zero(), xi, xj,
                                      r, {});
    EXPECT_EQ(contact_gap(pi, pj, N, xi, xj), full.gap); // bit for bit: it decides what is open
  }
}
