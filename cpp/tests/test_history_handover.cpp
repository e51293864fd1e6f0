// Contact history across ranks (history_handover.h): every old element
// whose successor another rank evaluates reaches that rank, and only
// elements next to a partition cut travel.
#include <textile/contact/history_handover.h>
#include <textile/contact/history_transfer.h>
#include <textile/contact/tolerances.h>
#include <gtest/gtest.h>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace textile::contact;

namespace
{
constexpr int order = 2;
constexpr int fibres = 4, elements = 8; // per fibre
constexpr int ranks = 3;

ContactElementState element_at(int fi, int fj, double si, double sj)
{
  ContactElementState e;
  e.fibre_i = fi;
  e.fibre_j = fj;
  e.s_i = si;
  e.s_j = sj;
  return e;
}

/// First node of the element holding abscissa s on fibre f.
std::int64_t element_node(const std::vector<std::int64_t>& first_node, int f, double s)
{
  const auto e = std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor(s)), 0,
                                          elements - 1);
  return first_node[f] + order * e;
}

struct Scene
{
  std::vector<std::int64_t> first_node;
  std::vector<std::int32_t> owner; // per node: blocks of a few elements, ranks mixed
  std::vector<ContactElementState> old;
};

Scene scene(std::mt19937& gen)
{
  Scene s;
  for (int f = 0; f <= fibres; ++f)
    s.first_node.push_back(static_cast<std::int64_t>(f) * (order * elements + 1));
  std::uniform_int_distribution<int> rank(0, ranks - 1);
  for (int f = 0; f < fibres; ++f)
  {
    int r = rank(gen);
    for (int e = 0; e < elements; ++e)
    {
      if (e % 3 == 0)
        r = rank(gen); // a cut every three elements or so
      for (int k = 0; k < order; ++k)
        s.owner.push_back(r);
    }
    s.owner.push_back(r); // the last node
  }
  std::uniform_int_distribution<int> fibre(0, fibres - 1);
  std::uniform_real_distribution<double> abscissa(0.0, elements);
  for (int k = 0; k < 300; ++k)
  {
    const int a = fibre(gen), b = fibre(gen);
    s.old.push_back(element_at(std::min(a, b), std::max(a, b), abscissa(gen), abscissa(gen)));
  }
  return s;
}
} // namespace

TEST(HistoryHandover, EverySuccessorOnAnotherRankFindsItsPredecessor)
{
  std::mt19937 gen(7);
  const Scene s = scene(gen);
  std::uniform_real_distribution<double> shift(-0.74, 0.74);
  for (int rank = 0; rank < ranks; ++rank)
  {
    const NodeOwners owners{s.owner, rank};
    // the elements this rank evaluates, and what it hands to the others
    std::vector<ContactElementState> mine;
    for (const auto& e : s.old)
      if (evaluated_here(e.fibre_i, e.fibre_j, element_node(s.first_node, e.fibre_i, e.s_i),
                         element_node(s.first_node, e.fibre_j, e.s_j), owners))
        mine.push_back(e);
    const ContactSet set(mine, 1);
    const auto out = history_handover(set, owners, s.first_node, order, ranks,
                                      history_match_distance);
    ASSERT_EQ(out.size(), std::size_t(ranks));
    EXPECT_TRUE(out[rank].empty());
    std::size_t travelling = 0;
    for (const auto& part : out)
      travelling += part.size();
    // only the elements near a cut travel (and some do)
    EXPECT_GT(travelling, 0u);
    EXPECT_LT(travelling, mine.size());
    // successors: moved by less than the matching distance on both fibres
    for (const auto& e : mine)
      for (int trial = 0; trial < 20; ++trial)
      {
        const double di = shift(gen), dj = 0.74 - std::abs(di);
        ContactPoint p;
        p.fibre_i = e.fibre_i;
        p.fibre_j = e.fibre_j;
        p.s_i = std::clamp(e.s_i + di, 0.0, double(elements));
        p.s_j = std::clamp(e.s_j + (trial % 2 ? dj : -dj), 0.0, double(elements));
        for (int r = 0; r < ranks; ++r)
        {
          if (r == rank
              or !evaluated_here(p.fibre_i, p.fibre_j,
                                 element_node(s.first_node, p.fibre_i, p.s_i),
                                 element_node(s.first_node, p.fibre_j, p.s_j),
                                 NodeOwners{s.owner, r}))
            continue;
          const auto& sent = out[r];
          const bool found = std::any_of(sent.begin(), sent.end(), [&](const auto& x)
                                         { return x.s_i == e.s_i and x.s_j == e.s_j
                                                  and x.fibre_i == e.fibre_i
                                                  and x.fibre_j == e.fibre_j; });
          EXPECT_TRUE(found) << "rank " << rank << " -> " << r << ": fibres " << e.fibre_i
                             << "," << e.fibre_j << " s " << e.s_i << "," << e.s_j;
        }
      }
  }
}

TEST(HistoryHandover, OneRankSendsNothingAndReceivedHistoryFollows)
{
  std::mt19937 gen(11);
  const Scene s = scene(gen);
  const std::vector<std::int32_t> alone(s.owner.size(), 0);
  const ContactSet set(s.old, 1);
  const auto out = history_handover(set, NodeOwners{alone, 0}, s.first_node, order, 1,
                                    history_match_distance);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].empty());
  const std::vector<ContactElementState> received(s.old.begin(), s.old.begin() + 5);
  const ContactSet both = with_history(set, received);
  ASSERT_EQ(both.elements().size(), s.old.size() + 5);
  EXPECT_EQ(both.elements()[s.old.size() + 2].s_i, s.old[2].s_i); // appended, in order
  EXPECT_EQ(both.num_zones(), set.num_zones());
}
