// All point ties of an effect, assembled together (no loop per tie in Python).
#pragma once

#include <petscmat.h>

#include <cstdint>
#include <span>
#include <vector>

namespace textile::junction
{

/// Penalty ties (point_tie.h) between fibre nodes' centroids and points of
/// a solid's cells, all with the same stiffness k (N/m) and the same number
/// of cell nodes n.
class PointTieSet
{
public:
  /// @param k         stiffness (N/m) of every tie
  /// @param nodes     local fibre node of each tie
  /// @param cell_dofs local block (node) indices of each tie's cell, n per tie
  /// @param phi       basis values of each tie's point, n per tie
  PointTieSet(double k, std::vector<std::int32_t> nodes, std::vector<std::int32_t> cell_dofs,
              std::vector<double> phi);

  std::size_t size() const { return _nodes.size(); }

  /// b_fibre (9 per local node) and b_solid (3 per local solid node) +=
  /// residual of every tie, from the displacements u_fibre, u_solid.
  void assemble_vector(std::span<const double> u_fibre, std::span<const double> u_solid,
                       std::span<double> b_fibre, std::span<double> b_solid) const;

  /// A += tangent; dofs_*: stacked local index of each local unrolled
  /// unknown (-1 where constrained).
  void assemble_matrix(Mat A, std::span<const std::int32_t> dofs_fibre,
                       std::span<const std::int32_t> dofs_solid) const;

  /// Sum over ties of the force they exert on the solid (k gap), (3,).
  std::vector<double> total_force(std::span<const double> u_fibre,
                                  std::span<const double> u_solid) const;

private:
  double _k;
  int _n;
  std::vector<std::int32_t> _nodes, _cells;
  std::vector<double> _phi;
};

} // namespace textile::junction
