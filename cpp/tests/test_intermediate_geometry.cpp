// How a line contact's length is cut into quadrature pieces
// (composite_gauss_rule, merge_fraction): the tolerance pinned here on both
// sides, so a change by a factor of two or more fails.
#include <textile/contact/centreline.h>
#include <textile/contact/intermediate_geometry.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace textile::contact;

TEST(CompositeGaussRule, PiecesMuchShorterThanTheSpacingAreMerged)
{
  // a unit length, a unit spacing: one piece would be one 2-point rule
  const double length = 1.0, spacing = 1.0;
  // a cut 5e-4 spacing after another (half merge_fraction): merged
  auto [p1, w1] = composite_gauss_rule({0.5, 0.5 + 5e-4}, length, spacing);
  EXPECT_EQ(p1.size(), 4u);
  // 2e-3 spacing (twice merge_fraction): a piece of its own
  auto [p2, w2] = composite_gauss_rule({0.5, 0.5 + 2e-3}, length, spacing);
  EXPECT_EQ(p2.size(), 6u);
  // the same at the ends of [0, 1]
  EXPECT_EQ(composite_gauss_rule({1.0 - 5e-4}, length, spacing).first.size(), 2u);
  EXPECT_EQ(composite_gauss_rule({1.0 - 2e-3}, length, spacing).first.size(), 4u);
  // the weights still sum to 1
  double sum = 0.0;
  for (double w : w1)
    sum += w;
  EXPECT_NEAR(sum, 1.0, 1e-15);
}
