// Where a crossing is placed on a centre line (snapped, tolerances.h
// kink_snap / kink_angle) and how a line contact's length is cut into
// quadrature pieces (composite_gauss_rule, merge_fraction): the two
// tolerances pinned here on both sides, so a change of either by a factor
// of two or more fails.
#include <textile/contact/centreline.h>
#include <textile/contact/intermediate_geometry.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace textile::contact;

namespace
{
/// One fibre of two unit elements (order 1), kinked at its middle node by
/// `angle` radians in the x-y plane.
Centrelines kinked(double angle)
{
  Centrelines c;
  c.x = {0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0 + std::cos(angle), std::sin(angle), 0.0};
  c.fibre_offsets = {0, 3};
  c.order = 1;
  c.radius = {0.1};
  c.validate();
  return c;
}
} // namespace

TEST(Snapped, ACrossingNearAKinkGoesToTheNode)
{
  // 0.05 element from the node: beyond node_snap (0.01), within kink_snap
  // (0.1). A kink of 2e-3 rad (twice kink_angle) is a kink: the crossing
  // sits at the node, where the normal is not ambiguous between the two
  // elements' tangents; 5e-4 rad (half kink_angle) is a straight line.
  EXPECT_EQ(snapped(kinked(2e-3), 0, 1.05), 1.0);
  EXPECT_EQ(snapped(kinked(2e-3), 0, 0.95), 1.0);
  EXPECT_EQ(snapped(kinked(5e-4), 0, 1.05), 1.05);
  // beyond kink_snap, even a sharp kink leaves the crossing where it is
  EXPECT_EQ(snapped(kinked(0.3), 0, 1.15), 1.15);
  // within node_snap, any node takes it
  EXPECT_EQ(snapped(kinked(0.0), 0, 1.005), 1.0);
}

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
