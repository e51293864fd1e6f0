// The integration choices shared by all elements of a fibre model.
#pragma once

#include "quadrature.h"
#include "../node_unknowns.h"

namespace textile::beam
{

/// Integration choices for one element type.
struct ElementRule
{
  int num_nodes = 3;          ///< 2 (linear) or 3 (quadratic)
  GaussLegendre axial;        ///< points along the element, on [-1, 1]
  bool poisson_cure = true;   ///< section split law (false: plain 3D SVK)
};

} // namespace textile::beam
