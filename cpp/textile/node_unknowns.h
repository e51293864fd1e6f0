// The unknowns of a fibre node, defined once for the whole C++ core.
#pragma once

namespace textile
{

/// Unknowns per fibre node: the centroid x0 and the section vectors g1, g2
/// (3 components each), in that order.
inline constexpr int dofs_per_node = 9;

} // namespace textile
