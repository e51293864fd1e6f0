// Held contacts: a pass keeps the contacts whose fibres have crossed beyond
// the search distance (stability issue item 9).
#include <textile/contact/detection.h>
#include <textile/contact/held_contact.h>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "test_contact_scenes.h"

using namespace textile::contact;
using scenes::section_vectors_along;
using scenes::two_lines;

namespace
{
constexpr double R = 1e-3, length = 0.02, delta_factor = 2.0;

/// Fibre 1 crosses fibre 0 at 90 degrees, `below` radii under it, shifted
/// by `shift` along x; the held contact says fibre 1 belongs above (N = -z
/// points from fibre 1 down to fibre 0).
struct Scene
{
  Centrelines c;
  std::vector<double> g;
  HeldContact held;
  Scene(double below, double shift = 0.0, Eigen::Vector3d normal = -Eigen::Vector3d::UnitZ())
      : c(two_lines(std::numbers::pi / 2, 4, length, R, 2 * R + below * R))
  {
    for (std::size_t n = c.fibre_offsets[1]; n < c.x.size() / 3; ++n)
      c.x[3 * n] += shift;
    g = section_vectors_along(c);
    held = {0, 1, 2.0, 2.0, normal, 2 * R, true}; // the crossing, mid-fibres
  }
  Detection detect_with_held(int& added) const
  {
    Detection d = detect(c, SectionVectors{g}, delta_factor, 1.0, 2.5e-3, 0.17);
    added = add_held_contacts(d, c, SectionVectors{g}, std::span(&held, 1));
    return d;
  }
};
} // namespace

TEST(HeldContacts, CrossedBeyondTheSearchDistanceIsKept)
{
  // 6 radii below: no zone (search distance 4R), but on the wrong side
  const Scene s(6.0);
  int added = 0;
  const Detection d = s.detect_with_held(added);
  ASSERT_EQ(added, 1);
  ASSERT_EQ(d.points.size(), 1u);
  ASSERT_EQ(d.zones.size(), 1u);
  const ContactPoint& p = d.points[0];
  EXPECT_NEAR(p.s_i, 2.0, 1e-12); // at the closest points
  EXPECT_NEAR(p.s_j, 2.0, 1e-12);
  EXPECT_EQ(p.held_normal, s.held.normal);
  EXPECT_NEAR(p.centroid_gap.z(), 6 * R, 1e-15);
  EXPECT_DOUBLE_EQ(p.length, 2 * R);
  // the particles face each other as the normal says the fibres belong:
  // fibre 0's at its top, fibre 1's at its bottom (g1 = +z)
  EXPECT_NEAR(p.xi1_i, R, 1e-15);
  EXPECT_NEAR(p.xi1_j, -R, 1e-15);
}

TEST(HeldContacts, SeparatedOnTheRightSideIsLetGo)
{
  // the same place, but the normal says fibre 1 belongs below: it simply
  // moved away
  const Scene s(6.0, 0.0, Eigen::Vector3d::UnitZ());
  int added = 0;
  EXPECT_TRUE(s.detect_with_held(added).points.empty());
  EXPECT_EQ(added, 0);
}

TEST(HeldContacts, SlidOffTheEndIsLetGo)
{
  // fibre 1 moved beyond fibre 0's end (x = length / 2) by 3 radii
  const Scene s(6.0, 0.5 * length + 3 * R);
  int added = 0;
  EXPECT_TRUE(s.detect_with_held(added).points.empty());
  EXPECT_EQ(added, 0);
}

TEST(HeldContacts, FoundByDetectionIsNotDoubled)
{
  // 1 radius below: detection finds the zone itself
  const Scene s(1.0);
  int added = 0;
  const Detection d = s.detect_with_held(added);
  EXPECT_EQ(added, 0);
  EXPECT_EQ(d.points.size(), 1u);
}
