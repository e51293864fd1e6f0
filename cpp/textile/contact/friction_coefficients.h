// Which Coulomb coefficient a pair of fibres takes: its group's within a
// group of fibres (a yarn), another between groups.
#pragma once

#include <cstddef>
#include <vector>

namespace textile::contact
{

/// The friction coefficients of a scene: within[g] for two fibres of group
/// g (the fibres of a yarn rub on each other along their length), `between`
/// for fibres of different groups and for every pair of a scene without
/// groups (an empty `group`). `group` holds each fibre's group (negative:
/// a fibre of no group).
struct FrictionCoefficients
{
  double between = 0;
  std::vector<double> within;
  std::vector<int> group;

  double mu(int fibre_i, int fibre_j) const
  {
    if (group.empty())
      return between;
    const int a = group.at(static_cast<std::size_t>(fibre_i));
    return a >= 0 and a == group.at(static_cast<std::size_t>(fibre_j))
               ? within.at(static_cast<std::size_t>(a))
               : between;
  }
};

} // namespace textile::contact
