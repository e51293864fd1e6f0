// The crossing order of the weaving stage (docs/method.md §6.2).
//
// Weaving starts from straight, coplanar, interpenetrating yarns. While it
// lasts, a contact element between fibres of two yarns that cross in a
// known order takes the vertical as its normal, oriented by that order
// rather than by where the fibres are: N = +e_z when fibre i's yarn lies
// above fibre j's (N points from j to i, contact_element.h), -e_z when it
// lies below. The gap N . (x0_i - x0_j) - h_i - h_j is then negative for a
// fibre of the upper yarn that is below a fibre of the lower yarn, however
// deep, so the yarns are pushed over and under each other. Pairs without
// an order (fibres of one yarn, yarns of one direction) keep the ordinary
// normal (contact_normal.h).
//
// An order made to *pass through* gives ordered pairs no contact at all:
// the yarns that cross pass through each other while something else (the
// heddles of the lifting weave, textile/effects/heddles.py) separates
// them; contacts within a yarn and between parallel yarns stay.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <vector>

namespace textile::contact
{

class WeavingOrder
{
public:
  WeavingOrder() = default;

  /// @param fibre_yarn  yarn of each fibre (0 .. num_yarns - 1)
  /// @param above       num_yarns x num_yarns, row-major: +1 if yarn a lies
  ///                    above yarn b where they cross, -1 below, 0 no order
  /// @throws std::invalid_argument: a yarn number out of range, a value
  ///         other than -1, 0, +1, an order that is not antisymmetric
  ///         (above[a, b] = -above[b, a], 0 on the diagonal), a size mismatch.
  /// @param pass_through  ordered pairs get no contact element (above)
  WeavingOrder(std::vector<int> fibre_yarn, std::vector<std::int8_t> above, int num_yarns,
               bool pass_through = false);

  int num_fibres() const { return static_cast<int>(_fibre_yarn.size()); }
  int num_yarns() const { return _num_yarns; }
  std::span<const int> fibre_yarn() const { return _fibre_yarn; }
  std::span<const std::int8_t> above() const { return _above; }

  /// +1 if fibre i's yarn lies above fibre j's, -1 below, 0 no order.
  int sign(int fibre_i, int fibre_j) const;

  /// The weaving normal of a pair, sign(i, j) e_z (zero without an order).
  Eigen::Vector3d normal(int fibre_i, int fibre_j) const;

  /// Whether ordered pairs pass through each other (no contact element).
  bool pass_through() const { return _pass_through; }

private:
  std::vector<int> _fibre_yarn;
  std::vector<std::int8_t> _above;
  int _num_yarns = 0;
  bool _pass_through = false;
};

} // namespace textile::contact
